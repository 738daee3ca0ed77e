//! A results folder as the views read it — as last read, the report of its finished
//! runs, whether a newer one is being made, why the last read failed — and the thread
//! that reads it. No view owns it: the screen keeps it and lends it to the view shown.
//!
//! The folder is only read: no file is written or created there and its lock is never
//! taken (the writer is found without it, [`crate::folder_lock::holder`]); its files are
//! read as a folder from elsewhere is ([`crate::results::folder_state`]). The thread looks
//! at the folder every [`REFRESH`], reads it again when its files changed
//! ([`folder_changes`]: a finished folder is read once) and, when the set of finished runs
//! changed, makes the comparison again (a bootstrap of seconds for a large protocol), so
//! that the keys never wait for it.

use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

use anyhow::{Context, Result};

use crate::config::Budget;
use crate::report::Report;
use crate::results::folder_changes;
use crate::results::folder_state::{FolderReader, FolderState, RunProgress, RunStatus};
use crate::results::run_metrics::{self, RunFiles};
use crate::results::Status;
use crate::trainer::MethodId;
use crate::tui::follow;
use crate::tui::workbench::views::run::RunKey;

/// How often the folder is read again: a run's episode is a fraction of a second, its end
/// seconds to hours; a second keeps the progress current at a few small reads a second.
pub const REFRESH: Duration = Duration::from_secs(1);

/// The folder the views show.
pub struct Folder {
    /// As last read.
    pub state: FolderState,
    /// The report of its finished runs; `None` until one has finished.
    pub report: Option<Report>,
    /// The report of newly finished runs is being made (the one shown is older, or none).
    pub computing: bool,
    /// The last refresh's failure, shown until a read succeeds again: the views keep the
    /// last good read.
    pub read_error: Option<String>,
}

impl Folder {
    pub fn new(state: FolderState, report: Option<Report>) -> Self {
        Self {
            state,
            report,
            computing: false,
            read_error: None,
        }
    }

    /// A new read; `report` is `Some` when its finished runs changed (the report of
    /// those, or `Some(None)` when none finished).
    pub fn refreshed(&mut self, state: FolderState, report: Option<Option<Report>>) {
        self.state = state;
        if let Some(report) = report {
            self.report = report;
            self.computing = false;
        }
        self.read_error = None;
    }
}

/// What the Comparison and Curves views read of the folder shown: its methods, its runs
/// with their episodes, the report of the finished ones. A protocol's results folder
/// ([`Folder`]) and a `sapnet compare` folder
/// ([`super::compare_folder::CompareFolder`]) both are one; where they differ (a protocol
/// plans its runs and their budget, compare chose how its runs were set side by side),
/// each says its own.
pub trait Compared {
    /// The folder, which the views keep what they read of it by.
    fn dir(&self) -> &Path;
    /// Its methods, in its order.
    fn methods(&self) -> Vec<MethodId>;
    /// The runs method `index` is given (a protocol's plan) or has (compare's).
    fn planned_runs(&self, index: usize) -> usize;
    /// Every run, method by method, with its episodes so far.
    fn runs(&self) -> &[RunProgress];
    /// Where each run with episodes has its per-episode metrics.
    fn run_files(&self) -> Vec<RunFiles>;
    /// The library's sources, as the activation metrics name them.
    fn sources(&self) -> Vec<String>;
    /// The budget the runs are read against: `sample_efficiency.csv`'s axis and extent.
    fn budget(&self) -> Budget;
    /// The curves' moving average, in episodes.
    fn window(&self) -> usize;
    /// The report of the finished runs; `None` until there is one.
    fn report(&self) -> Option<&Report>;
    /// Whether a newer report is being made (the one shown is older, or none).
    fn computing(&self) -> bool;

    /// Runs finished to their end.
    fn finished_runs(&self) -> usize {
        self.runs()
            .iter()
            .filter(|r| r.status == RunStatus::Done)
            .count()
    }
}

impl Compared for Folder {
    fn dir(&self) -> &Path {
        &self.state.dir
    }

    fn methods(&self) -> Vec<MethodId> {
        MethodId::all(&self.state.config.protocol.methods)
    }

    fn planned_runs(&self, _: usize) -> usize {
        self.state.config.protocol.runs as usize
    }

    fn runs(&self) -> &[RunProgress] {
        &self.state.runs
    }

    fn run_files(&self) -> Vec<RunFiles> {
        run_metrics::run_files(&self.state)
    }

    fn sources(&self) -> Vec<String> {
        self.state.library.iter().map(|e| e.name.clone()).collect()
    }

    fn budget(&self) -> Budget {
        self.state.config.protocol.budget
    }

    fn window(&self) -> usize {
        self.state.config.protocol.moving_average
    }

    fn report(&self) -> Option<&Report> {
        self.report.as_ref()
    }

    fn computing(&self) -> bool {
        self.computing
    }
}

