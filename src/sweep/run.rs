//! `sapnet sweep run`: one cell (as a Slurm array task, a GNU parallel job or by hand), or
//! every missing cell on this machine; `sapnet sweep prepare`: the libraries the cells
//! reuse, trained once before the array starts.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::Duration;

use anyhow::{bail, Context, Result};

use crate::config::Config;
use crate::env::PythonSettings;
use crate::experiment::{self, OutputOptions, RunOptions};
use crate::folder_lock::FolderLock;
use crate::policy_store::sha256_hex;
use crate::results::sweep::status::{state, CellState};
use crate::results::sweep::{
    cell_config, cell_failure, cell_lock, cell_name, cell_partial, cell_results, Manifest,
};
use crate::sources::{self, LibraryRoot};
use crate::trainer::Command as TrainerCommand;

/// How a `sweep run` of one cell ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellRun {
    /// Its results were there already.
    AlreadyDone,
    Finished,
    /// Stopped by a signal; its partial results are run again next time.
    Stopped,
}

/// The cell a scheduler asks for: `SLURM_ARRAY_TASK_ID`, else `JOB_COMPLETION_INDEX` (a
/// Kubernetes indexed Job).
pub fn cell_from_environment() -> Result<Option<usize>> {
    for name in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"] {
        if let Ok(value) = std::env::var(name) {
            let id = value
                .trim()
                .parse()
                .with_context(|| format!("{name}={value:?} is not a cell number"))?;
            return Ok(Some(id));
        }
    }
    Ok(None)
}

/// Runs cell `id` headless into a partial folder, renamed to `results/NNNN` once whole. A
/// cell done already is skipped; a partial one a killed process left is run again. The
/// library must be there (`sweep prepare`): cells never train it, as many run at once.
pub fn run_cell(
    sweep: &Path,
    id: usize,
    jobs: usize,
    python: &PythonSettings,
    stop: &Receiver<TrainerCommand>,
) -> Result<CellRun> {
    let manifest = Manifest::read(sweep)?;
    let Some(entry) = manifest.cells.iter().find(|c| c.id == id) else {
        bail!(
            "cell {id}: the sweep {} has cells 0 to {}",
            sweep.display(),
            manifest.cells.len().saturating_sub(1)
        );
    };
    // One process per cell: a second `sweep run --cell K` (a requeued job, an orphan of a
    // killed `--all`) is refused while the first runs, instead of deleting its partial.
    let results = sweep.join("results");
    crate::safe_io::real_dir(&results).with_context(|| format!("{}", results.display()))?;
    let _lock = FolderLock::acquire_file(
        &cell_lock(sweep, id),
        &cell_results(sweep, id),
        &format!("cell {}", cell_name(id)),
    )?;
    if state(sweep, id) == CellState::Done {
        return Ok(CellRun::AlreadyDone);
    }
    let outcome = attempt(sweep, &manifest, entry, jobs, python, stop);
    let failure = cell_failure(sweep, id);
    match &outcome {
        Err(err) => {
            // A failed attempt leaves its error, not a partial result that would read as
            // running.
            let _ = std::fs::remove_dir_all(cell_partial(sweep, id));
            let failed = failure.parent().unwrap_or(sweep);
            if crate::safe_io::real_dir(failed).is_ok() {
                let _ = crate::safe_io::write_bytes(&failure, format!("{err:#}\n").as_bytes());
            }
        }
        Ok(CellRun::Finished) => {
            let _ = std::fs::remove_file(&failure);
        }
        Ok(_) => {}
    }
    outcome
}

