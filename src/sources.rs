//! `sapnet sources`: trains the library of source policies (paper III-B) — N DQNs of random
//! architectures, "assuming that a person cannot manually design an optimal hidden layer" —
//! and writes it to `<library>/<task>/source-<i>.{safetensors,ron}`.

use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;

use anyhow::{bail, Context, Result};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use crate::config::Config;
use crate::env::EnvConfig;
use crate::experiment::{schedule, Observer};
use crate::policy_store::{self, PolicyInfo, TrainingBudget};
use crate::sapnet::PolicyDescription;
use crate::seeds;
use crate::trainer::{Command, Event, RunOutcome, RunSpec, SourcePolicy, TrainerError};

/// Stream key of the source library's seeds, apart from the experiments' `[method, run]`.
const SOURCES_STREAM: u64 = u64::MAX;

/// One source policy to train.
#[derive(Debug, Clone, PartialEq)]
pub struct SourcePlan {
    pub name: String,
    pub hidden: Vec<usize>,
    pub seed: u64,
}

/// The source task: `sources.env` when given, else the target task.
pub fn source_task(config: &Config) -> &EnvConfig {
    config.sources.env.as_ref().unwrap_or(&config.env)
}

/// `<library>/<source task>`, where the library of `config` lives.
pub fn library_dir(library: &Path, config: &Config) -> PathBuf {
    library.join(source_task(config).task_name())
}

/// The N architectures and seeds, drawn from the run seed: the number of hidden layers and
/// the units of each layer uniformly from the config's inclusive ranges.
pub fn plan(config: &Config) -> Vec<SourcePlan> {
    let s = &config.sources;
    let mut rng = StdRng::seed_from_u64(seeds::derive(config.seed, &[SOURCES_STREAM]));
    (0..s.count)
        .map(|i| {
            let layers = rng.random_range(s.hidden_layers.0..=s.hidden_layers.1);
            let hidden = (0..layers)
                .map(|_| rng.random_range(s.units.0..=s.units.1))
                .collect();
            SourcePlan {
                name: format!("source-{i}"),
                hidden,
                seed: seeds::derive(config.seed, &[SOURCES_STREAM, i as u64]),
            }
        })
        .collect()
}

/// Trains every planned source, then writes them all. Nothing is written if one fails or
/// the user stops (a [`Command::Stop`] on `stop`), and a library already on disk is
/// replaced only when `retrain` is set.
pub fn train_library(
    config: &Config,
    library: &Path,
    retrain: bool,
    stop: &Receiver<Command>,
) -> Result<PathBuf> {
    let dir = library_dir(library, config);
    let existing = policy_store::list(&dir)?;
    if !existing.is_empty() && !retrain {
        bail!(
            "{} already holds {} policies; pass --retrain to replace them",
            dir.display(),
            existing.len()
        );
    }
    let plans = plan(config);
    let mut progress = crate::headless::Progress::new(
        u64::from(config.sources.training_episodes) * plans.len() as u64,
    );
    let source_dqn = config.sources.dqn.as_ref().unwrap_or(&config.dqn);
    let mut trained = Vec::with_capacity(plans.len());
    for (i, source) in plans.iter().enumerate() {
        let spec = RunSpec::scratch(
            i as u32,
            &source.name,
            source_task(config).clone(),
            source_dqn.clone(),
            source.hidden.clone(),
            config.sources.training_episodes,
            config.protocol.test_episodes,
            source.seed,
        );
        let mut training = SourceTraining {
            progress: &mut progress,
            outcome: None,
        };
        let stopped = schedule(vec![spec], 1, stop, &mut training)
            .with_context(|| format!("training {}", source.name))?;
        let outcome = training
            .outcome
            .expect("a run that neither failed nor was stopped has an outcome");
        if stopped || outcome.record.stopped {
            progress.finish(false);
            bail!(
                "stopped by the user: nothing in {} was changed",
                dir.display()
            );
        }
        trained.push(outcome);
    }
    progress.finish(true);

    for (source, outcome) in plans.iter().zip(&trained) {
        let returns = &outcome.record.test_returns;
        let info = PolicyInfo {
            source_task: source_task(config).clone(),
            training: TrainingBudget {
                episodes: u64::from(outcome.record.episodes),
                steps: outcome.record.steps,
            },
            seed: source.seed,
            final_score: (!returns.is_empty())
                .then(|| returns.iter().sum::<f64>() / returns.len() as f64),
            reused: None,
        };
        policy_store::save(&dir, &source.name, &outcome.net, &info)
            .with_context(|| format!("writing {} to {}", source.name, dir.display()))?;
    }
    // A smaller library replaces a larger one: its extra sources must go.
    for stale in existing
        .iter()
        .filter(|name| !plans.iter().any(|p| &p.name == *name))
    {
        let (weights, metadata) = policy_store::paths(&dir, stale);
        for path in [metadata, weights] {
            match std::fs::remove_file(&path) {
                Err(err) if err.kind() != std::io::ErrorKind::NotFound => {
                    return Err(err)
                        .with_context(|| format!("removing the old policy {}", path.display()));
                }
                _ => {}
            }
        }
    }
    Ok(dir)
}

