//! Headless mode: runs what the config's protocol lists, with progress on stderr and
//! results on disk, consuming the trainer's event stream.
//!
//! Runs are spread over `jobs` threads (one per core by default). Each run writes its own
//! record as it trains and renames it into `runs/<method>-run<r>/` when it ends
//! ([`records`]); the files below are put together from those records in a fixed order
//! when the protocol ends, is stopped, or is found killed ([`assemble`]):
//! - `episodes.csv`: one row per training episode (`run, method, episode, reward, steps,
//!   loss, statistic_loss, epsilon, policy, wall_s`; `policy` is the source that acted
//!   most in the episode, for methods that reuse the library);
//! - `tests.csv`: the greedy test returns of each run (`run, method, test, return, policy`);
//! - `activations.csv`: per episode of every run that reuses the library, each source's
//!   score (SAP-Net: its activation), probability of being picked and steps acted;
//! - `trace.csv` (with `--trace`): every `spread` call of SAP-Net's activations;
//! - `comparison.csv`: one row per method, the measures of [`comparison`];
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

mod assemble;
pub mod comparison;
mod plots;
mod progress;
mod records;
mod replot;
mod results;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;
use std::time::Instant;

use anyhow::{bail, Context, Result};

use crate::config::{Config, MethodKind};
use crate::experiment::{self, policy_info, LibraryCopies, Observer};
use crate::policy_store::{self, PolicyInfo, TrainingBudget};
use crate::trainer::{Command, Divergence, Event, MethodId, RunOutcome, RunSpec, TrainerError};

use assemble::{assemble, Ending};
pub use plots::{write_all as write_plots, Curve, PlotData};
pub(crate) use progress::{Progress, Unit};
pub use records::run_name;
use records::RunWriter;
pub use replot::replot;
pub use results::{LibraryEntry, RunSummary, Status, Summary};

/// Entries that mark a directory as holding results already.
const RESULT_FILES: [&str; 8] = [
    "episodes.csv",
    "tests.csv",
    "activations.csv",
    "trace.csv",
    "comparison.csv",
    "summary.json",
    "policies",
    records::RUNS,
];

/// Files a run draws, replaced with the results.
const PLOT_FILES: [&str; 5] = [
    "learning_curve.png",
    "learning_curve.svg",
    "tests.png",
    "activations.png",
    "selections.png",
];

