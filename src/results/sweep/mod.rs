//! A sweep's folder, below the front ends: its manifest and cells, each cell's state
//! ([`status`]), and the merged reports per axis value ([`merge`]). `sapnet sweep` writes and
//! runs it (`crate::sweep`); the workbench reads it.
//!
//! ```text
//! SWEEP/
//!   sweep.ron              the manifest: every cell's id, axis values and config hash
//!   cells/0000.ron …       each cell's complete config
//!   slurm.sbatch           an array job over the cells
//!   parallel.txt           the GNU parallel command line
//!   results/0000/ …        a finished cell's results (renamed into place when whole)
//!   failed/0003.txt        why a cell's last attempt failed
//!   logs/                  the cells' stdout and stderr under Slurm
//!   merged/                `sapnet sweep merge`: comparisons per axis value, episodes.csv
//! ```

pub mod merge;
pub mod status;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

use crate::ron_file::{parse_ron_as, read_folder_text, ron_options};

/// `SWEEP/sweep.ron`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The grid file it was planned from.
    pub grid: PathBuf,
    /// The library root the cells reuse (absolute), read-only: `sweep prepare` trains it.
    pub library: PathBuf,
    pub cells: Vec<CellEntry>,
}

/// One cell of the manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellEntry {
    pub id: usize,
    /// `(path, value)` per axis.
    pub axes: Vec<(String, String)>,
    /// SHA-256 of `cells/NNNN.ron`.
    pub config_sha256: String,
}

impl Manifest {
    pub fn read(sweep: &Path) -> Result<Self> {
        let path = sweep.join("sweep.ron");
        let text = read_folder_text(&path)
            .with_context(|| format!("{} is not a sweep (sapnet sweep plan)", sweep.display()))?;
        Ok(parse_ron_as(
            &text,
            &path.display().to_string(),
            "sweep manifest",
        )?)
    }

    pub fn write(&self, sweep: &Path) -> Result<()> {
        let pretty = ron::ser::PrettyConfig::default().compact_arrays(true);
        let text = ron_options()
            .to_string_pretty(self, pretty)
            .context("the sweep's manifest")?;
        crate::policy_store::write_atomically(&sweep.join("sweep.ron"), text.as_bytes())
            .map_err(Into::into)
    }
}

/// `0007`: a cell's name in file names.
pub fn cell_name(id: usize) -> String {
    format!("{id:04}")
}

pub fn cell_config(sweep: &Path, id: usize) -> PathBuf {
    sweep.join("cells").join(format!("{}.ron", cell_name(id)))
}

pub fn cell_results(sweep: &Path, id: usize) -> PathBuf {
    sweep.join("results").join(cell_name(id))
}

/// Where a cell runs until it is whole.
pub fn cell_partial(sweep: &Path, id: usize) -> PathBuf {
    sweep
        .join("results")
        .join(format!(".{}.partial", cell_name(id)))
}

/// The lock a cell is run under (beside its results, which it must outlive).
pub fn cell_lock(sweep: &Path, id: usize) -> PathBuf {
    sweep
        .join("results")
        .join(format!(".{}.lock", cell_name(id)))
}

pub fn cell_failure(sweep: &Path, id: usize) -> PathBuf {
    sweep.join("failed").join(format!("{}.txt", cell_name(id)))
}

/// `sapnet.temperature=0.5, seed=1`: a cell's axis values.
pub fn describe(axes: &[(String, String)]) -> String {
    axes.iter()
        .map(|(p, v)| format!("{p}={v}"))
        .collect::<Vec<_>>()
        .join(", ")
}
