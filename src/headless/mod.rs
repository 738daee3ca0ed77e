//! Headless mode: runs what the config's protocol lists, with progress on stderr and
//! results on disk, consuming the trainer's event stream.
//!
//! Runs are spread over `jobs` threads (one per core by default). Files in the output
//! directory, each written as results arrive, so a stopped experiment keeps what it did:
//! - `episodes.csv`: one row per training episode (`run, method, episode, reward, steps,
//!   loss, statistic_loss, epsilon, policy, wall_s`; `policy` is the policy SAP-Net
//!   selected most in the episode);
//! - `tests.csv`: the greedy test returns of each run (`run, method, test, return, policy`);
//! - `activations.csv`: SAP-Net's activations, probabilities and selections per episode;
//! - `trace.csv` (with `--trace`): every `spread` call of SAP-Net's activations;
//! - `summary.json`: the config, the source library, each run's totals and test returns;
//! - `policies/<method>-run<r>.{safetensors,ron}` (e.g. `dqn-100-100-run0`, `sapnet-run0`):
//!   each trained network — SAP-Net's chosen policy after training — in the policy
//!   library's format;
//! - `learning_curve.png`/`.svg`, `tests.png`, `activations.png`: the paper's Fig. 5–8.
//!
//! Each SAP-Net run that finishes also adds its chosen policy to the policy library, as
//! `<library>/<target task>/chosen/<out dir>-sapnet-run<r>` (Algorithm 3's last step); the
//! sources beside it are never touched, and no policy already there is replaced.

mod plots;
mod progress;
mod replot;
mod results;

use std::collections::{BTreeMap, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver};
use std::sync::Arc;
use std::thread;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};

use crate::config::{Config, Method};
use crate::dqn::QNet;
use crate::policy_store::{self, PolicyInfo, TrainingBudget};
use crate::seeds;
use crate::sources;
use crate::trainer::{
    self, dqn_label, Command, Divergence, DqnRunSpec, Event, RunHandle, RunOutcome, RunSpec,
    SourcePolicy, StreamOptions, TrainerError, TransferRunSpec, SAPNET_LABEL,
};

pub(crate) use progress::Progress;
pub use replot::replot;
pub use results::{RunSummary, Summary};

/// How often the scheduler drains the runs' events and checks for Ctrl-C.
const POLL_INTERVAL: Duration = Duration::from_millis(10);

/// Entries that mark a directory as holding results already.
const RESULT_FILES: [&str; 6] = [
    "episodes.csv",
    "tests.csv",
    "activations.csv",
    "trace.csv",
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
    /// Root of the policy library SAP-Net reuses (`<library>/<task>/`).
    pub library: PathBuf,
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
    commands: Receiver<Command>,
) -> Result<Summary> {
    prepare_output(output)?;
    let mut summary = Summary::new(config);
    let (sources, commands) = if config.protocol.methods.contains(&Method::SapNet) {
        let (sources, commands) = sources::ensure_library(config, &options.library, commands)?;
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
        (Some(Arc::new(sources)), commands)
    } else {
        (None, commands)
    };
    let mut specs = run_specs(config, sources.as_ref())?;
    for spec in &mut specs {
        if let RunSpec::Transfer(transfer) = spec {
            transfer.stream.trace = options.trace;
        }
    }
    let chosen = ChosenCopies::new(config, output, &options.library);
    let mut sink = Sink::create(config, &output.dir, sources.as_deref(), &specs, chosen)?;
    if options.trace {
        sink.trace_to(&output.dir.join("trace.csv"))?;
    }
    let started = Instant::now();

    let outcome = schedule(specs, options.jobs, &commands, &mut sink, config, output);
    let trace_flushed = sink
        .trace
        .as_mut()
        .map_or(Ok(()), results::TraceWriter::flush);
    sink.progress.finish(matches!(outcome, Ok(false)));
    if let Err(err) = outcome {
        summary.error = Some(format!("{err:#}"));
    }
    if let Err(err) = &trace_flushed {
        summary.error.get_or_insert_with(|| format!("{err:#}"));
    }
    summary.runs = std::mem::take(&mut sink.finished).into_values().collect();
    summary.wall_s = started.elapsed().as_secs_f64();
    results::write_summary(&output.dir.join("summary.json"), &summary)?;
    if let Some(error) = &summary.error {
        bail!("{error}");
    }
    plots::write_all(&output.dir, &sink.plot_data(config))
        .with_context(|| format!("drawing the plots in {}", output.dir.display()))?;
    Ok(summary)
}

