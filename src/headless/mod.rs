//! Headless mode: runs what the config's protocol lists, with progress on stderr and
//! results on disk, consuming the trainer's event stream.
//!
//! Runs are spread over `jobs` threads (one per core by default). Files in the output
//! directory, each written as results arrive, so a stopped experiment keeps what it did:
//! - `episodes.csv`: one row per training episode (`run, method, episode, reward, steps,
//!   loss, statistic_loss, epsilon, policy, wall_s`; `policy` is the source that acted
//!   most in the episode, for methods that reuse the library);
//! - `tests.csv`: the greedy test returns of each run (`run, method, test, return, policy`);
//! - `activations.csv`: per episode of every run that reuses the library, each source's
//!   score (SAP-Net: its activation), probability of being picked and steps acted;
//! - `trace.csv` (with `--trace`): every `spread` call of SAP-Net's activations;
//! - `comparison.csv`: one row per method, the measures of [`comparison`];
//! - `summary.json`: the config, the source library, each run's totals and test returns;
//! - `policies/<method>-run<r>.{safetensors,ron}` (e.g. `dqn-100-100-run0`, `sapnet-run0`):
//!   each trained network — a reusing method's chosen source after fine-tuning — in the
//!   policy library's format;
//! - `learning_curve.png`/`.svg`, `tests.png`, `activations.png`: the paper's Fig. 5–8;
//!   `selections.png`: who acted, per reusing method.
//!
//! Each run of a reusing method that finishes also adds its chosen source, fine-tuned, to
//! the policy library, as `<library>/<target task>/chosen/<out dir>-<method>-run<r>`
//! (Algorithm 3's last step); the sources beside it are never touched, and no policy
//! already there is replaced.

pub mod comparison;
mod plots;
mod progress;
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
use crate::trainer::{
    self, Command, Divergence, Event, MethodId, RunOutcome, RunSpec, SourcePolicy, TrainerError,
};

pub(crate) use progress::Progress;
pub use replot::replot;
pub use results::{RunSummary, Summary};

/// Entries that mark a directory as holding results already.
const RESULT_FILES: [&str; 7] = [
    "episodes.csv",
    "tests.csv",
    "activations.csv",
    "trace.csv",
    "comparison.csv",
    "summary.json",
    "policies",
];

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
}

/// Runs the protocol of `config`: trains the source library if SAP-Net needs one that is
/// not there, then every (method, run). `commands` carries [`Command::Stop`] (from
/// Ctrl-C): the runs in progress then end early, no new ones start, and everything written
/// so far is kept.
pub fn run(
    config: &Config,
    output: &OutputOptions,
    options: &RunOptions,
    commands: &Receiver<Command>,
) -> Result<Summary> {
    prepare_output(output)?;
    let mut summary = Summary::new(config);
    let mut plan = experiment::plan(config, &options.library, commands)?;
    if let Some(sources) = &plan.sources {
        summary.library = Some(
            sources
                .iter()
                .map(|s| results::LibraryEntry {
                    name: s.name.clone(),
                    hidden: s.description.hidden.clone(),
                    final_score: s.final_score,
                })
                .collect(),
        );
    }
    for spec in &mut plan.specs {
        spec.stream.trace = options.trace && spec.method.kind == MethodKind::SapNet;
    }
    let copies = LibraryCopies::new(config, &output.dir, &options.library.path);
    let mut files =
        ResultFiles::create(config, output, plan.sources.as_deref(), &plan.specs, copies)?;
    if options.trace {
        files.trace_to(&output.dir.join("trace.csv"))?;
    }
    let started = Instant::now();

    let outcome = experiment::schedule(plan.specs, options.jobs, commands, &mut files);
    let trace_flushed = files
        .trace
        .as_mut()
        .map_or(Ok(()), results::TraceWriter::flush);
    files.progress.finish(matches!(outcome, Ok(false)));
    if let Err(err) = outcome {
        summary.error = Some(format!("{err:#}"));
    }
    if let Err(err) = &trace_flushed {
        summary.error.get_or_insert_with(|| format!("{err:#}"));
    }
    summary.runs = std::mem::take(&mut files.finished).into_values().collect();
    summary.wall_s = started.elapsed().as_secs_f64();
    let library = summary.library.as_deref().unwrap_or_default();
    summary.comparison = comparison::compare(config, library, &summary.runs, &files.rewards);
    comparison::write_csv(&output.dir.join("comparison.csv"), &summary.comparison)?;
    results::write_summary(&output.dir.join("summary.json"), &summary)?;
    if let Some(error) = &summary.error {
        bail!("{error}");
    }
    plots::write_all(&output.dir, &files.plot_data(config))
        .with_context(|| format!("drawing the plots in {}", output.dir.display()))?;
    Ok(summary)
}

