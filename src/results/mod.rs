//! A results directory on disk, below both front ends: `summary.json` ([`summary`]), each
//! run's own record in `runs/` ([`records`]), the CSV files ([`files`]) put together from
//! the records ([`assemble`]), and reading it all back — for `--resume`, `sapnet plot`
//! ([`replot`]), `sweep merge` and the dashboard's `--compare` ([`plot_data`]).

pub mod assemble;
pub mod files;
pub mod folder_changes;
pub mod folder_state;
pub mod found;
pub mod plot_data;
pub mod pool;
pub mod recorded_run;
pub mod records;
pub mod replot;
pub mod run_metrics;
pub mod shipped;
pub mod summary;
pub mod sweep;

use std::path::Path;

use anyhow::Result;

use crate::config::Config;
use crate::report::{LibraryEntry, RunSummary, TrainingRuns};

pub use assemble::{assemble, Ending};
pub use plot_data::read as read_plot_data;
pub use replot::replot;
pub use summary::{read_header, write_json, RunKey, Status, Summary, SummaryHeader};

/// Refuses a folder whose summary lists runs but which holds none of their records
/// (`runs/`): a report shipped with its files only, as `docs/reuse/<task>/` is. Made again,
/// or pooled, it would be a report of no runs, and `sapnet plot` would write it over the
/// files it came with.
pub(crate) fn require_records(dir: &Path, header: &SummaryHeader) -> Result<()> {
    if !header.listed_runs.is_empty() && !records::any(dir)? {
        anyhow::bail!(
            "{}: summary.json lists {} runs but the folder holds none of their records \
             ({}/{}/<run>/run.json): a report shipped without them is made again by \
             `sapnet plot` from its episodes.csv, but not pooled or resumed; use the \
             protocol's own output folder",
            dir.display(),
            header.listed_runs.len(),
            dir.display(),
            records::RUNS,
        );
    }
    Ok(())
}

/// A finished results directory, read back: its config, library, runs and each run's
/// training returns (what the comparison is computed from).
pub struct Results {
    pub config: Config,
    pub library: Option<Vec<LibraryEntry>>,
    pub runs: Vec<RunSummary>,
    pub episodes: TrainingRuns,
}

/// Reads the results in `dir` from its summary and run records.
pub fn read_results(dir: &Path) -> Result<Results> {
    let header = read_header(dir)?;
    require_records(dir, &header)?;
    let folders = records::read(dir, &header.config)?;
    let episodes = assemble::training_episodes(&folders)?;
    Ok(Results {
        config: header.config,
        library: header.library,
        runs: folders.into_iter().map(|f| f.summary).collect(),
        episodes,
    })
}
