//! `sapnet sweep status`: which cells are done, running, failed or missing.

use std::path::Path;

use anyhow::Result;

use super::{cell_failure, cell_partial, cell_results, Manifest};

/// Where one cell stands.
#[derive(Debug, Clone, PartialEq)]
pub enum CellState {
    Done,
    /// A partial result is there: running now, or killed (then `sweep run` reruns it).
    Running,
    /// Its last attempt failed, with the error's last line.
    Failed(String),
    Missing,
}

/// The state of every cell, in order.
pub fn states(sweep: &Path) -> Result<Vec<(usize, CellState)>> {
    let manifest = Manifest::read(sweep)?;
    Ok(manifest
        .cells
        .iter()
        .map(|cell| (cell.id, state(sweep, cell.id)))
        .collect())
}

pub fn state(sweep: &Path, id: usize) -> CellState {
    // A real directory each: a link planted in the folder is no cell's result.
    let is_dir = |p: &Path| std::fs::symlink_metadata(p).is_ok_and(|m| m.is_dir());
    if is_dir(&cell_results(sweep, id)) {
        return CellState::Done;
    }
    if is_dir(&cell_partial(sweep, id)) {
        return CellState::Running;
    }
    let failure = crate::safe_io::read_text(
        &cell_failure(sweep, id),
        crate::safe_io::Links::Refuse,
        crate::ron_file::MAX_TEXT_BYTES,
    );
    match failure {
        Ok(text) => CellState::Failed(
            text.lines()
                .rev()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("")
                .to_string(),
        ),
        Err(_) => CellState::Missing,
    }
}

/// The most characters of a failure shown per cell: an error's last line is short; a
/// failure note written by hand may not be.
const FAILURE_CHARS: usize = 300;

/// The counts, then one line per cell that is not done.
pub fn report(states: &[(usize, CellState)]) -> String {
    let count = |f: fn(&CellState) -> bool| states.iter().filter(|(_, s)| f(s)).count();
    let mut out = format!(
        "{} cells: {} done, {} running, {} failed, {} missing\n",
        states.len(),
        count(|s| *s == CellState::Done),
        count(|s| *s == CellState::Running),
        count(|s| matches!(s, CellState::Failed(_))),
        count(|s| *s == CellState::Missing),
    );
    for (id, state) in states {
        match state {
            // The cell's failure note is a file of the sweep's folder: shown as data.
            CellState::Failed(line) => out.push_str(&format!(
                "{id:04} failed: {}\n",
                crate::shown_text::cut(line, FAILURE_CHARS)
            )),
            CellState::Running => out.push_str(&format!("{id:04} running (or killed)\n")),
            CellState::Missing | CellState::Done => {}
        }
    }
    out
}