/// A run in progress.
struct Active {
    order: usize,
    spec: RunSpec,
    handle: RunHandle,
}

/// Runs `specs` in order, at most `jobs` at a time, feeding every event to `sink`.
/// Returns whether the user stopped the experiment; a run that fails stops the others and
/// is returned as the error (the other runs' results are kept in `sink`).
fn schedule(
    specs: Vec<RunSpec>,
    jobs: usize,
    commands: &Receiver<Command>,
    sink: &mut Sink,
    config: &Config,
    output: &OutputOptions,
) -> Result<bool> {
    let (events_tx, events) = mpsc::channel();
    let mut queue: VecDeque<(usize, RunSpec)> = specs.into_iter().enumerate().collect();
    let mut active: Vec<Active> = Vec::new();
    let mut stopping = false;
    let mut failure: Option<anyhow::Error> = None;
    loop {
        while !stopping && active.len() < jobs.max(1) {
            let Some((order, spec)) = queue.pop_front() else {
                break;
            };
            let handle = trainer::spawn(spec.clone(), events_tx.clone())
                .context("starting a trainer thread")?;
            active.push(Active {
                order,
                spec,
                handle,
            });
        }
        if active.is_empty() {
            break;
        }
        // Poll rather than wait on the channel: a send that finds its receiver parked
        // must wake it (in a profile of the transfer loop, the kernel's task switching
        // took 11% of the samples), while a receiver that drains every few milliseconds
        // costs the trainer nothing but the enqueue.
        thread::sleep(POLL_INTERVAL);
        for event in events.try_iter() {
            sink.on_event(event)?;
        }
        if !stopping && matches!(commands.try_recv(), Ok(Command::Stop)) {
            stopping = true;
            for run in &active {
                let _ = run.handle.commands.send(Command::Stop);
            }
        }
        let mut i = 0;
        while i < active.len() {
            if !active[i].handle.thread.is_finished() {
                i += 1;
                continue;
            }
            let run = active.swap_remove(i);
            // A finished thread has sent all its events: take them before its outcome.
            while let Ok(event) = events.try_recv() {
                sink.on_event(event)?;
            }
            let outcome = run.handle.thread.join().map_err(|_| {
                anyhow::anyhow!(
                    "the trainer thread of {} run {} panicked",
                    run.spec.method(),
                    run.spec.run() + 1
                )
            })?;
            match outcome {
                Ok(outcome) => {
                    stopping |= outcome.record.stopped;
                    sink.on_finished(run.order, &run.spec, outcome, config, output)?;
                }
                Err(err) => {
                    let err = sink.on_failed(&run.spec, err, config, output);
                    failure.get_or_insert(err);
                    stopping = true;
                    for other in &active {
                        let _ = other.handle.commands.send(Command::Stop);
                    }
                }
            }
        }
    }
    while let Ok(event) = events.try_recv() {
        sink.on_event(event)?;
    }
    match failure {
        Some(err) => Err(err),
        None => Ok(stopping),
    }
}

/// Everything the event stream writes: the CSV files, progress, and what the plots and
/// the summary need.
struct Sink {
    episodes: results::EpisodeWriter,
    tests: results::TestsWriter,
    activations: Option<results::ActivationsWriter>,
    trace: Option<results::TraceWriter>,
    progress: Progress,
    /// Training returns per (method, run).
    rewards: BTreeMap<(String, u32), Vec<f64>>,
    /// SAP-Net: the latest snapshot of each run, and the selections counted before the
    /// current episode.
    snapshots: BTreeMap<u32, (trainer::ActivationSnapshot, Vec<u64>)>,
    /// SAP-Net: activations at the end of every episode, per run.
    activation_history: BTreeMap<u32, Vec<Vec<f64>>>,
    names: Vec<String>,
    finished: BTreeMap<usize, RunSummary>,
    tested: BTreeMap<String, Vec<Vec<f64>>>,
    window: usize,
    /// Where SAP-Net's chosen policies join the library.
    chosen: ChosenCopies,
}

/// The library directory that receives SAP-Net's chosen policies, and the prefix that tells
/// one experiment's from another's.
struct ChosenCopies {
    dir: PathBuf,
    prefix: String,
}