/// Everything the event stream writes: the CSV files, progress, and what the plots and
/// the summary need.
struct ResultFiles {
    output: OutputOptions,
    config: Config,
    episodes: results::EpisodeWriter,
    tests: results::TestsWriter,
    activations: Option<results::ActivationsWriter>,
    trace: Option<results::TraceWriter>,
    progress: Progress,
    /// Training returns per (method, run).
    rewards: BTreeMap<(MethodId, u32), Vec<f64>>,
    /// Reusing runs: the latest snapshot of each, and the selections counted before the
    /// current episode.
    snapshots: BTreeMap<(MethodId, u32), (trainer::ActivationSnapshot, Vec<u64>)>,
    /// Reusing runs: scores and the steps each source acted, at the end of every episode.
    histories: BTreeMap<(MethodId, u32), plots::SelectionHistory>,
    names: Vec<String>,
    finished: BTreeMap<usize, RunSummary>,
    tested: BTreeMap<MethodId, Vec<Vec<f64>>>,
    window: usize,
    /// Where the chosen policies join the library.
    copies: LibraryCopies,
}

impl ResultFiles {
    fn create(
        config: &Config,
        output: &OutputOptions,
        sources: Option<&Vec<SourcePolicy>>,
        specs: &[RunSpec],
        copies: LibraryCopies,
    ) -> Result<Self> {
        let dir = &output.dir;
        let names: Vec<String> = sources
            .map(|s| s.iter().map(|p| p.name.clone()).collect())
            .unwrap_or_default();
        let activations = match sources {
            Some(_) => Some(results::ActivationsWriter::create(
                &dir.join("activations.csv"),
                &names,
            )?),
            None => None,
        };
        let planned = specs.iter().map(|s| u64::from(s.episodes)).sum();
        Ok(Self {
            output: output.clone(),
            config: config.clone(),
            episodes: results::EpisodeWriter::create(&dir.join("episodes.csv"))?,
            tests: results::TestsWriter::create(&dir.join("tests.csv"))?,
            activations,
            trace: None,
            progress: Progress::new(planned),
            rewards: BTreeMap::new(),
            snapshots: BTreeMap::new(),
            histories: BTreeMap::new(),
            names,
            finished: BTreeMap::new(),
            tested: BTreeMap::new(),
            window: config.protocol.moving_average,
            copies,
        })
    }

    /// Writes SAP-Net's trace events to `path` (nothing to write without a library).
    fn trace_to(&mut self, path: &Path) -> Result<()> {
        if self.activations.is_some() {
            self.trace = Some(results::TraceWriter::create(path, &self.names)?);
        }
        Ok(())
    }

    /// The row of `activations.csv` for an episode that just ended, from the snapshot the
    /// trainer sends right before `EpisodeEnded`.
    fn write_activations(&mut self, method: &MethodId, run: u32, episode: u32) -> Result<()> {
        let key = (method.clone(), run);
        let (Some(writer), Some((snapshot, counted))) =
            (&mut self.activations, self.snapshots.get_mut(&key))
        else {
            return Ok(());
        };
        let selected: Vec<u64> = snapshot
            .selections
            .iter()
            .zip(counted.iter())
            .map(|(now, before)| now - before)
            .collect();
        writer.write(
            run,
            method,
            episode,
            &snapshot.activations,
            &snapshot.probabilities,
            &selected,
        )?;
        counted.clone_from(&snapshot.selections);
        let history = self.histories.entry(key).or_default();
        history.scores.push(snapshot.activations.clone());
        history.acted.push(selected);
        Ok(())
    }

    fn plot_data(&self, config: &Config) -> plots::PlotData {
        let mut curves = Vec::new();
        let mut activations = Vec::new();
        let mut acted = Vec::new();
        for method in experiment::method_ids(config) {
            let runs: Vec<Vec<f64>> = self
                .rewards
                .iter()
                .filter(|((m, _), _)| *m == method)
                .map(|(_, r)| r.clone())
                .collect();
            if !runs.is_empty() {
                curves.push(plots::Curve {
                    label: method.label().to_string(),
                    sapnet: method.kind == MethodKind::SapNet,
                    returns: runs,
                    tests: self.tested.get(&method).cloned().unwrap_or_default(),
                });
            }
            let histories: Vec<&plots::SelectionHistory> = self
                .histories
                .iter()
                .filter(|((m, _), _)| *m == method)
                .map(|(_, h)| h)
                .collect();
            if histories.is_empty() {
                continue;
            }
            if method.kind == MethodKind::SapNet && activations.is_empty() {
                activations = histories.iter().map(|h| h.scores.clone()).collect();
            }
            let runs = histories.iter().map(|h| h.acted.clone()).collect();
            acted.push((method.label().to_string(), runs));
        }
        plots::PlotData {
            task: crate::env::make(&config.env).id().to_string(),
            window: self.window,
            curves,
            policy_names: self.names.clone(),
            activations,
            acted,
        }
    }
}

