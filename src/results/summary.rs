//! `summary.json`: where a protocol stands (its status, the runs not finished), its config,
//! its library and every finished run; written when the protocol starts and after every
//! run, always atomically.

use std::fs::File;
use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

use crate::config::Config;
use crate::report::{LibraryEntry, MethodComparison, RunSummary};

/// Where a protocol stands, the first field of `summary.json`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// A process is running it (or was killed: `sapnet plot` and `--resume` then say
    /// `interrupted`).
    Running,
    /// Every planned run finished.
    Complete,
    /// Stopped by the user or a signal; `--resume` finishes it.
    Stopped,
    /// A run failed (`error` says why); `--resume` retries the unfinished runs.
    Failed,
    /// The process died without saying so (SIGKILL, power loss); `--resume` finishes it.
    Interrupted,
}

/// A run of the protocol, by method label and 0-based index.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct RunKey {
    pub method: String,
    pub run: u32,
}

/// `summary.json`.
#[derive(Debug, Serialize)]
pub struct Summary {
    pub status: Status,
    /// Planned runs without a finished record: not started, stopped or killed.
    pub unfinished: Vec<RunKey>,
    pub crate_version: &'static str,
    pub config: Config,
    /// Whether SAP-Net's spread calls are traced (`--trace`): a resumed protocol goes on
    /// as it began.
    pub trace: bool,
    /// The source library the reusing methods drew on (absent without one).
    pub library: Option<Vec<LibraryEntry>>,
    /// Finished (and stopped) runs, ordered by method as the protocol lists them, then run.
    pub runs: Vec<RunSummary>,
    /// The methods side by side (`comparison.csv`).
    pub comparison: Vec<MethodComparison>,
    /// Seconds this process spent (a resumed protocol: since the resume).
    pub wall_s: f64,
    /// Why the experiment ended early, if it failed (the runs above finished before).
    pub error: Option<String>,
}

/// What `--resume` and `sapnet plot` read back from `summary.json`.
#[derive(Debug, Deserialize)]
pub struct SummaryHeader {
    /// Absent in results written before the field existed: complete or stopped, never
    /// resumable.
    pub status: Option<Status>,
    pub config: Config,
    #[serde(default)]
    pub trace: bool,
    pub library: Option<Vec<LibraryEntry>>,
    #[serde(default)]
    pub wall_s: f64,
    #[serde(default)]
    pub error: Option<String>,
}

impl Summary {
    pub fn new(config: &Config, trace: bool) -> Self {
        Self {
            status: Status::Running,
            unfinished: Vec::new(),
            crate_version: env!("CARGO_PKG_VERSION"),
            config: config.clone(),
            trace,
            library: None,
            runs: Vec::new(),
            comparison: Vec::new(),
            wall_s: 0.0,
            error: None,
        }
    }

    /// Some run was stopped by the user.
    pub fn stopped(&self) -> bool {
        self.status == Status::Stopped
    }
}

/// What `summary.json` says of the protocol: its status, config and library.
pub fn read_header(dir: &Path) -> Result<SummaryHeader> {
    let path = dir.join("summary.json");
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("reading {} (is this a results directory?)", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("reading {}", path.display()))
}

/// Writes `summary` (or a run's `run.json`) atomically: a reader never sees half a file.
pub fn write_json(path: &Path, summary: &impl Serialize) -> Result<()> {
    let tmp = path.with_extension("json.tmp");
    let write = || -> std::io::Result<()> {
        let mut file = File::create(&tmp)?;
        serde_json::to_writer_pretty(&mut file, summary)?;
        file.write_all(b"\n")?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    };
    write().map_err(|err| {
        let _ = std::fs::remove_file(&tmp);
        anyhow::Error::new(err).context(format!("writing {}", path.display()))
    })
}
