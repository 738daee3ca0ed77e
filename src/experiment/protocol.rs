//! A protocol, run: what the config's protocol lists, with progress on stderr (or told to a
//! [`Tap`]: the workbench's screen) and results on disk, consuming the trainer's event
//! stream. Every front end drives this one engine: `sapnet --headless`, the workbench,
//! `sweep run`.
//!
//! Runs are spread over `jobs` threads (one per core by default). Each run writes its own
//! record as it trains and renames it into `runs/<method>-run<r>/` when it ends
//! ([`results::records`]); the files below are put together from those records in a fixed order
//! when the protocol ends, is stopped, or is found killed ([`results::assemble`]):
//! - `episodes.csv`: one row per training episode (`run, method, episode, reward, steps,
//!   loss, statistic_loss, epsilon, policy, wall_s`; `policy` names the source that
//!   acted most in the episode, for methods that reuse the library);
//! - `tests.csv`: the greedy test returns of each run (`run, method, test, return, policy`);
//! - `activations.csv`: per episode of every run that reuses the library, each source's
//!   score (SAP-Net: its activation), probability of being picked and steps acted;
//! - `trace.csv` (with `--trace`): every `spread` call of SAP-Net's activations;
//! - `comparison.csv`: one row per method, the measures of [`crate::report::comparison`];
//! - `summary.json`: the status (`running`, `complete`, `stopped`, `failed`,
//!   `interrupted`), the runs not finished, the config, the source library, each run's
//!   totals and test returns; written when the protocol starts and after every run;
//! - `policies/<method>-run<r>.{safetensors,ron}` (e.g. `dqn-100-100-run0`, `sapnet-run0`):
//!   each trained network — a reusing method's chosen source after fine-tuning — in the
//!   policy library's format;
//! - `learning_curve.png`/`.svg`, `tests.png`, `activations.png`: the paper's Fig. 5–8;
//!   `selections.png`: who acted, per reusing method.
//!
//! `--resume` ([`resume`]) continues a stopped, failed or killed protocol: finished runs
//! are kept, the others run again from their seeds, giving the numbers an uninterrupted
//! protocol gives.
//!
//! Each run of a reusing method that finishes also adds its chosen source, fine-tuned, to
//! the policy library, as `<library>/<target task>/chosen/<out dir>-<method>-run<r>`
//! (Algorithm 3's last step); the sources beside it are never touched, and no policy
//! already there is replaced.

use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;
use std::time::Instant;

use anyhow::{bail, Context, Result};

use super::observer::ResultFiles;
use super::output::{self, open_output, OutputOptions};
use super::tap::{Tap, Tapped};
use super::tensorboard_runs::TensorBoardRuns;
use crate::config::{Budget, Config};
use crate::env::PythonSettings;
use crate::experiment::{self, LibraryCopies};

use crate::folder_lock::FolderLock;
use crate::progress::{Progress, Unit};
use crate::report::LibraryEntry;
use crate::results::{self, assemble, records, Ending, Status, Summary};
use crate::trainer::Command;

/// How the protocol runs.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Runs trained at the same time.
    pub jobs: usize,
    /// The policy library SAP-Net reuses (`<library>/<task>/`).
    pub library: crate::sources::LibraryRoot,
    /// Write every spread call of SAP-Net's runs to `trace.csv`.
    pub trace: bool,
    /// Add each reusing run's chosen policy to the library (Algorithm 3's last step).
    /// Sweeps leave it off: their library is shared, read-only, by many processes.
    pub copy_chosen: bool,
    /// Write each run's TensorBoard event file under `<out>/tensorboard/`.
    pub tensorboard: bool,
}

/// Runs the protocol of `config`: trains the source library if SAP-Net needs one that is
/// not there (and `options` allow it), then every (method, run). `commands` carries
/// [`Command::Stop`] (from Ctrl-C): the runs in progress then end early, no new ones
/// start, and everything written so far is kept.
pub fn run(
    config: &Config,
    output: &OutputOptions,
    options: &RunOptions,
    commands: &Receiver<Command>,
) -> Result<Summary> {
    let opened = OpenedOutput::open(output)?;
    run_opened(config, output, opened, options, commands, None)
}

/// An output folder taken for a protocol: its lock held, the results `--force` replaces
/// moved aside. Taken before a terminal UI opens, so that a folder that is refused is
/// said on the command line.
pub struct OpenedOutput {
    lock: FolderLock,
    replaced: Option<PathBuf>,
    /// The folder did not exist before: a protocol refused before writing anything
    /// leaves none behind.
    created: bool,
}