/// Where `--force` moves the results it replaces until the new ones are written.
const REPLACED: &str = ".replaced";
/// Where results go and whether old ones may be replaced.
#[derive(Debug, Clone)]
pub struct OutputOptions {
    pub dir: PathBuf,
    /// Replace results already in `dir`.
    pub force: bool,
}

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
    let replaced = prepare_output(output)?;
    let summary = protocol(config, &output.dir, options, None, commands);
    // Delete last: the old results go only once the new ones are written.
    if let (Ok(_), Some(replaced)) = (&summary, &replaced) {
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
/// again from their seeds. `options.trace` is ignored.
pub fn resume(dir: &Path, options: &RunOptions, commands: &Receiver<Command>) -> Result<Summary> {
    let header = replot::read_header(dir)?;
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
    let options = RunOptions {
        trace: header.trace,
        ..options.clone()
    };
    protocol(
        &header.config,
        dir,
        &options,
        Some(header.library.as_deref()),
        commands,
    )
}

/// A finished results directory, read back: its config, library, runs and each run's
/// training returns (what the comparison is computed from).
pub struct Results {
    pub config: Config,
    pub library: Option<Vec<results::LibraryEntry>>,
    pub runs: Vec<RunSummary>,
    pub rewards: BTreeMap<(MethodId, u32), Vec<f64>>,
}

/// Reads the results in `dir` from its summary and run records.
pub fn read_results(dir: &Path) -> Result<Results> {
    let header = replot::read_header(dir)?;
    let folders = records::read(dir, &header.config)?;
    let rewards = assemble::rewards(&folders)?;
    Ok(Results {
        config: header.config,
        library: header.library,
        runs: folders.into_iter().map(|f| f.summary).collect(),
        rewards,
    })
}

/// The protocol into `out`. `resumed` is `None` for a new protocol, else the library the
/// protocol began with (which must be the one loaded now).
fn protocol(
    config: &Config,
    out: &Path,
    options: &RunOptions,
    resumed: Option<Option<&[results::LibraryEntry]>>,
    commands: &Receiver<Command>,
) -> Result<Summary> {
    let mut plan = experiment::plan(config, &options.library, options.jobs, commands)?;
    let library: Option<Vec<results::LibraryEntry>> = plan.sources.as_ref().map(|sources| {
        sources
            .iter()
            .map(|s| results::LibraryEntry {
                name: s.name.clone(),
                hidden: s.description.hidden.clone(),
                task: s.description.source_task.clone(),
                final_score: s.final_score,
            })
            .collect()
    });
    let mut kept = Vec::new();
    if let Some(began_with) = resumed {
        if began_with != library.as_deref() {
            bail!(
                "the source library in {} is not the one {} began with (summary.json lists \
                 its names, architectures and scores): resume with the same --library",
                crate::sources::library_dir(&options.library.path, config).display(),
                out.display()
            );
        }
        let found = records::read(out, config)?;
        records::clear_unfinished(out, &found)?;
        kept = found
            .into_iter()
            .filter(|f| !f.summary.record.stopped)
            .collect();
        plan.specs.retain(|spec| {
            !kept
                .iter()
                .any(|f| f.summary.record.method == spec.method && f.summary.record.run == spec.run)
        });
        eprintln!(
            "resuming {}: {} runs finished before, {} to run",
            out.display(),
            kept.len(),
            plan.specs.len()
        );
    }
    for spec in &mut plan.specs {
        spec.stream.trace = options.trace && spec.method.kind == MethodKind::SapNet;
    }

    // On disk before the first run, so that even a killed protocol says what it was.
    let runs_dir = out.join(records::RUNS);
    std::fs::create_dir_all(&runs_dir)
        .with_context(|| format!("creating {}", runs_dir.display()))?;
    let mut summary = Summary::new(config, options.trace);
    summary.library.clone_from(&library);
    summary.unfinished = records::unfinished(config, &kept);
    summary.runs = kept.into_iter().map(|f| f.summary).collect();
    results::write_json(&out.join("summary.json"), &summary)?;

    let names = plan
        .sources
        .as_ref()
        .map(|s| s.iter().map(|p| p.name.clone()).collect())
        .unwrap_or_default();
    let copies = options
        .copy_chosen
        .then(|| LibraryCopies::new(config, out, &options.library.path));
    // A step budget bounds runs in steps, else their episodes do.
    let (unit, planned) = match config.protocol.max_steps {
        Some(steps) => (Unit::Steps, steps * plan.specs.len() as u64),
        None => (
            Unit::Episodes,
            plan.specs.iter().map(|s| u64::from(s.episodes)).sum(),
        ),
    };
    let mut files = ResultFiles {
        out: out.to_path_buf(),
        config: config.clone(),
        names,
        progress: Progress::new(planned, unit),
        writers: BTreeMap::new(),
        summary,
        copies,
    };
    let started = Instant::now();
    let outcome = experiment::schedule(plan.specs, options.jobs, commands, &mut files);
    files.progress.finish(matches!(outcome, Ok(false)));
    let ending = match outcome {
        Ok(false) => Ending {
            status: Status::Complete,
            error: None,
            wall_s: started.elapsed().as_secs_f64(),
        },
        Ok(true) => Ending {
            status: Status::Stopped,
            error: None,
            wall_s: started.elapsed().as_secs_f64(),
        },
        Err(err) => Ending {
            status: Status::Failed,
            error: Some(format!("{err:#}")),
            wall_s: started.elapsed().as_secs_f64(),
        },
    };
    let summary = assemble(out, config, library, options.trace, ending)?;
    if let Some(error) = &summary.error {
        bail!("{error}");
    }
    Ok(summary)
}

/// What the event stream writes: each run's record, progress, and `summary.json` after
/// every run.
struct ResultFiles {
    out: PathBuf,
    config: Config,
    /// The sources' names (none without a library).
    names: Vec<String>,
    progress: Progress,
    /// The record of every run in progress.
    writers: BTreeMap<(MethodId, u32), RunWriter>,
    /// Runs finished so far, rewritten to `summary.json` as each ends.
    summary: Summary,
    /// Where the chosen policies join the library, if they do.
    copies: Option<LibraryCopies>,
}

impl ResultFiles {
    fn writer(&mut self, method: &MethodId, run: u32) -> Result<&mut RunWriter> {
        let key = (method.clone(), run);
        if !self.writers.contains_key(&key) {
            let writer = RunWriter::create(&self.out, method, run, &self.names)?;
            self.writers.insert(key.clone(), writer);
        }
        Ok(self.writers.get_mut(&key).expect("inserted above"))
    }
}

impl Observer for ResultFiles {
    fn on_event(&mut self, event: Event) -> Result<()> {
        match event {
            Event::RunStarted {
                run,
                method,
                planned_episodes,
                ..
            } => {
                let planned = self
                    .config
                    .protocol
                    .max_steps
                    .unwrap_or(u64::from(planned_episodes));
                self.progress.run_started(method.label(), run, planned);
                self.writer(&method, run)?;
            }
            Event::Activations(snapshot) => {
                let (method, run) = (snapshot.method.clone(), snapshot.run);
                self.writer(&method, run)?.snapshot(snapshot);
            }
            Event::EpisodeEnded(record) => {
                self.writer(&record.method, record.run)?.episode(&record)?;
                self.progress.episode(&record);
            }
            Event::Trace(record) => {
                let names = std::mem::take(&mut self.names);
                let written = self
                    .writer(&record.method, record.run)
                    .and_then(|w| w.trace(&record, &names));
                self.names = names;
                written?;
            }
            // A failure is reported from the run's thread when it is joined.
            Event::Step(_) | Event::RunEnded(_) | Event::RunFailed { .. } => {}
        }
        Ok(())
    }

    fn on_finished(&mut self, _order: usize, _spec: &RunSpec, outcome: RunOutcome) -> Result<()> {
        let record = outcome.record;
        self.progress
            .run_finished(record.method.label(), record.run);
        let mut library_copy = None;
        // A run stopped before its first step trained nothing worth keeping.
        if record.steps > 0 {
            let name = run_name(record.method.label(), record.run);
            let info = policy_info(&self.config, &record);
            policy_store::save(&self.out.join("policies"), &name, &outcome.net, &info)
                .with_context(|| format!("saving the trained {}", record.method))?;
            // Only a finished reuse's choice, tested, is worth reusing. The results hold
            // it already, so a library that cannot take it costs a warning, not the run.
            if let (Some(copies), true) = (&self.copies, record.chosen.is_some() && !record.stopped)
            {
                match copies.add(&name, &outcome.net, &info) {
                    Ok(path) => library_copy = Some(path),
                    Err(err) => self.progress.warn(&format!(
                        "the chosen policy of {} run {} could not be added to the library in \
                         {}: {err:#}; it is in {}",
                        record.method,
                        record.run + 1,
                        copies.dir.display(),
                        self.out.join("policies").display()
                    )),
                }
            }
        }
        let key = (record.method.clone(), record.run);
        self.writer(&record.method, record.run)?;
        let writer = self.writers.remove(&key).expect("created above");
        let mut summary =
            RunSummary::new(record, &writer.rewards, self.config.protocol.moving_average);
        summary.library_copy = library_copy;
        writer.finish(&self.out, &summary)?;

        let runs = &mut self.summary.runs;
        runs.push(summary);
        runs.sort_by_key(|r| (r.record.method.index, r.record.run));
        self.summary.unfinished.retain(|k| {
            !runs.iter().any(|r| {
                !r.record.stopped && r.record.run == k.run && r.record.method.label() == k.method
            })
        });
        results::write_json(&self.out.join("summary.json"), &self.summary)
    }

    /// Keeps what a failed run left (its last good weights) and says what happened.
    fn on_failed(&mut self, spec: &RunSpec, err: TrainerError) -> anyhow::Error {
        let TrainerError::Diverged(divergence) = err else {
            return anyhow::Error::new(err).context(format!(
                "{} run {}",
                spec.method,
                spec.run + 1
            ));
        };
        let Divergence {
            method,
            run,
            source,
            episodes,
            steps,
            last_good,
        } = *divergence;
        let info = PolicyInfo {
            source_task: self.config.env.clone(),
            training: TrainingBudget {
                episodes: u64::from(episodes),
                steps,
            },
            seed: spec.seed,
            final_score: None,
            reused: None,
        };
        let policies = self.out.join("policies");
        let name = run_name(spec.method.label(), run);
        let kept = match policy_store::save(&policies, &name, &last_good, &info) {
            Ok(_) => format!(
                "its last good weights are in {}",
                policies.join(&name).display()
            ),
            Err(err) => format!("its last good weights could not be saved: {err}"),
        };
        anyhow::anyhow!("policy {method} (run {run}) diverged: {source}; {kept}")
    }
}

/// Creates the output directory and refuses to mix new results with old ones. With
/// `force`, the old results are moved into `<dir>/.replaced/` (returned), to be deleted
/// once the new ones are written: a directory where nothing can be written loses nothing.
fn prepare_output(output: &OutputOptions) -> Result<Option<PathBuf>> {
    let dir = &output.dir;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("creating the output directory {}", dir.display()))?;
    let existing: Vec<&str> = RESULT_FILES
        .into_iter()
        .filter(|f| dir.join(f).exists())
        .collect();
    if existing.is_empty() {
        return Ok(None);
    }
    if !output.force {
        bail!(
            "the output directory {} already holds results ({}); choose another --out, pass \
             --force to replace them, or --resume to finish them",
            dir.display(),
            existing.join(", ")
        );
    }
    let replaced = dir.join(REPLACED);
    if replaced.exists() {
        // A replacement that never finished: its results were replaced already.
        std::fs::remove_dir_all(&replaced)
            .with_context(|| format!("removing {}", replaced.display()))?;
    }
    std::fs::create_dir(&replaced).with_context(|| {
        format!(
            "cannot replace the results in {}: creating {}",
            dir.display(),
            replaced.display()
        )
    })?;
    let mut moved = Vec::new();
    for name in RESULT_FILES.iter().chain(PLOT_FILES.iter()) {
        let (from, to) = (dir.join(name), replaced.join(name));
        if !from.exists() {
            continue;
        }
        if let Err(err) = std::fs::rename(&from, &to) {
            // Put back what moved: the old results stay as they were.
            for (from, to) in moved.iter().rev() {
                let _ = std::fs::rename(to, from);
            }
            let _ = std::fs::remove_dir(&replaced);
            return Err(err).with_context(|| {
                format!(
                    "cannot replace the results in {}: moving {} aside; nothing was changed",
                    dir.display(),
                    from.display()
                )
            });
        }
        moved.push((from, to));
    }
    Ok(Some(replaced))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forced_results_move_aside_until_the_new_ones_are_written() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        std::fs::write(dir.join("episodes.csv"), "old").unwrap();
        std::fs::create_dir(dir.join("policies")).unwrap();
        std::fs::write(dir.join("policies/p.ron"), "old").unwrap();
        let refused = prepare_output(&OutputOptions {
            dir: dir.clone(),
            force: false,
        });
        assert!(format!("{:#}", refused.unwrap_err()).contains("--resume"));

        let replaced = prepare_output(&OutputOptions {
            dir: dir.clone(),
            force: true,
        })
        .unwrap()
        .unwrap();
        assert!(!dir.join("episodes.csv").exists());
        assert_eq!(
            std::fs::read_to_string(replaced.join("policies/p.ron")).unwrap(),
            "old"
        );
    }
}
