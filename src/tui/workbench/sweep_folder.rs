//! A sweep folder (`sapnet sweep plan`) as the Sweep view reads it — its cells (queued,
//! running, done, failed) and, per axis value, the comparison of its finished cells, made
//! by the code `sweep merge` writes `merged/comparison.csv` with
//! ([`crate::results::sweep::merge::groups`], [`crate::results::sweep::merge::value_report`]).
//!
//! Read only, as any folder from elsewhere: the manifest, each cell's state as `sweep
//! status` reads it, a running cell's process from its protocol's lock (never taken) and
//! its progress from its partial results, each done cell's records as `sweep merge` reads
//! them. The sweep screen's thread reads it again every [`super::folder::REFRESH`] and
//! makes the comparisons again when the set of done cells changed.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::folder_lock::{self, Holder};
use crate::report::Report;
use crate::results::folder_state::FolderReader;
use crate::results::sweep::status::{self, CellState};
use crate::results::sweep::{cell_partial, cell_results, describe, merge, Manifest};

/// Whether `dir` is a sweep folder: it holds a manifest, `sweep.ron`.
pub fn is_sweep(dir: &Path) -> bool {
    std::fs::symlink_metadata(dir.join("sweep.ron")).is_ok_and(|m| m.is_file())
}

/// Where a cell stands, as the Sweep view says it.
#[derive(Debug, Clone, PartialEq)]
pub enum CellStatus {
    /// Not started; a live process runs the sweep's cells.
    Queued,
    /// Not started, and no process runs any cell now.
    NotRun,
    /// Its process holds its protocol's lock.
    Running(Holder),
    /// A partial result no process writes: killed (`sweep run` runs it again).
    Stopped,
    Done,
    /// Its last attempt failed, with the error's last line.
    Failed(String),
}

impl CellStatus {
    pub fn name(&self) -> &'static str {
        match self {
            CellStatus::Queued => "queued",
            CellStatus::NotRun => "not run",
            CellStatus::Running(_) => "running",
            CellStatus::Stopped => "stopped",
            CellStatus::Done => "done",
            CellStatus::Failed(_) => "failed",
        }
    }
}

/// One cell of the sweep.
#[derive(Debug, Clone)]
pub struct CellRow {
    pub id: usize,
    /// Its axis values (`sapnet.temperature=0.5, seed=1`).
    pub axes: String,
    pub status: CellStatus,
    /// A running cell's runs finished of all, from its partial results.
    pub progress: Option<(usize, usize)>,
}

/// One axis value's comparison of its finished cells.
#[derive(Debug, Clone)]
pub struct ValueComparison {
    pub axis: String,
    pub value: String,
    /// Finished cells with that value.
    pub cells: usize,
    pub report: Report,
}

/// A sweep folder as read at one moment.
#[derive(Debug, Clone)]
pub struct SweepState {
    pub dir: PathBuf,
    pub axes: Vec<String>,
    pub cells: Vec<CellRow>,
}

impl SweepState {
    /// Reads the manifest and every cell's state; refused (naming the file) when the
    /// manifest cannot be read.
    pub fn read(dir: &Path) -> Result<Self> {
        let manifest = Manifest::read(dir)?;
        let mut cells = Vec::new();
        for cell in &manifest.cells {
            let partial = cell_partial(dir, cell.id);
            let (status, progress) = match status::state(dir, cell.id) {
                CellState::Done => (CellStatus::Done, None),
                CellState::Failed(line) => (CellStatus::Failed(line), None),
                CellState::Missing => (CellStatus::NotRun, None),
                CellState::Running => match folder_lock::holder(&partial)? {
                    Some(holder) => {
                        // Its progress, if its summary is there yet (it is written first).
                        let progress = FolderReader::new(&partial)
                            .read()
                            .ok()
                            .map(|f| (f.finished_runs(), f.runs.len()));
                        (CellStatus::Running(holder), progress)
                    }
                    None => (CellStatus::Stopped, None),
                },
            };
            cells.push(CellRow {
                id: cell.id,
                axes: describe(&cell.axes),
                status,
                progress,
            });
        }
        let live = cells
            .iter()
            .any(|c| matches!(c.status, CellStatus::Running(_)));
        if live {
            for cell in &mut cells {
                if cell.status == CellStatus::NotRun {
                    cell.status = CellStatus::Queued;
                }
            }
        }
        let axes = manifest
            .cells
            .first()
            .map(|c| c.axes.iter().map(|(p, _)| p.clone()).collect())
            .unwrap_or_default();
        Ok(Self {
            dir: dir.to_path_buf(),
            axes,
            cells,
        })
    }

    /// The done cells' ids: the comparisons change only when these do.
    pub fn done(&self) -> Vec<usize> {
        self.cells
            .iter()
            .filter(|c| c.status == CellStatus::Done)
            .map(|c| c.id)
            .collect()
    }

    pub fn count(&self, name: &str) -> usize {
        self.cells
            .iter()
            .filter(|c| c.status.name() == name)
            .count()
    }
}

/// Per axis value, the comparison of its done cells, as `sweep merge` makes it.
pub fn comparisons(dir: &Path, done: &[usize]) -> Result<Vec<ValueComparison>> {
    let manifest = Manifest::read(dir)?;
    let mut read = Vec::new();
    for cell in manifest.cells.iter().filter(|c| done.contains(&c.id)) {
        let results =
            crate::results::read_results(&cell_results(dir, cell.id)).with_context(|| {
                format!("reading cell {}", crate::results::sweep::cell_name(cell.id))
            })?;
        read.push((cell, results));
    }
    let axes: Vec<String> = manifest
        .cells
        .first()
        .map(|c| c.axes.iter().map(|(p, _)| p.clone()).collect())
        .unwrap_or_default();
    let refs: Vec<(&crate::results::sweep::CellEntry, &crate::results::Results)> =
        read.iter().map(|(c, r)| (*c, r)).collect();
    Ok(merge::groups(&axes, &refs)
        .into_iter()
        .map(|(axis, value, group)| {
            let (report, _) = merge::value_report(&axis, &value, &group);
            ValueComparison {
                cells: group.len(),
                axis,
                value,
                report,
            }
        })
        .collect())
}