impl OpenedOutput {
    pub fn open(output: &OutputOptions) -> Result<Self> {
        let created = !output.dir.exists();
        let (lock, replaced) = open_output(output)?;
        Ok(Self {
            lock,
            replaced,
            created,
        })
    }
}

/// [`run`] into a folder already taken, with `tap` (if any) told every run's events and
/// commands as they come: the protocol the workbench runs, the same one headless runs.
pub fn run_opened(
    config: &Config,
    output: &OutputOptions,
    opened: OpenedOutput,
    options: &RunOptions,
    commands: &Receiver<Command>,
    tap: Option<&Tap>,
) -> Result<Summary> {
    let OpenedOutput {
        lock,
        replaced,
        created,
    } = opened;
    let summary = protocol(config, &output.dir, options, None, commands, tap);
    if summary.is_err() && created {
        // Refused before anything was written (a library that cannot load, a config the
        // library cannot take): leave no empty folder behind. A folder holding anything is
        // kept: it is a failed run's record.
        drop(lock);
        let _ = std::fs::remove_file(output.dir.join(crate::folder_lock::LOCK_FILE));
        let _ = std::fs::remove_dir(&output.dir);
    }
    // Delete last: the old results go only once the new ones are written.
    if let (Ok(_), Some(replaced)) = (&summary, &replaced) {
        crate::failpoint::point("replaced-deleting");
        if let Err(err) = std::fs::remove_dir_all(replaced) {
            eprintln!(
                "warning: the results --force replaced could not all be deleted from {}: {err}",
                replaced.display()
            );
        }
    }
    summary.map_err(|err| match &replaced {
        Some(replaced) => err.context(format!(
            "the results --force replaced are kept in {}",
            replaced.display()
        )),
        None => err,
    })
}

/// Continues the protocol whose results are in `dir` (a stopped, failed or killed one):
/// with the config and `--trace` it began with, its finished runs kept, the others run
/// again from their seeds. `options.trace` is ignored. With `runs`, the protocol is
/// extended to that many runs per method, finished or not: run r's seeds do not depend
/// on the number of runs, so the result is the protocol that had `runs` from the start.
pub fn resume(
    dir: &Path,
    runs: Option<u32>,
    added: Option<&AddedMethods>,
    python: &PythonSettings,
    options: &RunOptions,
    commands: &Receiver<Command>,
) -> Result<Summary> {
    resume_tapped(dir, runs, added, python, options, commands, None)
}

/// [`resume`], with `tap` (if any) told every run's events and commands as they come.
pub fn resume_tapped(
    dir: &Path,
    runs: Option<u32>,
    added: Option<&AddedMethods>,
    python: &PythonSettings,
    options: &RunOptions,
    commands: &Receiver<Command>,
    tap: Option<&Tap>,
) -> Result<Summary> {
    let stopped = StoppedProtocol::take(dir, runs, added, python)?;
    resume_taken(stopped, options, commands, tap)
}

/// A stopped, failed or killed protocol's folder taken for resuming it: its lock held, its
/// stored config read and checked, its records found in their places. Taken before a
/// terminal UI opens (as [`OpenedOutput`] is), so that a folder that cannot be resumed is
/// said on the command line, or by `sapnet open`'s `R` without leaving the screen.
pub struct StoppedProtocol {
    lock: FolderLock,
    dir: PathBuf,
    header: results::SummaryHeader,
}

impl StoppedProtocol {
    /// Takes `dir` for resuming, extended to `runs` per method or by `added`'s methods;
    /// refused, saying why, when another process writes it or it holds nothing to resume.
    pub fn take(
        dir: &Path,
        runs: Option<u32>,
        added: Option<&AddedMethods>,
        python: &PythonSettings,
    ) -> Result<Self> {
        if !dir.is_dir() {
            bail!(
                "--out {}: no such results directory to resume (it would hold summary.json)",
                dir.display()
            );
        }
        let lock = crate::folder_lock::FolderLock::acquire(dir, "a resume")?;
        output::finish_replacement(dir)?;
        let mut header = results::read_header(dir)?;
        // The folder says what to train, never what program or module runs it.
        header.config.check_received(python).map_err(|e| {
            anyhow::anyhow!(
                "{}: the stored config: {e}",
                dir.join("summary.json").display()
            )
        })?;
        header.config.run_with(python);
        if let Some(runs) = runs {
            let had = header.config.protocol.runs;
            if runs < had {
                bail!(
                    "{} holds a protocol of {had} runs per method: --runs {runs} would drop runs \
                     (--resume --runs can only extend it)",
                    dir.display()
                );
            }
            if runs > had {
                header.config.protocol.runs = runs;
                header.config.validate().map_err(|e| {
                    anyhow::anyhow!("{}: --runs {runs}: {e}", dir.join("summary.json").display())
                })?;
                header.status = Some(Status::Stopped);
            }
        }
        if let Some(added) = added {
            add_methods(&mut header.config, added)
                .map_err(|e| anyhow::anyhow!("--add-methods {}: {e}", added.origin.display()))?;
            header.status = Some(Status::Stopped);
        }
        match header.status {
            None | Some(Status::Complete) => bail!(
                "{} holds a finished protocol (summary.json: status {}): nothing to resume",
                dir.display(),
                header
                    .status
                    .map_or("absent, written before --resume existed".into(), |s| {
                        format!("{s:?}").to_lowercase()
                    })
            ),
            Some(_) => {}
        }
        // Checked before anything is built or trained: a link planted among the records (or
        // as `runs/` itself), or a record out of its place, ends the resume before it trains.
        records::read(dir, &header.config)?;
        Ok(Self {
            lock,
            dir: dir.to_path_buf(),
            header,
        })
    }

