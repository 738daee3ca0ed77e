//! A Gymnasium task as a config names it, how this machine runs it (never recorded), and
//! what sapnet knows of some ids.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::env::rules::Rules;

/// A Gymnasium task: `Gymnasium(id: "LunarLander-v3", kwargs: {"gravity": -8.0})`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GymnasiumParams {
    /// The registered id, as `gymnasium.make` takes it.
    pub id: String,
    /// Keyword arguments of `gymnasium.make(id, **kwargs)`: the task's own (`gravity`,
    /// `enable_wind` of LunarLander) or `make`'s.
    pub kwargs: BTreeMap<String, serde_json::Value>,
    /// Attributes set on `env.unwrapped` after it is made, for constants a task has no
    /// keyword for (CartPole's `length`; derived ones such as its `polemass_length` are
    /// the config's to set too).
    pub attributes: BTreeMap<String, serde_json::Value>,
    /// The time limit (`TimeLimit`'s); `None`: the registered one.
    pub max_episode_steps: Option<u32>,
    /// `Some([lowest, highest])`, the returns of an episode, which scale returns for UCB1,
    /// PRQ-learning and pooled reports; required unless [`known`] has them for `id`.
    pub return_range: Option<Vec<f64>>,
    /// The Python that has Gymnasium; `None`: the active virtualenv's, else `python3`.
    /// How this machine runs the task, not the task: never recorded with results or a
    /// library ([`EnvConfig::as_recorded`]), and `--python` overrides it.
    pub python: Option<PathBuf>,
    /// A folder the worker adds to Python's path, for an id that names a module of the
    /// user's own (`"my_envs:Maze-v0"` imports `my_envs` from it). Relative to the config
    /// file's folder. Like `python`, never recorded; nothing else is imported from the
    /// folder sapnet runs in.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub module_dir: Option<PathBuf>,
    /// How long the Python side may take to make the environment, and each step or reset.
    #[serde(skip_serializing_if = "WorkerTimeouts::is_default")]
    pub timeouts: WorkerTimeouts,
}

/// How this machine runs Gymnasium tasks, from the user's own invocation (flags), never
/// from a folder: the interpreter (`--python`), the folder of the user's own environment
/// modules (`--module-dir`), and the modules a received folder's task ids may import
/// (`--allow-module`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PythonSettings {
    pub interpreter: Option<PathBuf>,
    pub module_dir: Option<PathBuf>,
    pub allowed_modules: Vec<String>,
}

/// Seconds the Python side of a Gymnasium task may take before it is killed and the run
/// fails: `timeouts: (start: 120, step: 60)`, each at most [`WorkerTimeouts::MAX`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WorkerTimeouts {
    /// Importing Gymnasium and making the environment.
    pub start: u32,
    /// One step, reset or state exchange.
    pub step: u32,
}

impl WorkerTimeouts {
    /// A day: longer is a hang, not a slow task.
    pub const MAX: u32 = 86_400;

    fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

impl Default for WorkerTimeouts {
    fn default() -> Self {
        Self {
            start: 120,
            step: 60,
        }
    }
}

impl GymnasiumParams {
    pub(in crate::env) fn check(&self, rules: &mut Rules) {
        rules.holds(
            "id",
            !self.id.is_empty()
                && self
                    .id
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_/:.".contains(c)),
            &format!(
                "a registered Gymnasium id such as \"LunarLander-v3\", got {:?}",
                self.id
            ),
        );
        for (field, names) in [("kwargs", &self.kwargs), ("attributes", &self.attributes)] {
            for name in names.keys() {
                rules.holds(
                    field,
                    !name.is_empty()
                        && !name.starts_with(|c: char| c.is_ascii_digit())
                        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'),
                    &format!("Python identifiers as names, got {name:?}"),
                );
            }
        }
        if let Some(steps) = self.max_episode_steps {
            rules.time_limit(steps);
        }
        for (field, seconds) in [
            ("timeouts.start", self.timeouts.start),
            ("timeouts.step", self.timeouts.step),
        ] {
            rules.holds(
                field,
                (1..=WorkerTimeouts::MAX).contains(&seconds),
                &format!(
                    "seconds from 1 to {} (a day), got {seconds}",
                    WorkerTimeouts::MAX
                ),
            );
        }
        match self.return_range.as_deref() {
            Some(range) => rules.holds(
                "return_range",
                matches!(*range, [low, high] if low.is_finite() && high.is_finite() && low < high),
                &format!("Some([lowest, highest]) finite with lowest < highest, got {range:?}"),
            ),
            None => rules.holds(
                "return_range",
                known_task(&self.id).is_some(),
                &format!(
                    "Some([lowest, highest]): the returns of {} an episode can have (it scales \
                     returns for UCB1, PRQ-learning and pooled reports; sapnet knows it only \
                     for CartPole, MountainCar, Acrobot and LunarLander)",
                    self.id
                ),
            ),
        }
    }
}

/// What sapnet knows of some Gymnasium tasks, so that a config need not say it.
pub struct KnownTask {
    pub return_range: (f64, f64),
    pub thresholds: &'static [f64],
    pub max_episode_steps: u32,
}

/// The classic-control tasks as Gymnasium registers them, and LunarLander-v3, whose
/// returns have no bounds: its range is a scale, from about a random policy's return
/// (−200) to above "solved" (200) at 300.
pub fn known_task(id: &str) -> Option<KnownTask> {
    Some(match id {
        "CartPole-v1" => KnownTask {
            return_range: (0.0, 500.0),
            thresholds: &[195.0, 475.0],
            max_episode_steps: 500,
        },
        "CartPole-v0" => KnownTask {
            return_range: (0.0, 200.0),
            thresholds: &[195.0, 475.0],
            max_episode_steps: 200,
        },
        "MountainCar-v0" => KnownTask {
            return_range: (-200.0, 0.0),
            thresholds: &[-150.0, -110.0],
            max_episode_steps: 200,
        },
        "Acrobot-v1" => KnownTask {
            return_range: (-500.0, 0.0),
            thresholds: &[-150.0, -100.0],
            max_episode_steps: 500,
        },
        "LunarLander-v3" => KnownTask {
            return_range: (-200.0, 300.0),
            thresholds: &[100.0, 200.0],
            max_episode_steps: 1000,
        },
        _ => return None,
    })
}

impl GymnasiumParams {
    /// The task without how this machine runs it: no `python`, no `module_dir`.
    pub fn as_recorded(&self) -> GymnasiumParams {
        GymnasiumParams {
            python: None,
            module_dir: None,
            ..self.clone()
        }
    }

    /// The user's `--python` and `--module-dir`, where given.
    pub fn run_with(&mut self, python: &PythonSettings) {
        if let Some(interpreter) = &python.interpreter {
            self.python = Some(interpreter.clone());
        }
        if let Some(dir) = &python.module_dir {
            self.module_dir = Some(dir.clone());
        }
    }

    /// The module the id imports (`"my_envs:Maze-v0"` imports `my_envs`), if it names one.
    pub fn imported_module(&self) -> Option<&str> {
        self.id.split_once(':').map(|(module, _)| module)
    }

    /// Checks a task read from a folder the user may have received (a results folder's
    /// `summary.json`, a sweep's cell): it may not choose code to run. A program
    /// (`python`), a folder to import from (`module_dir`) or a module to import (an id
    /// `module:Env`) is refused unless the user's own invocation names the same one
    /// (`--python`, `--module-dir`, `--allow-module`). `field` is the task's path in the
    /// config, for the message.
    pub fn check_received(&self, field: &str, python: &PythonSettings) -> Result<(), String> {
        let p = self;
        let refuse = |name: &str, stored: &Path, flag: &str, given: &Option<PathBuf>| {
            let given = given.as_ref().map_or(String::new(), |g| {
                format!(" (you gave {flag} {})", g.display())
            });
            Err(format!(
                "field `{field}.{name}` names {}{given}: a folder from elsewhere does not choose \
                 what sapnet runs (sapnet records none; this folder was written by hand or by an \
                 older sapnet). Give your own with {flag} PATH, the same path if you trust it",
                stored.display()
            ))
        };
        if let Some(stored) = &p.python {
            if python.interpreter.as_ref() != Some(stored) {
                return refuse("python", stored, "--python", &python.interpreter);
            }
        }
        if let Some(stored) = &p.module_dir {
            if python.module_dir.as_ref() != Some(stored) {
                return refuse("module_dir", stored, "--module-dir", &python.module_dir);
            }
        }
        if let Some(module) = self.imported_module() {
            if !python.allowed_modules.iter().any(|m| m == module) {
                return Err(format!(
                    "field `{field}.id` is {:?}, which imports the Python module {module}: a \
                     folder from elsewhere does not choose code to run. Give --allow-module \
                     {module} if you trust it",
                    p.id
                ));
            }
        }
        Ok(())
    }
}
