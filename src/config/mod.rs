//! The run configuration, read from RON (`assets/*.ron`): the sections each layer owns
//! (the task with `env`, the DQN with `dqn`, SAP-Net with `sapnet`, the methods with
//! `reuse`), gathered and checked across.
//!
//! Every hyper-parameter of the method lives in a section with a doc line, none as a
//! literal in code. Defaults are the paper's Tables I and II and `DESIGN.md`; a field left
//! out of a file keeps its default, an unknown field or a wrong type is an error that names
//! the file, the line and column, and the field's path ([`crate::ron_file`]).

mod protocol;
mod sources;

use std::path::Path;

use serde::{Deserialize, Serialize};

pub use protocol::{Budget, ProtocolConfig};
pub use sources::{SourceTaskConfig, SourcesConfig};

use crate::dqn::DqnConfig;
use crate::env::{CartPoleParams, EnvConfig, PythonSettings};
use crate::ron_file::{parse_ron, read_text, sapnet_field, ConfigError};
use crate::sapnet::SapNetParams;

/// Everything one run needs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// The target task and its physics.
    pub env: EnvConfig,
    /// DQN hyper-parameters (Table I, ChainerRL's defaults where the paper is silent).
    pub dqn: DqnConfig,
    /// SAP-Net parameters (Table II).
    pub sapnet: SapNetParams,
    /// The source-policy library.
    pub sources: SourcesConfig,
    /// What an experiment runs and how often.
    pub protocol: ProtocolConfig,
    /// The run seed: everything random derives from it.
    pub seed: u64,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            env: EnvConfig::CartPole(CartPoleParams::default()),
            dqn: DqnConfig::default(),
            sapnet: SapNetParams::default(),
            sources: SourcesConfig::default(),
            protocol: ProtocolConfig::default(),
            seed: 0,
        }
    }
}

impl Config {
    /// Reads and validates a config file.
    pub fn from_file(path: &Path) -> Result<Self, ConfigError> {
        let text = read_text(path)?;
        let mut config = Self::from_ron(&text, &path.display().to_string())?;
        // A task's module folder is the config's to name, relative to the config itself:
        // never to the folder sapnet happens to be started in.
        let folder = path.parent().unwrap_or(Path::new(""));
        for (_, task) in config.tasks_mut() {
            if let EnvConfig::Gymnasium(p) = task {
                if let Some(dir) = &mut p.module_dir {
                    let joined = folder.join(&*dir);
                    *dir = std::path::absolute(&joined).unwrap_or(joined);
                }
            }
        }
        Ok(config)
    }

    /// Every task of the config, with its field: the target, the sources' task, each of
    /// the library's tasks.
    pub fn tasks(&self) -> Vec<(String, &EnvConfig)> {
        let mut tasks = vec![("env".to_string(), &self.env)];
        if let Some(env) = &self.sources.env {
            tasks.push(("sources.env".into(), env));
        }
        for (i, task) in self.sources.tasks.iter().enumerate() {
            tasks.push((format!("sources.tasks[{i}].env"), &task.env));
        }
        tasks
    }

    fn tasks_mut(&mut self) -> Vec<(String, &mut EnvConfig)> {
        let mut tasks = vec![("env".to_string(), &mut self.env)];
        if let Some(env) = &mut self.sources.env {
            tasks.push(("sources.env".into(), env));
        }
        for (i, task) in self.sources.tasks.iter_mut().enumerate() {
            tasks.push((format!("sources.tasks[{i}].env"), &mut task.env));
        }
        tasks
    }

    /// The config as results record it: every task without how this machine runs it
    /// ([`EnvConfig::as_recorded`]), so that a folder never names a program to run.
    pub fn as_recorded(&self) -> Config {
        let mut recorded = self.clone();
        for (_, task) in recorded.tasks_mut() {
            *task = task.as_recorded();
        }
        recorded
    }

    /// Runs every Gymnasium task with the user's `--python` and `--module-dir`.
    pub fn run_with(&mut self, python: &PythonSettings) {
        for (_, task) in self.tasks_mut() {
            task.run_with(python);
        }
    }

    /// Checks a config read from a folder the user may have received: none of its tasks
    /// chooses code to run ([`EnvConfig::check_received`]).
    pub fn check_received(&self, python: &PythonSettings) -> Result<(), String> {
        for (field, task) in self.tasks() {
            task.check_received(&format!("{field}.Gymnasium"), python)?;
        }
        Ok(())
    }

