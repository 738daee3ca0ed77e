//! `summary.json`: where a protocol stands (its status, the runs not finished), its config,
//! its library and every finished run; written when the protocol starts and after every
//! run, always atomically.

use std::io::Write;
use std::path::Path;

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

use crate::config::Config;
use crate::report::{Improvement, LibraryEntry, MethodComparison, RunSummary};

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
    /// Every ordered pair of methods by the separation rule (`improvement.csv`), for the
    /// closing table; not in `summary.json`, whose readers take it from the CSV.
    #[serde(skip)]
    pub pairs: Vec<Improvement>,
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
    /// The runs the summary lists, counted and not read: a folder whose summary lists runs
    /// but which holds none of their records is a report shipped without them.
    #[serde(default, rename = "runs")]
    pub listed_runs: Vec<serde::de::IgnoredAny>,
}

impl Summary {
    pub fn new(config: &Config, trace: bool) -> Self {
        Self {
            status: Status::Running,
            unfinished: Vec::new(),
            crate_version: env!("CARGO_PKG_VERSION"),
            // Without how this machine runs its tasks: a folder never names a program.
            config: config.as_recorded(),
            trace,
            library: None,
            runs: Vec::new(),
            comparison: Vec::new(),
            pairs: Vec::new(),
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
    let text = crate::safe_io::read_text(&path, crate::safe_io::Links::Refuse, MAX_SUMMARY_BYTES)
        .with_context(|| {
        format!("reading {} (is this a results directory?)", path.display())
    })?;
    let header: SummaryHeader =
        serde_json::from_str(&text).with_context(|| format!("reading {}", path.display()))?;
    // The config a folder carries is checked as `--config` is: what a resume builds from
    // it (run folders named by method labels, a library named by `sources.name`) must stay
    // inside the folders it names.
    header
        .config
        .validate()
        .map_err(|e| anyhow::anyhow!("{}: the stored config: {e}", path.display()))?;
    // Before anything that grows with it (a dashboard's graph is n × n).
    let sources = header.library.as_ref().map_or(0, Vec::len);
    if sources > crate::limits::MAX_SOURCES {
        anyhow::bail!(
            "{}: library: {sources} sources, more than the {} a library may hold",
            path.display(),
            crate::limits::MAX_SOURCES
        );
    }
    Ok(header)
}

/// Refuses a run's record whose per-source counts (`source_steps`, `positive`,
/// `negative`) are neither empty (a method without a library, an older record) nor one per
/// source of the library of `sources`: its views index them by source.
pub fn check_per_source(
    path: &Path,
    record: &crate::trainer::RunRecord,
    sources: usize,
) -> Result<()> {
    for (field, counts) in [
        ("source_steps", &record.source_steps),
        ("positive", &record.positive),
        ("negative", &record.negative),
    ] {
        if !counts.is_empty() && counts.len() != sources {
            anyhow::bail!(
                "{}: {} run {}: {field} holds {} counts, expected one per source of \
                 summary.json's library ({sources})",
                path.display(),
                record.method.label(),
                record.run,
                counts.len()
            );
        }
    }
    Ok(())
}

/// The largest `summary.json` read: every run's totals, a few kilobytes each, for the most
/// runs a protocol may have.
pub(super) const MAX_SUMMARY_BYTES: u64 = 1 << 30;

/// Writes `summary` (or a run's `run.json`) atomically: a reader never sees half a file.
pub fn write_json(path: &Path, summary: &impl Serialize) -> Result<()> {
    crate::safe_io::write_atomically(path, |out| {
        serde_json::to_writer_pretty(&mut *out, summary)?;
        out.write_all(b"\n")
    })
    .with_context(|| format!("writing {}", path.display()))
}
