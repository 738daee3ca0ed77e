//! What the selectors did with the library: the activation of every source over the
//! episodes, and each source's share of the acting steps.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::axes::value_range;
use super::legend::{self, Entry, Swatch};
use super::palette::{marker, source_colour, Pen, SOURCE_COLOURS};
use super::{mean_over_runs, Drawn, PlotData, FAMILY};

/// The width of the sources' legend beside the selection panels.
const SOURCES_LEGEND: u32 = 200;

/// The activation of each source policy at the end of every episode, averaged over runs.
pub(super) fn activation_lines<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let policies = data.policy_names.len();
    let per_policy: Vec<Vec<f64>> = (0..policies)
        .map(|p| {
            let runs: Vec<Vec<f64>> = data
                .activations
                .iter()
                .map(|run| run.iter().map(|a| a[p]).collect())
                .collect();
            mean_over_runs(&runs)
        })
        .collect();
    let episodes = per_policy.iter().map(Vec::len).max().unwrap_or(1).max(1);
    let (_, high) = value_range(per_policy.iter().flatten().copied().chain([0.0]));
    let runs = data.activations.len();
    let mut chart = ChartBuilder::on(&root)
        .caption(
            legend::title(
                data.subject.as_deref(),
                &format!(
                    "{}: activation of each source policy, mean of {}",
                    data.task,
                    legend::runs_phrase([runs])
                ),
            ),
            (FAMILY, 22),
        )
        .margin(12)
        // Room for the last x label, which plotters centres on the axis's end.
        .margin_right(30)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(1f64..episodes as f64, 0f64..high)?;
    chart
        .configure_mesh()
        .x_desc("episode")
        .y_desc("activation A")
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| {
            if high >= 10.0 {
                format!("{y:.0}")
            } else {
                format!("{y:.2}")
            }
        })
        .label_style((FAMILY, 15))
        .draw()?;
    // Curves that coincide (two sources that never act keep the same activation) must
    // still each be seen: ten colours far apart, and a marker shape of its own every tenth
    // of the episodes, shifted per source so that the markers of equal curves sit side by
    // side instead of on top of each other.
    let every = (episodes / 10).max(1);
    for (p, line) in per_policy.iter().enumerate() {
        let colour = source_colour(p);
        let shape = p / SOURCE_COLOURS.len() + p;
        chart
            .draw_series(LineSeries::new(
                line.iter().enumerate().map(|(e, &a)| ((e + 1) as f64, a)),
                colour.stroke_width(2),
            ))?
            .label(data.policy_names[p].clone())
            .legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new([(0, 0), (20, 0)], colour.stroke_width(2))
                    + marker(shape, (10, 0), colour)
            });
        let offset = p * every / policies.max(1);
        let points: Vec<(f64, f64)> = line
            .iter()
            .enumerate()
            .skip(offset)
            .step_by(every)
            .map(|(e, &a)| ((e + 1) as f64, a))
            .collect();
        chart.draw_series(
            points
                .into_iter()
                .map(|point| EmptyElement::at(point) + marker(shape, (0, 0), colour)),
        )?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FAMILY, 14))
        .draw()?;
    root.present()
}

/// For each reusing method, a panel of stacked shares: the fraction of each episode's
/// acting steps taken by each source, mean over runs (episodes spent in the warm-up left
/// out).
pub(super) fn selection_shares<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let root = root.titled(
        &legend::title(
            data.subject.as_deref(),
            &format!(
                "{}: share of the acting steps taken by each source, mean over runs",
                data.task
            ),
        ),
        (FAMILY, 20),
    )?;
    // One legend for every panel, beside them, top to bottom as the areas are stacked.
    let (root, legend_area) = root.split_horizontally(root.dim_in_pixel().0 - SOURCES_LEGEND);
    let policies = data.policy_names.len();
    let entries: Vec<Entry> = (0..policies)
        .rev()
        .map(|p| Entry {
            label: data.policy_names[p].clone(),
            swatch: Swatch::Bar(Pen::solid(source_colour(p))),
        })
        .collect();
    legend::draw(&legend_area.margin(30, 0, 0, 0), &entries, &[])?;
    let panels = root.split_evenly((data.acted.len(), 1));
    for (panel, (label, runs)) in panels.iter().zip(&data.acted) {
        // run → episode → share per policy.
        let shares: Vec<Vec<Vec<f64>>> = runs
            .iter()
            .map(|run| {
                run.iter()
                    .filter(|acted| acted.iter().sum::<u64>() > 0)
                    .map(|acted| {
                        let total = acted.iter().sum::<u64>() as f64;
                        acted.iter().map(|&a| a as f64 / total).collect()
                    })
                    .collect()
            })
            .collect();
        let per_policy: Vec<Vec<f64>> = (0..policies)
            .map(|p| {
                let series: Vec<Vec<f64>> = shares
                    .iter()
                    .map(|run| run.iter().map(|s| s[p]).collect())
                    .collect();
                mean_over_runs(&series)
            })
            .collect();
        let episodes = per_policy.iter().map(Vec::len).max().unwrap_or(1).max(2);
        let mut chart = ChartBuilder::on(panel)
            .caption(legend::with_runs(label, runs.len()), (FAMILY, 16))
            .margin(8)
            .margin_right(20)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(1f64..episodes as f64, 0f64..1f64)?;
        chart
            .configure_mesh()
            .x_desc("episode after the warm-up")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.1}"))
            .label_style((FAMILY, 12))
            .draw()?;
        // Stacked from the top: each area reaches the cumulative share up to its policy.
        for p in (0..policies).rev() {
            let colour = source_colour(p);
            let top: Vec<(f64, f64)> = (0..episodes)
                .map(|e| {
                    let stacked: f64 = per_policy[..=p]
                        .iter()
                        .map(|l| l.get(e).copied().unwrap_or(0.0))
                        .sum();
                    ((e + 1) as f64, stacked.min(1.0))
                })
                .collect();
            chart.draw_series(AreaSeries::new(top, 0.0, colour.filled()))?;
        }
    }
    root.present()
}
