//! `--tensorboard`: each run of a protocol as a TensorBoard run,
//! `<out>/tensorboard/<method>-run<r>/`, written while it trains so that `tensorboard
//! --logdir <out>/tensorboard` shows the protocol live.
//!
//! A run's folder is named by its method's label as the results show it (`dqn[100]-run0`),
//! so that TensorBoard's run selector reads as the comparison table does.
//!
//! Tags are CleanRL's where it has one (`charts/episodic_return`, `charts/episodic_length`,
//! `losses/td_loss`, `charts/epsilon`, `charts/SPS`, each at the run's global step as
//! CleanRL logs them) and sapnet's own for what a reusing run adds:
//! `sapnet/activation/<source>` and `sapnet/probability/<source>` at each selector
//! snapshot, and `sapnet/acting_source/<source>`, 1 for the source that acted most in the
//! episode and 0 for the others. Which source acted is a category: as one scalar (its
//! index) TensorBoard would draw a line between sources and smooth it into indices that
//! name none; as one indicator a source, smoothing gives the share of recent episodes each
//! led. The run's settings are its hyper-parameters (TensorBoard's HParams tab), its end
//! the session's status.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::config::{Budget, Config};
use crate::results::records::run_name;
use crate::tensorboard::{EventWriter, HParamValue, SessionStatus};
use crate::trainer::{ActivationSnapshot, EpisodeRecord, MethodId, RunSpec};

/// The folder of the event files under `--out`.
pub const TENSORBOARD_DIR: &str = "tensorboard";

/// One run's event file and its global step.
struct RunLog {
    writer: EventWriter,
    /// Environment steps so far: the x axis of every scalar.
    steps: u64,
}

/// The event files of a protocol's runs in progress.
pub(super) struct TensorBoardRuns {
    root: PathBuf,
    /// The library's sources, naming the activation and probability tags.
    names: Vec<String>,
    /// Each planned run's seed, for its hyper-parameters.
    seeds: BTreeMap<(MethodId, u32), u64>,
    runs: BTreeMap<(MethodId, u32), RunLog>,
}

impl TensorBoardRuns {
    /// Event files under `<out>/tensorboard/`, made if missing (a real directory, never a
    /// link to elsewhere).
    pub(super) fn new(out: &Path, names: Vec<String>, specs: &[RunSpec]) -> Result<Self> {
        let root = out.join(TENSORBOARD_DIR);
        crate::safe_io::real_dir(&root).with_context(|| format!("{}", root.display()))?;
        Ok(Self {
            root,
            names,
            seeds: specs
                .iter()
                .map(|s| ((s.method.clone(), s.run), s.seed))
                .collect(),
            runs: BTreeMap::new(),
        })
    }

    /// Starts `method`'s run `run` afresh: what a killed or stopped attempt of it left
    /// is removed, so a resumed protocol's curves are each run's once.
    pub(super) fn run_started(
        &mut self,
        config: &Config,
        method: &MethodId,
        run: u32,
    ) -> Result<()> {
        let dir = self.root.join(event_dir_name(method.label(), run));
        // remove_dir_all removes a planted link itself, never what it points to.
        if std::fs::symlink_metadata(&dir).is_ok() {
            std::fs::remove_dir_all(&dir)
                .or_else(|_| std::fs::remove_file(&dir))
                .with_context(|| format!("removing the earlier attempt {}", dir.display()))?;
        }
        let mut writer = EventWriter::create(&dir)
            .with_context(|| format!("starting an event file in {}", dir.display()))?;
        writer
            .hparams(&hparams(
                config,
                method,
                run,
                self.seeds.get(&(method.clone(), run)),
            ))
            .with_context(|| format!("writing {}", writer.path().display()))?;
        self.runs
            .insert((method.clone(), run), RunLog { writer, steps: 0 });
        Ok(())
    }

