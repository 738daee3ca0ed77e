//! `sample_efficiency.png`: each method's IQM of the runs' moving averages at every point
//! of training, with its 95% bootstrap band, as openrlbenchmark draws it.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::curves::{beside_legend, pens};
use super::legend::{self, Entry, Swatch};
use super::{axes, Drawn, PlotData, FAMILY};
use crate::report::sample_efficiency::EfficiencyPoint;

/// Draws `points` (one curve per method of `data`, in its order).
pub(super) fn sample_efficiency<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
    points: &[Vec<EfficiencyPoint>],
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let w = data.window.max(1);
    let episodes = points
        .iter()
        .filter_map(|p| p.last().map(|p| p.episode))
        .max()
        .unwrap_or(w);
    let fit = axes::fit(
        points
            .iter()
            .flatten()
            .flat_map(|p| [p.iqm.point, p.iqm.lo, p.iqm.hi]),
        data.return_range,
    );
    let (area, legend_area) = beside_legend(&root);
    let mut chart = ChartBuilder::on(&area)
        .caption(
            legend::title(
                data.subject.as_deref(),
                &format!(
                    "{}: IQM over runs of the episode return's moving average of {w}",
                    data.task
                ),
            ),
            (FAMILY, 20),
        )
        .margin(12)
        .margin_right(30)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0f64..episodes as f64, fit.low..fit.high)?;
    chart
        .configure_mesh()
        .x_desc(format!("episode (the last of each window of {w})"))
        .y_desc(format!("episode return, MA{w}: IQM over runs"))
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .label_style((FAMILY, 15))
        .draw()?;
    let pens = pens(&data.curves);
    let banded = |curve: &[EfficiencyPoint]| curve.iter().any(|p| p.runs > 1);
    for (curve, pen) in points.iter().zip(&pens) {
        if !banded(curve) {
            continue;
        }
        let band: Vec<(f64, f64)> = curve
            .iter()
            .map(|p| (p.episode as f64, fit.clamp(p.iqm.hi)))
            .chain(
                curve
                    .iter()
                    .rev()
                    .map(|p| (p.episode as f64, fit.clamp(p.iqm.lo))),
            )
            .collect();
        chart.draw_series(std::iter::once(Polygon::new(
            band,
            pen.colour.mix(0.15).filled(),
        )))?;
    }
    for (curve, &pen) in points.iter().zip(&pens) {
        let line = curve
            .iter()
            .map(|p| (p.episode as f64, p.iqm.point))
            .collect();
        legend::draw_line(&mut chart, line, pen)?;
    }
    let entries: Vec<Entry> = data
        .curves
        .iter()
        .zip(&pens)
        .map(|(c, &pen)| Entry {
            label: legend::with_runs(&c.label, c.returns.len()),
            swatch: Swatch::Line(pen),
        })
        .collect();
    let mut notes = vec![format!(
        "band: 95% bootstrap CI of the IQM over {}",
        legend::runs_phrase(data.curves.iter().map(|c| c.returns.len()))
    )];
    notes.extend(fit.note().map(|n| format!("band {n}")));
    legend::draw(&legend_area, &entries, &notes)?;
    root.present()
}