    /// Reads and validates a config from RON text; `origin` names it in errors.
    pub fn from_ron(text: &str, origin: &str) -> Result<Self, ConfigError> {
        let config: Config = parse_ron(text, origin)?;
        config.validate().map_err(|message| ConfigError::Invalid {
            origin: origin.to_string(),
            message,
        })?;
        Ok(config)
    }

    /// What a valid config does that its author may not mean, to say on stderr.
    pub fn warnings(&self) -> Vec<String> {
        let mut said = Vec::new();
        if self.protocol.test_episodes == 0 {
            said.push(
                "protocol.test_episodes is 0: nothing is tested greedily, so tests.csv, \
                 tests.png and the comparison's test column stay empty, and a library trained \
                 with it has no scores (BestSource cannot pick)"
                    .to_string(),
            );
        }
        for (field, task) in self.tasks() {
            if let Some(module) = task.imported_module() {
                said.push(format!(
                    "{field}: the Gymnasium id {:?} imports the Python module {module} (from \
                     the task's module_dir, your PYTHONPATH or the interpreter's packages)",
                    task.gym_id()
                ));
            }
        }
        said
    }

    /// Cuts the protocol for a smoke run: 1/20 of the budget, at most 2 runs per method.
    /// The source library is the real one (a library trained on a cut budget would be
    /// reused by later full runs).
    pub fn quick(&mut self) {
        self.protocol.budget = self.protocol.budget.cut(20);
        self.protocol.runs = self.protocol.runs.min(2);
    }

    /// Checks the values serde cannot: ranges and relations between fields.
    pub fn validate(&self) -> Result<(), String> {
        self.env.validate("env")?;
        self.sources.validate(&self.env)?;
        self.dqn.validate("dqn")?;
        if let Some(sources) = &self.sources.dqn {
            sources.validate("sources.dqn")?;
        }
        // 𝒜 > 0 among them: SAP-Net's own parameters refuse what the net cannot run on.
        self.sapnet.validate().map_err(|e| {
            sapnet_field(&e, "sapnet.").unwrap_or_else(|| format!("section `sapnet`: {e}"))
        })?;
        self.protocol.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dqn::Exploration;
    use crate::reuse::Method;

    /// The budget reads as written, and as configs and results folders wrote it before
    /// there was one; written back, it reads the same.
    #[test]
    fn the_budget_reads_in_either_form_and_round_trips() {
        let read = |text: &str| Config::from_ron(text, "test.ron").map(|c| c.protocol.budget);
        assert_eq!(
            read("(protocol: (budget: Steps(1000)))").unwrap(),
            Budget::Steps(1000)
        );
        assert_eq!(
            read("(protocol: (budget: Episodes(7)))").unwrap(),
            Budget::Episodes(7)
        );
        assert_eq!(
            read("(protocol: (episodes: 7))").unwrap(),
            Budget::Episodes(7)
        );
        let zoo = "(protocol: (episodes: 100000, max_steps: Some(50000)))";
        assert_eq!(read(zoo).unwrap(), Budget::Steps(50000));
        assert_eq!(
            read("(protocol: (runs: 3))").unwrap(),
            Budget::Episodes(5000)
        );
        let both = read("(protocol: (budget: Steps(10), episodes: 5))")
            .unwrap_err()
            .to_string();
        assert!(both.contains("protocol.budget"), "{both}");
        for budget in [Budget::Steps(123), Budget::Episodes(45)] {
            let mut config = Config::default();
            config.protocol.budget = budget;
            let ron = crate::ron_file::ron_options().to_string(&config).unwrap();
            assert_eq!(read(&ron).unwrap(), budget, "{ron}");
            let json = serde_json::to_string(&config).unwrap();
            let back: Config = serde_json::from_str(&json).unwrap();
            assert_eq!(back.protocol.budget, budget, "{json}");
        }
    }

    #[test]
    fn a_syntax_error_between_fields_names_the_field_around_it() {
        let err = Config::from_ron("(\n    dqn: (batch_size: 32.5),\n)", "bad.ron")
            .unwrap_err()
            .to_string();
        // A fraction where a whole number belongs: named at its field, not the struct.
        assert!(
            err.contains(
                "line 2, column 25, field `dqn.batch_size`: expected a whole number, got 32.5"
            ),
            "{err}"
        );
        let err = Config::from_ron("(\n    dqn: (batch_size: 32),\n", "bad.ron")
            .unwrap_err()
            .to_string();
        assert!(!err.contains('?'), "{err}");
    }

    #[test]
    fn a_bad_sapnet_parameter_is_worded_as_every_field() {
        let err = Config::from_ron("(sapnet: (temperature: -1.0))", "t.ron")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("field `sapnet.temperature`: expected a finite number > 0, got -1.0"),
            "{err}"
        );
    }

