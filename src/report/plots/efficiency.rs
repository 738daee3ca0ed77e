//! `sample_efficiency.png`: each method's IQM of the runs' moving averages at every point
//! of training, with its 95% bootstrap band, as openrlbenchmark draws it.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::curves::{curves_chart, Curves};
use super::legend;
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
    let banded = |curve: &[EfficiencyPoint]| curve.iter().any(|p| p.runs > 1);
    let bands = points
        .iter()
        .map(|curve| banded(curve).then(|| curve.iter().map(|p| (p.at, p.iqm)).collect()))
        .collect();
    let lines = points
        .iter()
        .map(|curve| curve.iter().map(|p| (p.at as f64, p.iqm.point)).collect())
        .collect();
    let notes = vec![format!(
        "band: 95% bootstrap CI of the IQM over {}",
        legend::runs_phrase(data.curves.iter().map(|c| c.runs.len()))
    )];
    curves_chart(
        root,
        data,
        Curves {
            caption: format!(
                "{}: IQM over runs of the episode return's moving average of {w}",
                data.task
            ),
            y_desc: format!("episode return, MA{w}: IQM over runs"),
            last,
            fit,
            thinned: vec![false; points.len()],
            lines,
            bands,
            notes,
        },
    )
}