impl ChosenCopies {
    fn new(config: &Config, output: &OutputOptions, library: &Path) -> Self {
        // A policy's name may not start with a dot (hidden files are the store's temporaries).
        let prefix = output
            .dir
            .file_name()
            .map(|n| n.to_string_lossy().trim_start_matches('.').to_string())
            .filter(|n| !n.is_empty())
            .unwrap_or_else(|| "results".into());
        Self {
            dir: library.join(config.env.task_name()).join("chosen"),
            prefix,
        }
    }

    /// Writes `net` under a name no policy in the directory has yet (`…-2`, `…-3` after
    /// the first), and returns the path of its metadata file.
    fn add(&self, file_name: &str, net: &QNet, info: &PolicyInfo) -> Result<PathBuf> {
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("creating {}", self.dir.display()))?;
        let base = format!("{}-{file_name}", self.prefix);
        let mut k = 1;
        let (name, metadata) = loop {
            let name = match k {
                1 => base.clone(),
                k => format!("{base}-{k}"),
            };
            let (weights, metadata) = policy_store::paths(&self.dir, &name);
            // The metadata file is claimed by creating it, so that another sapnet writing
            // to the same library at the same time cannot take the same name; the store's
            // save then renames the real metadata over this placeholder.
            if !weights.exists() {
                match std::fs::OpenOptions::new()
                    .write(true)
                    .create_new(true)
                    .open(&metadata)
                {
                    Ok(_) => break (name, metadata),
                    Err(err) if err.kind() == std::io::ErrorKind::AlreadyExists => {}
                    Err(err) => {
                        return Err(err).with_context(|| format!("creating {}", metadata.display()))
                    }
                }
            }
            k += 1;
        };
        if let Err(err) = policy_store::save(&self.dir, &name, net, info) {
            let _ = std::fs::remove_file(&metadata);
            return Err(err.into());
        }
        Ok(metadata)
    }
}

impl Sink {
    fn create(
        config: &Config,
        dir: &Path,
        sources: Option<&Vec<SourcePolicy>>,
        specs: &[RunSpec],
        chosen: ChosenCopies,
    ) -> Result<Self> {
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
        let planned = specs.iter().map(|s| u64::from(s.episodes())).sum();
        Ok(Self {
            episodes: results::EpisodeWriter::create(&dir.join("episodes.csv"))?,
            tests: results::TestsWriter::create(&dir.join("tests.csv"))?,
            activations,
            trace: None,
            progress: Progress::new(planned),
            rewards: BTreeMap::new(),
            snapshots: BTreeMap::new(),
            activation_history: BTreeMap::new(),
            names,
            finished: BTreeMap::new(),
            tested: BTreeMap::new(),
            window: config.protocol.moving_average,
            chosen,
        })
    }

    /// Writes SAP-Net's trace events to `path` (nothing to write without SAP-Net runs).
    fn trace_to(&mut self, path: &Path) -> Result<()> {
        if self.activations.is_some() {
            self.trace = Some(results::TraceWriter::create(path, &self.names)?);
        }
        Ok(())
    }

