//! `selections.png`: which source acted, run by run. A panel per method that reuses the
//! library, a strip per run over the episodes after the warm-up, each column the shares of
//! the acting steps each source took in a bin of episodes. Runs are never averaged: two
//! runs locked on different sources show two solid strips of different colours, not a
//! 50/50 split; a selector that changes source every episode shows mixed columns, binned,
//! instead of a barcode.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::activations::SOURCES_LEGEND;
use super::legend::{self, Entry, Swatch};
use super::palette::{source_colour, Pen};
use super::{Drawn, PlotData, FAMILY};

/// At most this many columns per strip.
const COLUMNS: usize = 60;
/// A run's strip, and the room a panel's caption and axis take.
const STRIP: u32 = 20;
const PANEL_EXTRA: u32 = 66;

/// The figure's height for these methods' runs.
pub(super) fn height(acted: &[(String, Vec<Vec<Vec<u64>>>)]) -> u32 {
    60 + acted
        .iter()
        .map(|(_, runs)| PANEL_EXTRA + STRIP * runs.len().max(1) as u32)
        .sum::<u32>()
}

/// How many episodes a column holds for runs of at most `episodes` episodes.
pub(super) fn bin_width(episodes: usize) -> usize {
    episodes.div_ceil(COLUMNS).max(1)
}

/// One run's columns: the episodes after the warm-up (those in which a source acted) in
/// bins of `width`, each the share of the bin's acting steps each source took.
pub(super) fn binned_shares(run: &[Vec<u64>], width: usize) -> Vec<Vec<f64>> {
    let acting: Vec<&Vec<u64>> = run.iter().filter(|a| a.iter().sum::<u64>() > 0).collect();
    acting
        .chunks(width.max(1))
        .map(|bin| {
            let sources = bin.iter().map(|a| a.len()).max().unwrap_or(0);
            let steps: Vec<u64> = (0..sources)
                .map(|p| bin.iter().map(|a| a.get(p).copied().unwrap_or(0)).sum())
                .collect();
            let total = steps.iter().sum::<u64>() as f64;
            steps.iter().map(|&s| s as f64 / total).collect()
        })
        .collect()
}

pub(super) fn selection_strips<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let episodes = data
        .acted
        .iter()
        .flat_map(|(_, runs)| runs.iter())
        .map(|run| run.iter().filter(|a| a.iter().sum::<u64>() > 0).count())
        .max()
        .unwrap_or(1)
        .max(1);
    let width = bin_width(episodes);
    let root = root.titled(
        &legend::title(
            data.subject.as_deref(),
            &format!(
                "{}: share of the acting steps each source took, per run, in bins of {}",
                data.task,
                if width == 1 {
                    "1 episode".to_string()
                } else {
                    format!("{width} episodes")
                }
            ),
        ),
        (FAMILY, 20),
    )?;
    let (root, legend_area) = root.split_horizontally(root.dim_in_pixel().0 - SOURCES_LEGEND);
    let entries: Vec<Entry> = data
        .policy_names
        .iter()
        .enumerate()
        .map(|(p, name)| Entry {
            label: name.clone(),
            swatch: Swatch::Bar(Pen::solid(source_colour(p))),
        })
        .collect();
    legend::draw(&legend_area.margin(30, 0, 0, 0), &entries, &[])?;
    let heights: Vec<u32> = data
        .acted
        .iter()
        .map(|(_, runs)| PANEL_EXTRA + STRIP * runs.len().max(1) as u32)
        .collect();
    let mut rest = root;
    for ((label, runs), h) in data.acted.iter().zip(heights) {
        let (panel, below) = rest.split_vertically(h);
        draw_panel(&panel, label, runs, (episodes, width))?;
        rest = below;
    }
    Ok(())
}

/// One method's strips, run 0 at the top.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    label: &str,
    runs: &[Vec<Vec<u64>>],
    (episodes, width): (usize, usize),
) -> Drawn<DB> {
    let n = runs.len().max(1);
    let mut chart = ChartBuilder::on(area)
        .caption(legend::with_runs(label, runs.len()), (FAMILY, 16))
        .margin(6)
        .margin_right(24)
        .x_label_area_size(34)
        .y_label_area_size(60)
        .build_cartesian_2d(0f64..episodes as f64, 0f64..n as f64)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .y_labels(0)
        .x_desc("episode after the warm-up")
        .x_label_formatter(&|x| format!("{x:.0}"))
        .label_style((FAMILY, 12))
        .draw()?;
    for (r, run) in runs.iter().enumerate() {
        // Run r's strip, from the top, with a white line between strips.
        let (bottom, top) = ((n - 1 - r) as f64 + 0.06, (n - r) as f64 - 0.06);
        for (b, shares) in binned_shares(run, width).iter().enumerate() {
            let (x0, x1) = ((b * width) as f64, ((b + 1) * width).min(episodes) as f64);
            let mut y = bottom;
            for (p, &share) in shares.iter().enumerate() {
                if share <= 0.0 {
                    continue;
                }
                let y1 = y + share * (top - bottom);
                chart.draw_series(std::iter::once(Rectangle::new(
                    [(x0, y), (x1, y1)],
                    source_colour(p).filled(),
                )))?;
                y = y1;
            }
        }
        // The run's name left of its strip, in the panel's own pixels.
        let (x, y) = chart.backend_coord(&(0.0, (bottom + top) / 2.0));
        let (base_x, base_y) = area.get_base_pixel();
        area.draw(&Text::new(
            format!("run {r}"),
            (x - base_x - 6, y - base_y + 3),
            (FAMILY, 12)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Right, VPos::Center)),
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_run_keeps_its_own_source() {
        // Two runs locked on different sources: each run's columns are all its own source,
        // never a half of each.
        let locked_on = |p: usize| -> Vec<Vec<u64>> {
            (0..6)
                .map(|_| {
                    let mut a = vec![0; 3];
                    a[p] = 10;
                    a
                })
                .collect()
        };
        for p in [0, 2] {
            for column in binned_shares(&locked_on(p), 2) {
                assert_eq!(column[p], 1.0);
            }
        }
    }

    #[test]
    fn bins_weigh_the_steps_and_skip_the_warm_up() {
        // A warm-up episode (no source acted), then 3 + 1 steps, then 0 + 4: one bin of
        // two episodes, 3/8 and 5/8.
        let run = vec![vec![0, 0], vec![3, 1], vec![0, 4]];
        assert_eq!(binned_shares(&run, 2), vec![vec![0.375, 0.625]]);
        assert_eq!(binned_shares(&run, 1).len(), 2);
    }

    #[test]
    fn a_long_run_has_at_most_sixty_columns() {
        assert_eq!(bin_width(50), 1);
        assert_eq!(bin_width(250), 5);
        assert_eq!(250usize.div_ceil(bin_width(250)), 50);
        assert!(5_000usize.div_ceil(bin_width(5_000)) <= COLUMNS);
    }
}
