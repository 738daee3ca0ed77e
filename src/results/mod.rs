//! A results directory on disk, below both front ends: `summary.json` ([`summary`]), each
//! run's own record in `runs/` ([`records`]), the CSV files ([`files`]) put together from
//! the records ([`assemble`]), and reading it all back — for `--resume`, `sapnet plot`
//! ([`replot`]), `sweep merge` and the dashboard's `--compare`.

pub mod assemble;
pub mod files;
pub mod pool;
pub mod records;
pub mod replot;
pub mod summary;

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Result;

use crate::config::Config;
use crate::report::{LibraryEntry, RunSummary};
use crate::trainer::MethodId;

pub use assemble::{assemble, Ending};
pub use replot::{read as read_plot_data, replot};
pub use summary::{read_header, write_json, RunKey, Status, Summary, SummaryHeader};

/// A finished results directory, read back: its config, library, runs and each run's
/// training returns (what the comparison is computed from).
pub struct Results {
    pub config: Config,
    pub library: Option<Vec<LibraryEntry>>,
    pub runs: Vec<RunSummary>,
    pub rewards: BTreeMap<(MethodId, u32), Vec<f64>>,
}

/// Reads the results in `dir` from its summary and run records.
pub fn read_results(dir: &Path) -> Result<Results> {
    let header = read_header(dir)?;
    let folders = records::read(dir, &header.config)?;
    let rewards = assemble::rewards(&folders)?;
    Ok(Results {
        config: header.config,
        library: header.library,
        runs: folders.into_iter().map(|f| f.summary).collect(),
        rewards,
    })
}