    fn on_event(&mut self, event: Event) -> Result<()> {
        match event {
            Event::RunStarted { run, method, .. } => self.progress.run_started(&method, run),
            Event::Activations(snapshot) => {
                let counted = self
                    .snapshots
                    .remove(&snapshot.run)
                    .map_or_else(|| vec![0; snapshot.selections.len()], |(_, c)| c);
                self.snapshots.insert(snapshot.run, (snapshot, counted));
            }
            Event::EpisodeEnded(record) => {
                self.episodes.write(&record)?;
                self.progress.episode(&record);
                self.rewards
                    .entry((record.method.clone(), record.run))
                    .or_default()
                    .push(record.reward);
                if record.method == SAPNET_LABEL {
                    self.write_activations(record.run, record.episode)?;
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

    /// The row of `activations.csv` for an episode that just ended, from the snapshot the
    /// trainer sends right before `EpisodeEnded`.
    fn write_activations(&mut self, run: u32, episode: u32) -> Result<()> {
        let (Some(writer), Some((snapshot, counted))) =
            (&mut self.activations, self.snapshots.get_mut(&run))
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
            episode,
            &snapshot.activations,
            &snapshot.probabilities,
            &selected,
        )?;
        counted.clone_from(&snapshot.selections);
        self.activation_history
            .entry(run)
            .or_default()
            .push(snapshot.activations.clone());
        Ok(())
    }

    fn on_finished(
        &mut self,
        order: usize,
        spec: &RunSpec,
        outcome: RunOutcome,
        config: &Config,
        output: &OutputOptions,
    ) -> Result<()> {
        let record = outcome.record;
        let mut library_copy = None;
        // A run stopped before its first step trained nothing worth keeping.
        if record.steps > 0 {
            let name = policy_file_name(&record.method, record.run);
            let info = policy_info(config, &record, spec);
            policy_store::save(&output.dir.join("policies"), &name, &outcome.net, &info)
                .with_context(|| format!("saving the trained {}", record.method))?;
            // Only a finished transfer's choice, tested, is worth reusing. The results hold
            // it already, so a library that cannot take it costs a warning, not the run.
            if matches!(spec, RunSpec::Transfer(_)) && !record.stopped {
                match self.chosen.add(&name, &outcome.net, &info) {
                    Ok(path) => library_copy = Some(path),
                    Err(err) => self.progress.warn(&format!(
                        "the chosen policy of {} run {} could not be added to the library in \
                         {}: {err:#}; it is in {}",
                        record.method,
                        record.run + 1,
                        self.chosen.dir.display(),
                        output.dir.join("policies").display()
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
    fn on_failed(
        &mut self,
        spec: &RunSpec,
        err: TrainerError,
        config: &Config,
        output: &OutputOptions,
    ) -> anyhow::Error {
        let TrainerError::Diverged(divergence) = err else {
            return anyhow::Error::new(err).context(format!(
                "{} run {}",
                spec.method(),
                spec.run() + 1
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
            source_task: config.env.clone(),
            training: TrainingBudget {
                episodes: u64::from(episodes),
                steps,
            },
            seed: spec.seed(),
            final_score: None,
            reused: None,
        };
        let policies = output.dir.join("policies");
        let name = policy_file_name(spec.method(), run);
        let kept = match policy_store::save(&policies, &name, &last_good, &info) {
            Ok(_) => format!(
                "its last good weights are in {}",
                policies.join(&name).display()
            ),
            Err(err) => format!("its last good weights could not be saved: {err}"),
        };
        anyhow::anyhow!("policy {method} (run {run}) diverged: {source}; {kept}")
    }

    fn plot_data(&self, config: &Config) -> plots::PlotData {
        let mut curves = Vec::new();
        for method in method_labels(config) {
            let runs: Vec<&Vec<f64>> = self
                .rewards
                .iter()
                .filter(|((m, _), _)| *m == method)
                .map(|(_, r)| r)
                .collect();
            if !runs.is_empty() {
                curves.push(plots::Curve {
                    label: method.clone(),
                    returns: runs.into_iter().cloned().collect(),
                    tests: self.tested.get(&method).cloned().unwrap_or_default(),
                });
            }
        }
        plots::PlotData {
            task: crate::env::make(&config.env).id().to_string(),
            window: self.window,
            curves,
            policy_names: self.names.clone(),
            activations: self.activation_history.values().cloned().collect(),
        }
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

/// The labels of the config's methods, in the protocol's order.
fn method_labels(config: &Config) -> Vec<String> {
    config
        .protocol
        .methods
        .iter()
        .map(|m| match m {
            Method::SapNet => SAPNET_LABEL.to_string(),
            Method::Dqn { hidden } => dqn_label(hidden),
        })
        .collect()
}

/// One spec per (method, run), each with its own seed derived from the run seed.
pub(crate) fn run_specs(
    config: &Config,
    sources: Option<&Arc<Vec<SourcePolicy>>>,
) -> Result<Vec<RunSpec>> {
    let labels = method_labels(config);
    if let Some(twice) = labels
        .iter()
        .enumerate()
        .find(|(i, l)| labels[..*i].contains(l))
    {
        bail!(
            "config field `protocol.methods` lists {} twice; each method runs once per run",
            twice.1
        );
    }
    let mut specs = Vec::new();
    for run in 0..config.protocol.runs {
        for (m, method) in config.protocol.methods.iter().enumerate() {
            let seed = seeds::derive(config.seed, &[m as u64, u64::from(run)]);
            specs.push(match method {
                Method::Dqn { hidden } => RunSpec::Dqn(DqnRunSpec {
                    run,
                    method: dqn_label(hidden),
                    env: config.env.clone(),
                    dqn: config.dqn.clone(),
                    hidden: hidden.clone(),
                    episodes: config.protocol.episodes,
                    max_steps: config.protocol.max_steps,
                    test_episodes: config.protocol.test_episodes,
                    seed,
                    stream: StreamOptions::episodes(),
                }),
                Method::SapNet => RunSpec::Transfer(TransferRunSpec {
                    run,
                    method: SAPNET_LABEL.to_string(),
                    env: config.env.clone(),
                    dqn: config.dqn.clone(),
                    sapnet: config.sapnet.clone(),
                    sources: Arc::clone(sources.expect("SAP-Net runs load the library first")),
                    episodes: config.protocol.episodes,
                    max_steps: config.protocol.max_steps,
                    test_episodes: config.protocol.test_episodes,
                    seed,
                    stream: StreamOptions::episodes(),
                }),
            });
        }
    }
    Ok(specs)
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
    ] {
        let path = output.dir.join(stale);
        if path.exists() {
            std::fs::remove_file(&path)
                .with_context(|| format!("removing the old result {}", path.display()))?;
        }
    }
    Ok(())
}

fn policy_info(config: &Config, record: &trainer::RunRecord, spec: &RunSpec) -> PolicyInfo {
    let final_score = (!record.test_returns.is_empty())
        .then(|| record.test_returns.iter().sum::<f64>() / record.test_returns.len() as f64);
    let reused = match (spec, &record.chosen) {
        (RunSpec::Transfer(_), Some(chosen)) => Some(format!(
            "{}/{}",
            sources::source_task(config).task_name(),
            chosen.name
        )),
        _ => None,
    };
    PolicyInfo {
        source_task: config.env.clone(),
        training: TrainingBudget {
            episodes: u64::from(record.episodes),
            steps: record.steps,
        },
        seed: record.seed,
        final_score,
        reused,
    }
}

/// Trains `spec` on a thread of its own and hands its events to `on_event`, on this thread,
/// as they arrive. Gives back the command receiver with the outcome, for the next run.
pub(crate) fn drive(
    spec: &DqnRunSpec,
    commands: Receiver<Command>,
    mut on_event: impl FnMut(Event) -> Result<()>,
) -> Result<(Result<RunOutcome, TrainerError>, Receiver<Command>)> {
    let (events_tx, events_rx) = mpsc::channel();
    let worker = {
        let spec = spec.clone();
        thread::Builder::new()
            .name(format!("trainer {} run {}", spec.method, spec.run))
            .spawn(move || {
                let outcome = trainer::train(&spec, &events_tx, &commands);
                (outcome, commands)
            })
            .context("starting the trainer thread")?
    };
    for event in events_rx {
        on_event(event)?;
    }
    worker
        .join()
        .map_err(|_| anyhow::anyhow!("the trainer thread of {} panicked", spec.method))
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

    #[test]
    fn a_chosen_copy_skips_names_taken_or_being_written() {
        use rand::SeedableRng;
        let tmp = tempfile::tempdir().unwrap();
        let output = OutputOptions {
            dir: tmp.path().join(".hidden-out"),
            force: false,
        };
        let copies = ChosenCopies::new(&Config::default(), &output, &tmp.path().join("lib"));
        let net = QNet::new(
            crate::dqn::Architecture::new(4, &[3], 2),
            &mut rand::rngs::StdRng::seed_from_u64(0),
        )
        .unwrap();
        let info = PolicyInfo {
            source_task: Config::default().env,
            training: TrainingBudget {
                episodes: 1,
                steps: 1,
            },
            seed: 0,
            final_score: None,
            reused: None,
        };
        // A leading dot would make a hidden name, which the store refuses.
        let first = copies.add("sapnet-run0", &net, &info).unwrap();
        assert!(first.ends_with("lib/cartpole/chosen/hidden-out-sapnet-run0.ron"));
        // Another process has claimed "-2" but not written it yet.
        std::fs::write(copies.dir.join("hidden-out-sapnet-run0-2.ron"), "").unwrap();
        let third = copies.add("sapnet-run0", &net, &info).unwrap();
        assert!(third.ends_with("hidden-out-sapnet-run0-3.ron"));
        assert!(policy_store::load(&copies.dir, "hidden-out-sapnet-run0-3").is_ok());
        assert_eq!(
            std::fs::read(copies.dir.join("hidden-out-sapnet-run0-2.ron")).unwrap(),
            b""
        );
    }

    #[test]
    fn a_method_listed_twice_is_refused() {
        let mut config = Config::default();
        config.protocol.methods = vec![
            Method::Dqn { hidden: vec![8] },
            Method::Dqn { hidden: vec![8] },
        ];
        let err = run_specs(&config, None).unwrap_err().to_string();
        assert!(
            err.contains("`protocol.methods` lists dqn[8] twice"),
            "{err}"
        );
    }
}
