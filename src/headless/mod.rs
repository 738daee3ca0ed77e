//! Headless mode: runs what the config's protocol lists, with progress on stderr and
//! results on disk, consuming the trainer's event stream.
//!
//! Files in the output directory:
//! - `episodes.csv`: one row per training episode (`run, method, episode, reward, steps,
//!   loss, statistic_loss, epsilon, wall_s`), flushed as episodes end, so a stopped run
//!   keeps every finished episode;
//! - `summary.json`: the config, each run's test returns and totals, whether it was stopped;
//! - `policies/<method>-run<r>.{safetensors,ron}` (e.g. `dqn-100-100-run0`): each trained
//!   network with its metadata, in the policy library's format.

mod progress;
mod results;

use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver};
use std::thread;
use std::time::Instant;

use anyhow::{bail, Context, Result};

use crate::config::{Config, Method};
use crate::policy_store::{self, PolicyInfo, TrainingBudget};
use crate::seeds;
use crate::trainer::{self, dqn_label, Command, Divergence, DqnRunSpec, Event, TrainerError};

pub(crate) use progress::Progress;
pub use results::{RunSummary, Summary};

/// Entries that mark a directory as holding results already.
const RESULT_FILES: [&str; 3] = ["episodes.csv", "summary.json", "policies"];

/// Where results go and whether old ones may be replaced.
#[derive(Debug, Clone)]
pub struct OutputOptions {
    pub dir: PathBuf,
    /// Replace results already in `dir`.
    pub force: bool,
}

/// Runs the protocol of `config`. `commands` carries [`Command::Stop`] (from Ctrl-C): the
/// current run then ends early and everything written so far is kept.
pub fn run(
    config: &Config,
    output: &OutputOptions,
    commands: Receiver<Command>,
) -> Result<Summary> {
    let specs = run_specs(config)?;
    prepare_output(output)?;
    let mut writer = results::EpisodeWriter::create(&output.dir.join("episodes.csv"))?;
    let planned: u64 = specs.iter().map(|s| u64::from(s.episodes)).sum();
    let mut progress = progress::Progress::new(planned);
    let started = Instant::now();
    let mut summary = Summary::new(config);
    let mut commands = commands;

    for spec in specs {
        let mut rewards = Vec::new();
        let (outcome, returned) = drive(&spec, commands, |event| {
            match event {
                Event::RunStarted { run, method, .. } => progress.run_started(&method, run),
                Event::EpisodeEnded(record) => {
                    writer.write(&record)?;
                    progress.episode(&record);
                    rewards.push(record.reward);
                }
                _ => {}
            }
            Ok(())
        })?;
        commands = returned;
        let name = policy_file_name(&spec.method, spec.run);
        let policies = output.dir.join("policies");
        match outcome {
            Ok(outcome) => {
                // A run stopped before its first step (Ctrl-C during the previous run's
                // greedy test) trained nothing worth keeping.
                if outcome.record.steps > 0 {
                    let info = policy_info(config, &outcome.record);
                    policy_store::save(&policies, &name, &outcome.net, &info)
                        .with_context(|| format!("saving the trained {}", spec.method))?;
                }
                summary.push(RunSummary::new(
                    outcome.record,
                    &rewards,
                    config.protocol.moving_average,
                ));
                if summary.stopped() {
                    break;
                }
            }
            Err(TrainerError::Diverged(divergence)) => {
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
                    seed: spec.seed,
                    final_score: None,
                };
                let kept = match policy_store::save(&policies, &name, &last_good, &info) {
                    Ok(_) => format!(
                        "its last good weights are in {}",
                        policies.join(&name).display()
                    ),
                    Err(err) => format!("its last good weights could not be saved: {err}"),
                };
                progress.finish(false);
                let message = format!("policy {method} (run {run}) diverged: {source}; {kept}");
                summary.error = Some(message.clone());
                summary.wall_s = started.elapsed().as_secs_f64();
                results::write_summary(&output.dir.join("summary.json"), &summary)?;
                bail!(message);
            }
            Err(err) => return Err(err.into()),
        }
    }
    progress.finish(!summary.stopped());
    summary.wall_s = started.elapsed().as_secs_f64();
    results::write_summary(&output.dir.join("summary.json"), &summary)?;
    Ok(summary)
}

/// Trains `spec` on a thread of its own and hands its events to `on_event`, on this thread,
/// as they arrive. Gives back the command receiver with the outcome, for the next run.
pub(crate) fn drive(
    spec: &DqnRunSpec,
    commands: Receiver<Command>,
    mut on_event: impl FnMut(Event) -> Result<()>,
) -> Result<(
    Result<trainer::RunOutcome, TrainerError>,
    Receiver<Command>,
)> {
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

/// `dqn[100,100]`, run 0 → `dqn-100-100-run0`: a plain file name.
fn policy_file_name(method: &str, run: u32) -> String {
    let plain: String = method
        .chars()
        .filter(|&c| c != ']')
        .map(|c| if c == '[' || c == ',' { '-' } else { c })
        .collect();
    format!("{plain}-run{run}")
}

/// One spec per (method, run), each with its own seed derived from the run seed.
fn run_specs(config: &Config) -> Result<Vec<DqnRunSpec>> {
    let mut specs = Vec::new();
    for (m, method) in config.protocol.methods.iter().enumerate() {
        let hidden = match method {
            Method::Dqn { hidden } => hidden,
            Method::SapNet => bail!(
                "this build runs DQN from scratch only: SAP-Net transfer runs (Algorithm 3) \
                 are not implemented yet. Use a config whose protocol.methods lists only Dqn \
                 methods, e.g. assets/dqn_cartpole.ron"
            ),
        };
        for run in 0..config.protocol.runs {
            specs.push(DqnRunSpec {
                run,
                method: dqn_label(hidden),
                env: config.env.clone(),
                dqn: config.dqn.clone(),
                hidden: hidden.clone(),
                episodes: config.protocol.episodes,
                max_steps: config.protocol.max_steps,
                test_episodes: config.protocol.test_episodes,
                seed: seeds::derive(config.seed, &[m as u64, u64::from(run)]),
                stream: trainer::StreamOptions::episodes(),
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
    // Old policies must not sit beside new results as if this run had trained them.
    let policies = output.dir.join("policies");
    if policies.exists() {
        std::fs::remove_dir_all(&policies)
            .with_context(|| format!("removing the old results in {}", policies.display()))?;
    }
    Ok(())
}

fn policy_info(config: &Config, record: &trainer::RunRecord) -> PolicyInfo {
    let final_score = (!record.test_returns.is_empty())
        .then(|| record.test_returns.iter().sum::<f64>() / record.test_returns.len() as f64);
    PolicyInfo {
        source_task: config.env.clone(),
        training: TrainingBudget {
            episodes: u64::from(record.episodes),
            steps: record.steps,
        },
        seed: record.seed,
        final_score,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn policy_file_names_are_plain() {
        assert_eq!(policy_file_name("dqn[100,100]", 0), "dqn-100-100-run0");
        assert_eq!(policy_file_name("dqn[16]", 3), "dqn-16-run3");
    }
}