/// Whether `R` can resume `state`'s protocol where it is shown, and if not why, with what
/// to type instead: every command said here works when typed (tests/it/resume_cli.rs
/// follows each).
pub fn resumable(state: &FolderState) -> Result<(), String> {
    let dir = state.dir.display();
    // This process's own lock is the session's protocol, which its phase says (the last
    // read may have seen the lock before the protocol let it go).
    let writer = state
        .writer
        .as_ref()
        .filter(|w| w.pid != std::process::id());
    if let Some(writer) = writer {
        return Err(format!(
            "{} writes this folder and goes on there; once it ends or is stopped, R here (or \
             `sapnet --resume --out {dir}`) finishes what it left",
            writer.describe()
        ));
    }
    match state.status {
        Some(Status::Stopped | Status::Failed | Status::Running | Status::Interrupted) => Ok(()),
        Some(Status::Complete) => Err(format!(
            "this protocol is complete: nothing to resume (`sapnet --resume --runs N --out \
             {dir}`, N above its {}, adds runs to it)",
            state.config.protocol.runs
        )),
        None => Err(
            "summary.json has no status (written before --resume existed): nothing to resume"
                .into(),
        ),
    }
}

/// The run a resumed protocol is followed in: the first not finished of the method the UI
/// follows by default, else the first not finished.
pub fn first_unfinished(state: &FolderState) -> Option<RunKey> {
    let ids = MethodId::all(&state.config.protocol.methods);
    let preferred = follow::followed_method(&ids, None).ok().flatten();
    let unfinished = |method: Option<&MethodId>| {
        state
            .runs
            .iter()
            .filter(|r| r.status != RunStatus::Done)
            .find(|r| method.is_none_or(|m| *m == r.method))
            .map(|r| (r.method.label().to_string(), r.run))
    };
    unfinished(preferred.as_ref()).or_else(|| unfinished(None))
}

/// What the reading thread sends: the folder as read, with the report of its finished
/// runs when they changed (`Some(None)`: none finished); or why the read failed.
pub type Read = Result<(FolderState, Option<Option<Report>>), String>;

/// The thread that reads one folder; dropping this (however the screen ends) wakes the
/// thread and ends it.
pub struct FolderReads {
    pub reads: mpsc::Receiver<Read>,
    _stop: mpsc::Sender<()>,
}

impl FolderReads {
    /// Reads `dir` from now on, the first read at once.
    pub fn start(dir: &Path) -> Result<Self> {
        let looked = folder_changes::look(dir);
        Self::of(FolderReader::new(dir), looked)
    }

    /// Reads on with `reader` (which read the folder once already, after `looked`), the
    /// first read at once: it makes the report the screen opened without.
    pub fn of(reader: FolderReader, looked: folder_changes::Look) -> Result<Self> {
        let (reads_tx, reads) = mpsc::channel();
        let (stop_tx, stop) = mpsc::channel::<()>();
        std::thread::Builder::new()
            .name("workbench: reading the folder".into())
            .spawn(move || read_on(reader, looked, &reads_tx, &stop))
            .context("starting the thread that reads the folder")?;
        Ok(Self {
            reads,
            _stop: stop_tx,
        })
    }
}

/// Reads the folder at once, then again when its files changed ([`folder_changes`]:
/// looked at every [`REFRESH`]; `looked` is the look of the read on screen) until `stop`
/// is dropped, sending each read, with the report made again when the finished runs
/// changed.
fn read_on(
    mut reader: FolderReader,
    mut looked: folder_changes::Look,
    reads: &mpsc::Sender<Read>,
    stop: &mpsc::Receiver<()>,
) {
    lowest_priority();
    let mut reported = None;
    let mut first = true;
    loop {
        if !first {
            match stop.recv_timeout(REFRESH) {
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                _ => return,
            }
            let look = folder_changes::look(reader.dir());
            if look == looked {
                continue;
            }
            looked = look;
        }
        first = false;
        let read = match reader.read() {
            Ok(folder) => {
                let finished = folder.finished_key();
                if reported.as_ref() == Some(&finished) {
                    Ok((folder, None))
                } else {
                    let report = (!finished.is_empty()).then(|| folder.report());
                    reported = Some(finished);
                    Ok((folder, Some(report)))
                }
            }
            Err(err) => Err(format!("{err:#}")),
        };
        if reads.send(read).is_err() {
            return;
        }
    }
}

/// Puts the calling thread at nice 19: the comparison made again as runs end (a bootstrap
/// of seconds for a large protocol) then takes what training leaves of the cores, never
/// their time (on Linux a thread has a nice value of its own). Best effort: a refusal
/// leaves the thread as it was.
pub(crate) fn lowest_priority() {
    // SAFETY: gettid and setpriority on this thread, no memory involved.
    unsafe {
        let tid = libc::gettid();
        libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, 19);
    }
}