fn attempt(
    sweep: &Path,
    manifest: &Manifest,
    entry: &crate::results::sweep::CellEntry,
    jobs: usize,
    python: &PythonSettings,
    stop: &Receiver<TrainerCommand>,
) -> Result<CellRun> {
    let id = entry.id;
    let path = cell_config(sweep, id);
    let text = crate::ron_file::read_folder_text(&path)?;
    if sha256_hex(text.as_bytes()) != entry.config_sha256 {
        bail!(
            "{} changed after the sweep was planned (its SHA-256 differs from sweep.ron): \
             `sapnet sweep plan` with the same grid and --out writes it back as planned; to run \
             other settings, change the grid and plan into another --out",
            path.display()
        );
    }
    let config = received_cell(&text, &path, python)?;
    let partial = cell_partial(sweep, id);
    if std::fs::symlink_metadata(&partial).is_ok() {
        std::fs::remove_dir_all(&partial)
            .or_else(|_| std::fs::remove_file(&partial))
            .with_context(|| format!("removing the partial cell {}", partial.display()))?;
    }
    let output = OutputOptions {
        dir: partial.clone(),
        force: false,
    };
    let options = RunOptions {
        jobs,
        library: LibraryRoot {
            path: manifest.library.clone(),
            train_if_missing: false,
        },
        trace: false,
        copy_chosen: false,
        tensorboard: false,
    };
    let reuses = config.protocol.methods.iter().any(|m| m.kind().reuses);
    if reuses && sources::needs_training(&config, &manifest.library)? {
        bail!(
            "cell {}: the source library {} is missing or unfinished; `sapnet sweep prepare \
             {}` trains it once, before the cells",
            cell_name(id),
            sources::library_dir(&manifest.library, &config).display(),
            sweep.display()
        );
    }
    let summary = experiment::run(&config, &output, &options, stop)
        .with_context(|| format!("cell {}", cell_name(id)))?;
    if summary.stopped() {
        return Ok(CellRun::Stopped);
    }
    // Done means every planned run is there, finished.
    let planned = config.protocol.methods.len() * config.protocol.runs as usize;
    let finished = summary.runs.iter().filter(|r| !r.record.stopped).count();
    if summary.status != crate::results::Status::Complete || finished != planned {
        bail!(
            "cell {}: {finished} of its {planned} runs finished (status {:?}): not marked done",
            cell_name(id),
            summary.status
        );
    }
    let results = cell_results(sweep, id);
    crate::failpoint::point("cell-finished");
    std::fs::rename(&partial, &results)
        .with_context(|| format!("renaming {} into place", partial.display()))?;
    Ok(CellRun::Finished)
}

/// A cell's config, read from a sweep folder that may come from elsewhere: it names what to
/// train, never the program or module that runs it ([`Config::check_received`]); the
/// user's own `--python` and `--module-dir` run it.
fn received_cell(text: &str, path: &Path, python: &PythonSettings) -> Result<Config> {
    let mut config = Config::from_ron(text, &path.display().to_string())?;
    config
        .check_received(python)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    config.run_with(python);
    Ok(config)
}

/// The flags that give `python` to a cell's own process.
fn python_flags(python: &PythonSettings) -> Vec<std::ffi::OsString> {
    let mut flags = Vec::new();
    for (flag, path) in [
        ("--python", &python.interpreter),
        ("--module-dir", &python.module_dir),
    ] {
        if let Some(path) = path {
            flags.push(flag.into());
            flags.push(path.into());
        }
    }
    for module in &python.allowed_modules {
        flags.push("--allow-module".into());
        flags.push(module.into());
    }
    flags
}

