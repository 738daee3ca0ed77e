//! What the comparison's figures (`intervals.png`, `profiles.png`, `improvement.png`)
//! share: their title, the run counts they are over, the methods' pens.

use super::legend;
use super::palette::{method_pens, Pen};
use crate::report::Report;

/// A title: the sweep's axis value if any, the tasks, then `rest`.
pub(super) fn title(report: &Report, rest: &str) -> String {
    legend::title(
        report.subject.as_deref(),
        &format!("{}: {rest}", report.task_titles.join(", ")),
    )
}

/// "2 runs" (or "2–5 runs") per method.
pub(super) fn runs(report: &Report) -> String {
    legend::runs_phrase(report.comparison.iter().map(|m| m.runs))
}

/// The methods' pens, as the learning curves give them.
pub(super) fn pens(report: &Report) -> Vec<Pen> {
    method_pens(&report.comparison.iter().map(|m| m.kind).collect::<Vec<_>>())
}