/// Progress of one source's training, and its outcome.
struct SourceTraining<'a> {
    progress: &'a mut crate::headless::Progress,
    outcome: Option<RunOutcome>,
}

impl Observer for SourceTraining<'_> {
    fn on_event(&mut self, event: Event) -> Result<()> {
        match event {
            Event::RunStarted { method, .. } => self.progress.run_started(method.label(), 0),
            Event::EpisodeEnded(record) => self.progress.episode(&record),
            _ => {}
        }
        Ok(())
    }

    fn on_finished(&mut self, _order: usize, _spec: &RunSpec, outcome: RunOutcome) -> Result<()> {
        self.outcome = Some(outcome);
        Ok(())
    }

    fn on_failed(&mut self, _spec: &RunSpec, err: TrainerError) -> anyhow::Error {
        anyhow::Error::new(err)
    }
}

/// Reads the source library of `config` from `<library>/<source task>/` for reuse on the
/// target task: every policy must load intact, fit the target task's sizes and have been
/// trained on the config's source task.
pub fn load_library(config: &Config, library: &Path) -> Result<Vec<SourcePolicy>> {
    let dir = library_dir(library, config);
    let mut names = policy_store::list(&dir)?;
    if names.is_empty() {
        bail!(
            "the source library {} holds no policies; train it with `sapnet sources --config <FILE>`",
            dir.display()
        );
    }
    // source-2 before source-10.
    names.sort_by_key(|name| natural_key(name));
    let env = crate::env::make(&config.env);
    let expected = source_task(config);
    let mut sources = Vec::with_capacity(names.len());
    for name in names {
        let stored =
            policy_store::load_for_task(&dir, &name, env.observation_size(), env.action_count())?;
        if &stored.metadata.source_task != expected {
            bail!(
                "policy {} was trained on {:?}, but the config's source task is {:?}; retrain the \
                 library with `sapnet sources --retrain` or use another --library",
                policy_store::paths(&dir, &name).1.display(),
                stored.metadata.source_task,
                expected
            );
        }
        sources.push(SourcePolicy {
            description: PolicyDescription {
                hidden: stored.metadata.architecture.hidden.clone(),
                activation: stored.metadata.activation.clone(),
                source_task: stored.metadata.source_task_name.clone(),
            },
            final_score: stored.metadata.final_score,
            net: stored.net,
            name,
        });
    }
    Ok(sources)
}

/// The library of `config`, trained first if `<library>/<task>/` holds none (with progress
/// on stderr; `stop` ends it), then loaded.
pub fn ensure_library(
    config: &Config,
    library: &Path,
    stop: &Receiver<Command>,
) -> Result<Vec<SourcePolicy>> {
    let dir = library_dir(library, config);
    if policy_store::list(&dir)?.is_empty() {
        eprintln!(
            "no source library in {}: training {} source policies first ({} episodes each)",
            dir.display(),
            config.sources.count,
            config.sources.training_episodes
        );
        train_library(config, library, false, stop)?;
    }
    load_library(config, library)
}

/// `source-10` → ("source-", 10): names with the same prefix sort by number.
fn natural_key(name: &str) -> (String, u64) {
    let digits = name.len() - name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    let (prefix, number) = name.split_at(name.len() - digits);
    (prefix.to_string(), number.parse().unwrap_or(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plans_stay_in_range_and_follow_the_seed() {
        let mut config = Config::default();
        config.sources.count = 50;
        let plans = plan(&config);
        assert_eq!(plans.len(), 50);
        for p in &plans {
            assert!((1..=3).contains(&p.hidden.len()), "{p:?}");
            assert!(p.hidden.iter().all(|u| (50..=150).contains(u)), "{p:?}");
        }
        // All three depths occur among 50 draws (a failure here is a broken draw, not luck:
        // P(a depth missing) < 3·(2/3)^50 ≈ 5e-9).
        for layers in 1..=3 {
            assert!(plans.iter().any(|p| p.hidden.len() == layers));
        }
        assert_eq!(plans, plan(&config));
        config.seed = 1;
        assert_ne!(plans, plan(&config));
    }

    #[test]
    fn numbered_names_sort_by_number() {
        let mut names = vec!["source-10", "source-2", "source-1", "other"];
        names.sort_by_key(|n| natural_key(n));
        assert_eq!(names, ["other", "source-1", "source-2", "source-10"]);
    }
}