    /// The config the protocol resumes with (its stored one, extended as asked).
    pub fn config(&self) -> &Config {
        &self.header.config
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

/// Resumes the protocol of a folder taken for it, with `tap` (if any) told every run's
/// events and commands as they come: what `--headless --resume` does, and the UI's.
pub fn resume_taken(
    stopped: StoppedProtocol,
    options: &RunOptions,
    commands: &Receiver<Command>,
    tap: Option<&Tap>,
) -> Result<Summary> {
    let StoppedProtocol { lock, dir, header } = stopped;
    let options = RunOptions {
        trace: header.trace,
        ..options.clone()
    };
    let summary = protocol(
        &header.config,
        &dir,
        &options,
        Some(header.library.as_deref()),
        commands,
        tap,
    )?;
    output::finish_replacement(&dir)?;
    drop(lock);
    Ok(summary)
}

/// A config whose methods extend a folder's protocol (`--resume --add-methods`).
pub struct AddedMethods {
    pub config: Config,
    /// Where it was read from, for errors.
    pub origin: std::path::PathBuf,
}

/// `stored` with the methods `added` lists after its own. Refused unless `added` lists
/// `stored`'s methods first, in order, and equals it in every other field but the number of
/// runs: then every finished run is the run the extended protocol would have made, since a
/// run's seeds come from its method's label and its index, never from the list.
fn add_methods(stored: &mut Config, added: &AddedMethods) -> Result<(), String> {
    let had = &stored.protocol.methods;
    let wanted = &added.config.protocol.methods;
    if wanted.len() <= had.len() || !wanted.starts_with(had) {
        let labels = |methods: &[crate::reuse::Method]| {
            methods
                .iter()
                .map(|m| m.label())
                .collect::<Vec<_>>()
                .join(", ")
        };
        return Err(format!(
            "field `protocol.methods`: expected the folder's methods first, in order ({}), then \
             the methods to add; got {}",
            labels(had),
            labels(wanted)
        ));
    }
    let mut same = added.config.clone();
    same.protocol.methods.clone_from(had);
    same.protocol.runs = stored.protocol.runs;
    let fields = [
        ("env", same.env == stored.env),
        ("dqn", same.dqn == stored.dqn),
        ("sapnet", same.sapnet == stored.sapnet),
        ("sources", same.sources == stored.sources),
        ("protocol", same.protocol == stored.protocol),
        ("seed", same.seed == stored.seed),
    ];
    if let Some((field, _)) = fields.iter().find(|(_, equal)| !equal) {
        return Err(format!(
            "field `{field}`: expected the folder's own (in its summary.json's config): the \
             runs it holds were trained with it"
        ));
    }
    if same != *stored {
        return Err("expected the folder's config in every field but `protocol.methods`".into());
    }
    stored.protocol.methods.clone_from(wanted);
    stored.validate()
}

/// The protocol into `out`. `resumed` is `None` for a new protocol, else the library the
/// protocol began with (which must be the one loaded now).
fn protocol(
    config: &Config,
    out: &Path,
    options: &RunOptions,
    resumed: Option<Option<&[LibraryEntry]>>,
    commands: &Receiver<Command>,
    tap: Option<&Tap>,
) -> Result<Summary> {
    let mut plan = experiment::plan(config, &options.library, options.jobs, commands)?;
    let library: Option<Vec<LibraryEntry>> = plan.sources.as_deref().map(|s| library_entries(s));
    let kept = match resumed {
        Some(began_with) => {
            if began_with != library.as_deref() {
                bail!(
                    "the source library in {} is not the one {} began with (summary.json \
                     lists its names, architectures and scores): resume with the same \
                     --library",
                    crate::sources::library_dir(&options.library.path, config).display(),
                    out.display()
                );
            }
            keep_finished(out, config, &mut plan.specs, tap.is_none())?
        }
        None => Vec::new(),
    };
    for spec in &mut plan.specs {
        spec.stream.trace = options.trace && spec.method.kind.spreads;
    }
    if let Some(tap) = tap {
        tap.stream(&mut plan.specs);
    }

    // On disk before the first run, so that even a killed protocol says what it was.
    let runs_dir = out.join(records::RUNS);
    std::fs::create_dir_all(&runs_dir)
        .with_context(|| format!("creating {}", runs_dir.display()))?;
    crate::failpoint::point("runs-created");
    let mut summary = Summary::new(config, options.trace);
    summary.library.clone_from(&library);
    summary.unfinished = records::unfinished(config, &kept);
    summary.runs = kept.into_iter().map(|f| f.summary).collect();
    results::write_json(&out.join("summary.json"), &summary)?;
    crate::failpoint::point("summary-started");

    let names: Vec<String> = plan
        .sources
        .as_ref()
        .map(|s| s.iter().map(|p| p.name.clone()).collect())
        .unwrap_or_default();
    let copies = options
        .copy_chosen
        .then(|| LibraryCopies::new(config, out, &options.library.path));
    let tensorboard = if options.tensorboard {
        Some(TensorBoardRuns::new(out, names.clone(), &plan.specs)?)
    } else {
        None
    };
    // Bars on stderr would be drawn over a screen on the terminal: a tapped protocol
    // shows its progress there instead.
    let progress = tap
        .is_none()
        .then(|| planned_progress(config, plan.specs.len()));
    let mut files = Tapped {
        files: ResultFiles::new(
            out.to_path_buf(),
            config.clone(),
            names,
            progress,
            summary,
            copies,
            tensorboard,
        ),
        tap,
    };
    let started = Instant::now();
    let outcome = crate::trainer::schedule(plan.specs, options.jobs, commands, &mut files);
    files.files.finish_progress(matches!(outcome, Ok(false)));
    let (status, error) = match outcome {
        Ok(false) => (Status::Complete, None),
        Ok(true) => (Status::Stopped, None),
        Err(err) => (Status::Failed, Some(format!("{err:#}"))),
    };
    let ending = Ending {
        status,
        error,
        wall_s: started.elapsed().as_secs_f64(),
    };
    let summary = assemble(out, config, library, options.trace, ending)?;
    if let Some(error) = &summary.error {
        bail!("{error}");
    }
    Ok(summary)
}

/// What summary.json records of the library: enough to tell, on resuming, that it is the
/// one the protocol began with.
fn library_entries(sources: &[crate::trainer::SourcePolicy]) -> Vec<LibraryEntry> {
    sources
        .iter()
        .map(|s| LibraryEntry {
            name: s.name.clone(),
            hidden: s.description.hidden.clone(),
            task: s.description.source_task.clone(),
            activation: s.description.activation.clone(),
            final_score: s.final_score,
        })
        .collect()
}

/// A resumed protocol's finished runs, kept: what its unfinished ones left is cleared and
/// they leave `specs`, which the protocol runs again from their seeds.
fn keep_finished(
    out: &Path,
    config: &Config,
    specs: &mut Vec<crate::trainer::RunSpec>,
    say: bool,
) -> Result<Vec<records::RunFolder>> {
    let found = records::read(out, config)?;
    records::clear_unfinished(out, &found)?;
    let kept: Vec<records::RunFolder> = found
        .into_iter()
        .filter(|f| !f.summary.record.stopped)
        .collect();
    specs.retain(|spec| {
        !kept
            .iter()
            .any(|f| f.summary.record.method == spec.method && f.summary.record.run == spec.run)
    });
    // A screen on the terminal says it itself.
    if say {
        eprintln!(
            "resuming {}: {} runs finished before, {} to run",
            out.display(),
            kept.len(),
            specs.len()
        );
    }
    Ok(kept)
}

/// The progress bar of `runs` runs: a step budget bounds runs in steps, else their episodes
/// do.
fn planned_progress(config: &Config, runs: usize) -> Progress {
    match config.protocol.budget {
        Budget::Steps(steps) => Progress::new(steps * runs as u64, Unit::Steps),
        Budget::Episodes(episodes) => {
            Progress::new(u64::from(episodes) * runs as u64, Unit::Episodes)
        }
    }
}
