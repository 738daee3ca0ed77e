//! `activations.png`: the activation of every source policy at the end of each episode,
//! mean over runs, a panel per method that spreads activation (SAP-Net and its variants),
//! on a log axis: one source's activation grows into the thousands while the others stay
//! below ten, and a linear axis flattens those to zero.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::legend::{self, Entry, Swatch};
use super::palette::{marker, source_colour, SOURCE_COLOURS};
use super::{mean_over_runs, Drawn, PlotData, FAMILY};

/// The width of the sources' legend beside the panels.
pub(super) const SOURCES_LEGEND: u32 = 200;
/// A panel's height.
const PANEL_HEIGHT: u32 = 330;

/// The figure's size for `methods` panels, two a row beside the sources' legend (one
/// alone as tall as a learning curve).
pub(super) fn size(methods: usize) -> (u32, u32) {
    if methods <= 1 {
        return (1000 + SOURCES_LEGEND, 600);
    }
    let rows = methods.div_ceil(2) as u32;
    (1300 + SOURCES_LEGEND, 50 + rows * PANEL_HEIGHT)
}

/// The log axis' ends for activations `values`: from the smallest positive one (or a
/// millionth of the largest, if that is higher: a source that held a trace of activation
/// is drawn with those that held none), to a little above the largest. Activations of 0
/// are drawn at the bottom. No positive value: 0.1 to 1.
pub(super) fn log_bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (low, high) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0f64), |(l, h), v| (l.min(v), h.max(v)));
    if high == 0.0 {
        return (0.1, 1.0);
    }
    let floor = low.max(high * 1e-6);
    // Room of a fifth of a decade each side; a floor at the top still spans one decade.
    let (floor, top) = (floor / 10f64.powf(0.2), high * 10f64.powf(0.2));
    if top / floor < 10.0 {
        (top / 10.0, top)
    } else {
        (floor, top)
    }
}

/// Each method's mean activation of each source over its runs (method → source →
/// episode).
fn mean_lines(data: &PlotData) -> Vec<(String, usize, Vec<Vec<f64>>)> {
    let policies = data.policy_names.len();
    data.activations
        .iter()
        .map(|(label, runs)| {
            let lines = (0..policies)
                .map(|p| {
                    let series: Vec<Vec<f64>> = runs
                        .iter()
                        .map(|run| {
                            run.iter()
                                .map(|a| a.get(p).copied().unwrap_or(0.0))
                                .collect()
                        })
                        .collect();
                    mean_over_runs(&series)
                })
                .collect();
            (label.clone(), runs.len(), lines)
        })
        .collect()
}

pub(super) fn activation_panels<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let methods = mean_lines(data);
    let root = root.titled(
        &legend::title(
            data.subject.as_deref(),
            &format!(
                "{}: activation A of each source policy at each episode's end, mean over runs \
                 (log axis; 0 drawn at the bottom)",
                data.task
            ),
        ),
        (FAMILY, 20),
    )?;
    let width = root.dim_in_pixel().0;
    let (panels_area, legend_area) = root.split_horizontally(width - SOURCES_LEGEND);
    let entries: Vec<Entry> = data
        .policy_names
        .iter()
        .enumerate()
        .map(|(p, name)| Entry {
            label: name.clone(),
            swatch: Swatch::Marked(source_colour(p), shape(p)),
        })
        .collect();
    legend::draw(&legend_area.margin(30, 0, 0, 0), &entries, &[])?;
    // One axis for every panel, so that panels compare.
    let (floor, top) = log_bounds(
        methods
            .iter()
            .flat_map(|(_, _, lines)| lines.iter().flatten().copied()),
    );
    let columns = if methods.len() > 1 { 2 } else { 1 };
    let rows = methods.len().div_ceil(columns).max(1);
    let panels = panels_area.split_evenly((rows, columns));
    for (panel, (label, runs, lines)) in panels.iter().zip(&methods) {
        draw_panel(panel, &legend::with_runs(label, *runs), lines, (floor, top))?;
    }
    root.present()
}

/// Source `p`'s marker: a shape of its own beside every source of its colour.
fn shape(p: usize) -> usize {
    p / SOURCE_COLOURS.len() + p
}

/// One method's activations, a line per source, markers to tell coinciding lines apart.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    lines: &[Vec<f64>],
    (floor, top): (f64, f64),
) -> Drawn<DB> {
    let episodes = lines.iter().map(Vec::len).max().unwrap_or(1).max(2);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, 16))
        .margin(8)
        // Room for the last x label, which plotters centres on the axis's end.
        .margin_right(24)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d(1f64..episodes as f64, (floor..top).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("episode")
        .y_desc("activation A")
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| {
            if *y >= 1.0 {
                format!("{y:.0}")
            } else {
                format!("{y:.1e}")
            }
        })
        .label_style((FAMILY, 13))
        .draw()?;
    let at = |a: f64| a.max(floor);
    // Curves that coincide (two sources that never act keep the same activation) must
    // still each be seen: colours far apart, and a marker shape of its own every tenth of
    // the episodes, shifted per source so that the markers of equal curves sit side by
    // side instead of on top of each other.
    let every = (episodes / 10).max(1);
    let sources = lines.len();
    for (p, line) in lines.iter().enumerate() {
        let colour = source_colour(p);
        let shape = shape(p);
        chart.draw_series(LineSeries::new(
            line.iter()
                .enumerate()
                .map(|(e, &a)| ((e + 1) as f64, at(a))),
            colour.stroke_width(2),
        ))?;
        let offset = p * every / sources.max(1);
        chart.draw_series(
            line.iter()
                .enumerate()
                .skip(offset)
                .step_by(every)
                .map(|(e, &a)| {
                    EmptyElement::at(((e + 1) as f64, at(a))) + marker(shape, (0, 0), colour)
                }),
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_log_axis_spans_the_smallest_and_largest_activation() {
        // 0.35 to 11,800 (the quick protocol's): a fifth of a decade of room each side.
        let (low, high) = log_bounds([0.0, 0.35, 2.0, 11_800.0].into_iter());
        let room = 10f64.powf(0.2);
        assert!((low - 0.35 / room).abs() < 1e-12, "{low}");
        assert!((high - 11_800.0 * room).abs() < 1e-9, "{high}");
    }

    #[test]
    fn a_trace_of_activation_sits_with_the_zeros() {
        // 1e-12 beside 1,000: the floor is a millionth of the largest.
        let (low, _) = log_bounds([1e-12, 1_000.0].into_iter());
        assert!((low - 1e-3 / 10f64.powf(0.2)).abs() < 1e-12, "{low}");
    }

    #[test]
    fn no_activation_yet_still_has_an_axis() {
        assert_eq!(log_bounds([0.0, 0.0].into_iter()), (0.1, 1.0));
        // One value: a decade below it.
        let (low, high) = log_bounds([5.0].into_iter());
        assert!((high / low - 10.0).abs() < 1e-9 && high > 5.0);
    }
}