impl Observer for ResultFiles {
    fn on_event(&mut self, event: Event) -> Result<()> {
        match event {
            Event::RunStarted { run, method, .. } => {
                self.progress.run_started(method.label(), run);
            }
            Event::Activations(snapshot) => {
                let key = (snapshot.method.clone(), snapshot.run);
                let counted = self
                    .snapshots
                    .remove(&key)
                    .map_or_else(|| vec![0; snapshot.selections.len()], |(_, c)| c);
                self.snapshots.insert(key, (snapshot, counted));
            }
            Event::EpisodeEnded(record) => {
                self.episodes.write(&record)?;
                self.progress.episode(&record);
                self.rewards
                    .entry((record.method.clone(), record.run))
                    .or_default()
                    .push(record.reward);
                if record.method.kind.reuses() {
                    self.write_activations(&record.method, record.run, record.episode)?;
                    if let Some(trace) = &mut self.trace {
                        trace.flush()?;
                    }
                }
            }
            Event::Trace(record) => {
                if let Some(trace) = &mut self.trace {
                    trace.write(&record)?;
                }
            }
            // A failure is reported from the run's thread when it is joined.
            Event::Step(_) | Event::RunEnded(_) | Event::RunFailed { .. } => {}
        }
        Ok(())
    }

    fn on_finished(&mut self, order: usize, _spec: &RunSpec, outcome: RunOutcome) -> Result<()> {
        let record = outcome.record;
        let mut library_copy = None;
        // A run stopped before its first step trained nothing worth keeping.
        if record.steps > 0 {
            let name = policy_file_name(record.method.label(), record.run);
            let info = policy_info(&self.config, &record);
            policy_store::save(
                &self.output.dir.join("policies"),
                &name,
                &outcome.net,
                &info,
            )
            .with_context(|| format!("saving the trained {}", record.method))?;
            // Only a finished reuse's choice, tested, is worth reusing. The results hold
            // it already, so a library that cannot take it costs a warning, not the run.
            if record.chosen.is_some() && !record.stopped {
                match self.copies.add(&name, &outcome.net, &info) {
                    Ok(path) => library_copy = Some(path),
                    Err(err) => self.progress.warn(&format!(
                        "the chosen policy of {} run {} could not be added to the library in \
                         {}: {err:#}; it is in {}",
                        record.method,
                        record.run + 1,
                        self.copies.dir.display(),
                        self.output.dir.join("policies").display()
                    )),
                }
            }
        }
        self.tests.write(&record)?;
        if !record.test_returns.is_empty() {
            self.tested
                .entry(record.method.clone())
                .or_default()
                .push(record.test_returns.clone());
        }
        let rewards = self
            .rewards
            .get(&(record.method.clone(), record.run))
            .map_or(&[][..], Vec::as_slice);
        let mut summary = RunSummary::new(record, rewards, self.window);
        summary.library_copy = library_copy;
        self.finished.insert(order, summary);
        Ok(())
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
        let policies = self.output.dir.join("policies");
        let name = policy_file_name(spec.method.label(), run);
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

/// `dqn[100,100]`, run 0 → `dqn-100-100-run0`: a plain file name.
fn policy_file_name(method: &str, run: u32) -> String {
    let plain: String = method
        .chars()
        .filter(|&c| c != ']')
        .map(|c| if c == '[' || c == ',' { '-' } else { c })
        .collect();
    format!("{plain}-run{run}")
}

/// Creates the output directory and refuses to mix new results with old ones.
fn prepare_output(output: &OutputOptions) -> Result<()> {
    std::fs::create_dir_all(&output.dir)
        .with_context(|| format!("creating the output directory {}", output.dir.display()))?;
    let existing: Vec<&str> = RESULT_FILES
        .into_iter()
        .filter(|f| output.dir.join(f).exists())
        .collect();
    if !existing.is_empty() && !output.force {
        bail!(
            "the output directory {} already holds results ({}); choose another --out or pass --force to replace them",
            output.dir.display(),
            existing.join(", ")
        );
    }
    // Old files must not sit beside new results as if this run had made them.
    let policies = output.dir.join("policies");
    if policies.exists() {
        std::fs::remove_dir_all(&policies)
            .with_context(|| format!("removing the old results in {}", policies.display()))?;
    }
    for stale in [
        "activations.csv",
        "trace.csv",
        "learning_curve.png",
        "learning_curve.svg",
        "tests.png",
        "activations.png",
        "selections.png",
        "comparison.csv",
    ] {
        let path = output.dir.join(stale);
        if path.exists() {
            std::fs::remove_file(&path)
                .with_context(|| format!("removing the old result {}", path.display()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn policy_file_names_are_plain() {
        assert_eq!(policy_file_name("dqn[100,100]", 0), "dqn-100-100-run0");
        assert_eq!(policy_file_name("dqn[16]", 3), "dqn-16-run3");
        assert_eq!(policy_file_name("sapnet", 1), "sapnet-run1");
    }
}