    #[test]
    fn defaults_are_the_papers_tables() {
        let c = Config::default();
        assert_eq!(c.dqn.gamma, 0.99);
        assert_eq!(c.dqn.adam_epsilon, 1e-3);
        assert_eq!(c.dqn.replay_capacity, 1_000_000);
        assert_eq!(c.dqn.replay_start_size, 50);
        assert_eq!(c.dqn.target_update_interval, 10_000);
        assert_eq!(c.dqn.exploration, Exploration::Constant { epsilon: 0.03 });
        assert_eq!(c.sapnet.delta, -0.5);
        assert_eq!(c.sapnet.threshold, 1.0);
        assert_eq!(c.sapnet.coefficient, 1.0);
        assert_eq!(c.sapnet.prototypes[0].omega, 0.1);
        assert_eq!(c.protocol.budget, Budget::Episodes(5000));
        assert_eq!(c.protocol.runs, 5);
        assert_eq!(c.protocol.test_episodes, 5);
        assert_eq!(c.sources.count, 10);
    }

    #[test]
    fn an_empty_document_is_the_default() {
        assert_eq!(Config::from_ron("()", "test").unwrap(), Config::default());
    }

    #[test]
    fn newtype_variants_need_no_double_parentheses() {
        let c = Config::from_ron("(env: MountainCar(max_episode_steps: 300))", "test").unwrap();
        match c.env {
            EnvConfig::MountainCar(p) => assert_eq!(p.max_episode_steps, 300),
            other => panic!("wrong env {other:?}"),
        }
    }

    #[test]
    fn a_method_listed_twice_is_refused_with_its_place() {
        let err = Config::from_ron(
            "(protocol: (methods: [Dqn(hidden: [8]), Ucb1, Dqn(hidden: [8])]))",
            "test",
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("field `protocol.methods[2]`: lists dqn[8] a second time"),
            "{err}"
        );
    }

    #[test]
    fn every_method_reads_from_ron_and_bad_knobs_are_located() {
        let c = Config::from_ron(
            "(protocol: (methods: [SapNet, SapNetWith(judgment: Episode, decay: 0.999), \
             SapNetWith(judgment: KSteps(10), temperature: Some(Linear(from: 4.0, to: 0.5, \
             steps: 1000))), Random, RandomPerEpisode, Ucb1, Prql(), Prql(psi: 0.5), \
             BestSource, Dqn(hidden: [100])]))",
            "test",
        )
        .unwrap();
        let labels: Vec<String> = c.protocol.methods.iter().map(Method::label).collect();
        assert_eq!(
            labels,
            [
                "sapnet",
                "sapnet-episode-decay0.999",
                "sapnet-tau-lin4-0.5-k10",
                "random",
                "random-episode",
                "ucb1",
                "prql",
                "prql-psi0.5",
                "best-source",
                "dqn[100]"
            ]
        );
        for (text, field) in [
            ("SapNetWith(decay: 0.0)", "protocol.methods[0].decay"),
            (
                "SapNetWith(judgment: KSteps(0))",
                "protocol.methods[0].judgment",
            ),
            (
                "SapNetWith(temperature: Some(Exponential(from: 0.0, to: 1.0, steps: 5)))",
                "protocol.methods[0].temperature.from",
            ),
            ("Prql(psi: 2.0)", "protocol.methods[0].psi"),
            ("Prql(upsilon: 0.0)", "protocol.methods[0].upsilon"),
        ] {
            let err = Config::from_ron(&format!("(protocol: (methods: [{text}]))"), "x.ron")
                .unwrap_err()
                .to_string();
            assert!(err.contains(&format!("field `{field}`")), "{text}: {err}");
        }
        // τ ≤ 0 for the paper's SAP-Net is refused in its own section.
        let err = Config::from_ron("(sapnet: (temperature: 0.0))", "x.ron")
            .unwrap_err()
            .to_string();
        assert!(err.contains("temperature"), "{err}");
    }
}
