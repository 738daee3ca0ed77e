//! `sample_efficiency.png`: each method's IQM of the runs' moving averages at every point
//! of training, with its 95% bootstrap band, as openrlbenchmark draws it.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::curves::{
    band_polygon, beside_legend, emphasis_note, episode_chart, in_drawing_order, pens,
};
use super::legend::{self, Entry, Swatch};
use super::{axes, Drawn, PlotData};
use crate::report::sample_efficiency::EfficiencyPoint;

/// Draws `points` (one curve per method of `data`, in its order).
pub(super) fn sample_efficiency<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
    points: &[Vec<EfficiencyPoint>],
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let w = data.window.max(1);
    let last = points
        .iter()
        .filter_map(|p| p.last().map(|p| p.at))
        .max()
        .unwrap_or(w as u64);
    let fit = axes::fit(
        points
            .iter()
            .flatten()
            .flat_map(|p| [p.iqm.point, p.iqm.lo, p.iqm.hi]),
        data.return_range,
    );
    let (area, legend_area) = beside_legend(&root);
    let caption = format!(
        "{}: IQM over runs of the episode return's moving average of {w}",
        data.task
    );
    let mut chart = episode_chart(
        &area,
        legend::title(data.subject.as_deref(), &caption),
        format!("episode return, MA{w}: IQM over runs"),
        super::curves::x_axis(data, last),
        &fit,
    )?;
    let pens = pens(&data.curves);
    let banded = |curve: &[EfficiencyPoint]| curve.iter().any(|p| p.runs > 1);
    for (curve, pen) in points.iter().zip(&pens) {
        if !banded(curve) || pen.faint {
            continue;
        }
        let band = curve.iter().map(|p| (p.at, p.iqm));
        chart.draw_series(std::iter::once(band_polygon(band, &fit, *pen)))?;
    }
    for i in in_drawing_order(&pens) {
        let line = points[i]
            .iter()
            .map(|p| (p.at as f64, p.iqm.point))
            .collect();
        legend::draw_line(&mut chart, line, pens[i])?;
    }
    let entries: Vec<Entry> = data
        .curves
        .iter()
        .zip(&pens)
        .map(|(c, &pen)| Entry {
            label: legend::with_runs(&c.label, c.runs.len()),
            swatch: Swatch::Line(pen),
        })
        .collect();
    let mut notes = vec![format!(
        "band: 95% bootstrap CI of the IQM over {}",
        legend::runs_phrase(data.curves.iter().map(|c| c.runs.len()))
    )];
    notes.extend(emphasis_note(&pens));
    notes.extend(fit.note().map(|n| format!("band {n}")));
    legend::draw(&legend_area, &entries, &notes)?;
    root.present()
}
