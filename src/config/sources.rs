//! The `sources` section: the library of source policies (paper III-B), over one source
//! task or several.

use serde::{Deserialize, Serialize};

use crate::dqn::DqnConfig;
use crate::env::mapping::{check_fit, native_spaces, InterTaskMapping};
use crate::env::EnvConfig;
use crate::limits::{MAX_EPISODES, MAX_HIDDEN_LAYERS, MAX_SOURCES};
use crate::ron_file::check;

/// The library of source policies (paper III-B).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SourcesConfig {
    /// N, the number of source policies (paper: 10).
    pub count: usize,
    /// Inclusive range of the number of hidden layers, drawn uniformly (paper: 1–3).
    pub hidden_layers: (usize, usize),
    /// Inclusive range of units per hidden layer, drawn uniformly (around 100).
    pub units: (usize, usize),
    /// Episodes each source policy trains on the source task (default: Table I's 5000 for
    /// CartPole; with the paper's ε and target interval, a few hundred leave most sources
    /// at ~10-step episodes, see BENCHMARKS.md "Learning").
    pub training_episodes: u32,
    /// The source task, when it differs from the target task (`None`: the same).
    pub env: Option<EnvConfig>,
    /// A library over several source tasks (empty: all `count` policies on `env`): each
    /// task with its physics and how many of the `count` policies train on it, in order.
    pub tasks: Vec<SourceTaskConfig>,
    /// The library's folder under `--library` (default: the source task's name, e.g.
    /// `cartpole`); needed with `tasks`.
    pub name: Option<String>,
    /// DQN settings for training the sources, when they differ from the experiment's `dqn`
    /// (`None`: the same; fields left out take Table I's defaults). The paper does not say
    /// how its sources were trained; with Table I's settings MountainCar sources never
    /// reach the flag.
    pub dqn: Option<DqnConfig>,
}

impl Default for SourcesConfig {
    fn default() -> Self {
        Self {
            count: 10,
            hidden_layers: (1, 3),
            units: (50, 150),
            training_episodes: 5000,
            env: None,
            tasks: Vec::new(),
            name: None,
            dqn: None,
        }
    }
}

/// One source task of a library over several (`sources.tasks`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceTaskConfig {
    /// The task with its physics, e.g. `CartPole(length: 1.0)`.
    pub env: EnvConfig,
    /// How many policies train on it.
    pub count: usize,
    /// Its name in results and on the graph (default: the task and what differs from its
    /// defaults, e.g. `cartpole(length=1.0)`).
    #[serde(default)]
    pub label: Option<String>,
    /// How a source of another agent (other observation or action space than the target's)
    /// is reused: χ_X and χ_A (`crate::env::mapping`, docs/FUTURE_WORK.md).
    #[serde(default)]
    pub mapping: Option<InterTaskMapping>,
}

impl SourcesConfig {
    /// The ranges serde cannot check, and the tasks' fit to the `target` task.
    pub fn validate(&self, target: &EnvConfig) -> Result<(), String> {
        if let Some(env) = &self.env {
            env.validate("sources.env")?;
        }
        self.check_tasks(target)?;
        let src = self;
        check(
            (1..=MAX_SOURCES).contains(&src.count),
            "sources.count",
            &format!("1 to {MAX_SOURCES} policies"),
            src.count,
        )?;
        check(
            src.training_episodes > 0,
            "sources.training_episodes",
            "at least 1 (0 would write an untrained library)",
            src.training_episodes,
        )?;
        check(
            src.training_episodes <= MAX_EPISODES,
            "sources.training_episodes",
            &format!("at most {MAX_EPISODES}"),
            src.training_episodes,
        )?;
        check(
            src.hidden_layers.0 >= 1 && src.hidden_layers.0 <= src.hidden_layers.1,
            "sources.hidden_layers",
            "(min, max) with 1 <= min <= max",
            format!("{:?}", src.hidden_layers),
        )?;
        check(
            src.hidden_layers.1 <= MAX_HIDDEN_LAYERS,
            "sources.hidden_layers",
            &format!("at most {MAX_HIDDEN_LAYERS} hidden layers"),
            format!("{:?}", src.hidden_layers),
        )?;
        check(
            src.units.0 >= 1 && src.units.0 <= src.units.1,
            "sources.units",
            "(min, max) with 1 <= min <= max",
            format!("{:?}", src.units),
        )
    }

    /// `sources.tasks` and `sources.name`: tasks that make sense, as many policies as
    /// `count`, a portable folder name.
    fn check_tasks(&self, target: &EnvConfig) -> Result<(), String> {
        let s = self;
        if let Some(name) = &s.name {
            check(
                crate::safe_io::is_portable_name(name) && name != "chosen",
                "sources.name",
                &format!(
                    "a folder name of {} (not `chosen`)",
                    crate::safe_io::PORTABLE_NAME
                ),
                format!("{name:?}"),
            )?;
        }
        if s.tasks.is_empty() {
            return Ok(());
        }
        check(
            s.env.is_none(),
            "sources.env",
            "None with `sources.tasks` (give the source tasks one way)",
            "Some(..)",
        )?;
        check(
            s.name.is_some(),
            "sources.name",
            "the library's folder name, needed with `sources.tasks`",
            "None",
        )?;
        for (i, task) in s.tasks.iter().enumerate() {
            task.env.validate(&format!("sources.tasks[{i}].env"))?;
            check(
                task.count > 0,
                &format!("sources.tasks[{i}].count"),
                "at least 1",
                task.count,
            )?;
            // A Gymnasium task's spaces are known once its Python side runs: loading the
            // library checks them.
            if let (Some(source), Some(target)) = (native_spaces(&task.env), native_spaces(target))
            {
                check_fit(
                    &format!("sources.tasks[{i}]"),
                    task.mapping.as_ref(),
                    source,
                    target,
                )?;
            }
        }
        let total: usize = s.tasks.iter().map(|t| t.count).sum();
        check(
            total == s.count,
            "sources.count",
            &format!("the policies of sources.tasks together, {total}"),
            s.count,
        )?;
        let labels: Vec<String> = s
            .tasks
            .iter()
            .map(|t| t.label.clone().unwrap_or_else(|| t.env.label()))
            .collect();
        if let Some((i, twice)) = labels
            .iter()
            .enumerate()
            .find(|(i, l)| labels[..*i].contains(l))
        {
            return Err(format!(
                "field `sources.tasks[{i}]`: {twice} is listed a second time; give each task \
                 once, with its count"
            ));
        }
        Ok(())
    }
}