/// Trains every library the cells reuse that is missing or unfinished, one after the other.
/// Training writes a library where `sweep.ron` says, and a sweep folder may come from
/// elsewhere: so a library that needs training is trained only into the `library` the
/// user names (`--library`), which must be the sweep's.
pub fn prepare(
    sweep: &Path,
    library: Option<&Path>,
    python: &PythonSettings,
    stop: &Receiver<TrainerCommand>,
) -> Result<()> {
    let manifest = Manifest::read(sweep)?;
    let _lock = FolderLock::acquire(sweep, "a sweep prepare")?;
    let confirmed = match library {
        Some(given) => {
            let given = super::plan::absolute(given)?;
            if given != manifest.library {
                bail!(
                    "--library {}: the cells of {} reuse {} (sweep.ron); prepare trains that \
                     library, or plan the sweep again with --library {}",
                    given.display(),
                    sweep.display(),
                    manifest.library.display(),
                    given.display()
                );
            }
            true
        }
        None => false,
    };
    let mut seen = Vec::new();
    for entry in &manifest.cells {
        let path = cell_config(sweep, entry.id);
        let config = received_cell(&crate::ron_file::read_folder_text(&path)?, &path, python)?;
        if !config.protocol.methods.iter().any(|m| m.kind().reuses) {
            continue;
        }
        let training = sources::LibraryTraining::of(&config);
        let dir = sources::library_dir(&manifest.library, &config);
        // Cells that differ by seed (or test episodes) reuse one library: it is readied once.
        if seen
            .iter()
            .any(|(d, t): &(PathBuf, sources::LibraryTraining)| {
                *d == dir && t.differences(&training).is_empty()
            })
        {
            continue;
        }
        seen.push((dir.clone(), training));
        if !confirmed && sources::needs_training(&config, &manifest.library)? {
            bail!(
                "the library {} of cell {} needs training: `sapnet sweep prepare {} --library \
                 {}` trains it (named on the command line, since a sweep folder from elsewhere \
                 must not choose where sapnet writes)",
                dir.display(),
                entry.id,
                super::plan::quote(sweep),
                super::plan::quote(&manifest.library)
            );
        }
        let root = LibraryRoot {
            path: manifest.library.clone(),
            train_if_missing: true,
        };
        sources::ensure_library(&config, &root, stop)
            .with_context(|| format!("the library {} of cell {}", dir.display(), entry.id))?;
        eprintln!("library {} ready", dir.display());
    }
    Ok(())
}

/// Runs every cell not done yet on this machine, `jobs` cells at a time, each a `sapnet
/// sweep run --cell K` process of its own (as under Slurm or parallel) logging to
/// `logs/NNNN.{out,err}`; a line of progress over cells on stderr. Returns how many failed.
pub fn run_all(sweep: &Path, jobs: usize, python: &PythonSettings) -> Result<usize> {
    let manifest = Manifest::read(sweep)?;
    let exe = std::env::current_exe().context("finding the sapnet binary")?;
    let todo: Vec<usize> = manifest
        .cells
        .iter()
        .map(|c| c.id)
        .filter(|&id| state(sweep, id) != CellState::Done)
        .collect();
    let total = manifest.cells.len();
    let mut done = total - todo.len();
    let mut failed = 0;
    let mut queue = todo.into_iter();
    let mut running: Vec<(usize, Child)> = Vec::new();
    let mut said = String::new();
    let logs = sweep.join("logs");
    crate::safe_io::real_dir(&logs).with_context(|| format!("{}", logs.display()))?;
    loop {
        while running.len() < jobs.max(1) {
            let Some(id) = queue.next() else { break };
            // Created anew, never written through a link planted in the folder.
            let log = |ext: &str| {
                let path = logs.join(format!("{}.{ext}", cell_name(id)));
                crate::safe_io::create(&path)
                    .with_context(|| format!("creating {}", path.display()))
            };
            let child = Command::new(&exe)
                .args(["sweep", "run"])
                .arg(sweep)
                .args(["--cell", &id.to_string(), "--jobs", "1"])
                .args(python_flags(python))
                .stdout(Stdio::from(log("out")?))
                .stderr(Stdio::from(log("err")?))
                .spawn()
                .with_context(|| format!("starting cell {id}"))?;
            running.push((id, child));
        }
        if running.is_empty() {
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
        let mut still = Vec::new();
        for (id, mut child) in running {
            match child.try_wait()? {
                Some(status) if status.success() => done += 1,
                Some(_) => {
                    failed += 1;
                    eprintln!(
                        "cell {}: failed, see {}",
                        cell_name(id),
                        logs.join(format!("{}.err", cell_name(id))).display()
                    );
                }
                None => still.push((id, child)),
            }
        }
        running = still;
        let line = format!(
            "cells: {done}/{total} done, {} running, {failed} failed",
            running.len()
        );
        if line != said {
            // One line redrawn on a terminal; a line per change in a log.
            if std::io::stderr().is_terminal() {
                eprint!("\r{line}   ");
            } else {
                eprintln!("{line}");
            }
            said = line;
        }
        if crate::signals::received().is_some() {
            // The children got the signal too (one process group): wait for them to stop.
            for (_, child) in &mut running {
                let _ = child.wait();
            }
            eprintln!();
            bail!("stopped by the user: finished cells are kept; run again to finish the rest");
        }
    }
    eprintln!();
    Ok(failed)
}