    /// An episode's return, length, loss, ε, steps per second and acting source, at the
    /// step it ended.
    pub(super) fn episode(&mut self, record: &EpisodeRecord) -> Result<()> {
        let Some(log) = self.runs.get_mut(&(record.method.clone(), record.run)) else {
            return Ok(());
        };
        log.steps += u64::from(record.steps);
        let step = log.steps as i64;
        let w = &mut log.writer;
        let written = (|| {
            w.scalar("charts/episodic_return", step, record.reward as f32)?;
            w.scalar("charts/episodic_length", step, record.steps as f32)?;
            w.scalar("charts/epsilon", step, record.epsilon as f32)?;
            // CleanRL's: the run's steps over its seconds so far.
            if record.wall_s > 0.0 {
                w.scalar("charts/SPS", step, (step as f64 / record.wall_s) as f32)?;
            }
            if let Some(loss) = record.loss {
                w.scalar("losses/td_loss", step, loss as f32)?;
            }
            if let Some(acted) = record.policy {
                for (i, name) in self.names.iter().enumerate() {
                    let led = if i == acted as usize { 1.0 } else { 0.0 };
                    w.scalar(&format!("sapnet/acting_source/{name}"), step, led)?;
                }
            }
            // Each episode on disk as it ends: TensorBoard follows the run live.
            w.flush()
        })();
        written.with_context(|| format!("writing {}", w.path().display()))
    }

    /// A reusing run's scores and probabilities, one tag per source.
    pub(super) fn snapshot(&mut self, snapshot: &ActivationSnapshot) -> Result<()> {
        let Some(log) = self.runs.get_mut(&(snapshot.method.clone(), snapshot.run)) else {
            return Ok(());
        };
        let step = snapshot.step as i64;
        let w = &mut log.writer;
        let written = (|| {
            for (i, name) in self.names.iter().enumerate() {
                if let Some(&a) = snapshot.activations.get(i) {
                    w.scalar(&format!("sapnet/activation/{name}"), step, a as f32)?;
                }
                if let Some(&p) = snapshot.probabilities.get(i) {
                    w.scalar(&format!("sapnet/probability/{name}"), step, p as f32)?;
                }
            }
            std::io::Result::Ok(())
        })();
        written.with_context(|| format!("writing {}", w.path().display()))
    }

    /// Closes `method`'s run `run`: its session ends as finished, or stopped.
    pub(super) fn run_finished(
        &mut self,
        method: &MethodId,
        run: u32,
        stopped: bool,
    ) -> Result<()> {
        let Some(mut log) = self.runs.remove(&(method.clone(), run)) else {
            return Ok(());
        };
        let status = if stopped {
            SessionStatus::Failure
        } else {
            SessionStatus::Success
        };
        let w = &mut log.writer;
        w.end_session(status)
            .and_then(|()| w.flush())
            .with_context(|| format!("writing {}", w.path().display()))
    }
}

/// A run's event folder: its label as the results show it (a portable name but for the
/// brackets and commas of a network's sizes, which file names allow), unless too long for
/// a file name, then the run folder's name.
pub fn event_dir_name(label: &str, run: u32) -> String {
    const LONGEST: usize = 120;
    if label.len() <= LONGEST {
        format!("{label}-run{run}")
    } else {
        run_name(label, run)
    }
}

/// What TensorBoard's HParams tab shows of a run: its method and seed, and the settings
/// a comparison varies.
fn hparams(
    config: &Config,
    method: &MethodId,
    run: u32,
    seed: Option<&u64>,
) -> Vec<(&'static str, HParamValue)> {
    let dqn = &config.dqn;
    let seed = seed.map_or(String::new(), u64::to_string);
    vec![
        ("method", method.label().into()),
        ("family", method.kind.family.into()),
        ("task", config.env.gym_id().into()),
        ("run", HParamValue::Number(f64::from(run))),
        // As text: a 64-bit seed does not fit the f64 a number is shown as.
        ("seed", HParamValue::Text(seed)),
        (
            match config.protocol.budget {
                Budget::Episodes(_) => "episodes",
                Budget::Steps(_) => "steps",
            },
            HParamValue::Number(match config.protocol.budget {
                Budget::Episodes(n) => f64::from(n),
                Budget::Steps(n) => n as f64,
            }),
        ),
        ("gamma", HParamValue::Number(dqn.gamma)),
        ("learning_rate", HParamValue::Number(dqn.learning_rate)),
        ("batch_size", HParamValue::Number(dqn.batch_size as f64)),
        (
            "sapnet_temperature",
            HParamValue::Number(config.sapnet.temperature),
        ),
    ]
}
