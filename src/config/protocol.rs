//! The `protocol` section: what an experiment runs (its methods, each defined in
//! [`crate::reuse`]) and how often.

use serde::{Deserialize, Serialize};

use crate::env::EnvConfig;
use crate::limits::{MAX_EPISODES, MAX_HIDDEN_LAYERS, MAX_RUNS, MAX_STEPS, MAX_TEST_EPISODES};
use crate::reuse::Method;
use crate::ron_file::check;

/// What an experiment runs and how often (paper III-B).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProtocolConfig {
    /// Training episodes per run (Table I: 5000 CartPole, 10000 MountainCar).
    pub episodes: u32,
    /// Also stop a run after this many environment steps, cutting the episode in progress
    /// (rl-baselines3-zoo budgets in steps). `None`: episodes only.
    pub max_steps: Option<u64>,
    /// Independent runs per method, averaged (paper: 5).
    pub runs: u32,
    /// Greedy test episodes after training (Table I "Number of test": 5).
    pub test_episodes: u32,
    /// Window of the moving average of episode returns in plots (paper: 10).
    pub moving_average: usize,
    /// Moving averages whose first episode `comparison.csv` reports per method; `None`:
    /// the task's own (CartPole 195 and 475, MountainCar −150 and −110, Acrobot −150 and
    /// −100).
    pub thresholds: Option<Vec<f64>>,
    pub methods: Vec<Method>,
}

impl ProtocolConfig {
    /// The thresholds of the comparison on `env`.
    pub fn thresholds(&self, env: &EnvConfig) -> Vec<f64> {
        self.thresholds
            .clone()
            .unwrap_or_else(|| env.return_thresholds().to_vec())
    }
}

impl Default for ProtocolConfig {
    fn default() -> Self {
        Self {
            episodes: 5000,
            max_steps: None,
            runs: 5,
            test_episodes: 5,
            moving_average: 10,
            thresholds: None,
            methods: vec![
                Method::SapNet,
                Method::Dqn { hidden: vec![100] },
                Method::Dqn {
                    hidden: vec![100, 100],
                },
                Method::Dqn {
                    hidden: vec![100, 100, 100],
                },
            ],
        }
    }
}

impl ProtocolConfig {
    /// The ranges serde cannot check, each method's knobs by its own file, and the labels
    /// one each.
    pub fn validate(&self) -> Result<(), String> {
        let p = self;
        check(
            (1..=MAX_RUNS).contains(&p.runs),
            "protocol.runs",
            &format!("1 to {MAX_RUNS}"),
            p.runs,
        )?;
        check(
            (1..=MAX_EPISODES).contains(&p.episodes),
            "protocol.episodes",
            &format!("1 to {MAX_EPISODES}"),
            p.episodes,
        )?;
        check(
            p.test_episodes <= MAX_TEST_EPISODES,
            "protocol.test_episodes",
            &format!("at most {MAX_TEST_EPISODES}"),
            p.test_episodes,
        )?;
        if let Some(thresholds) = &p.thresholds {
            check(
                thresholds.len() <= 16 && thresholds.iter().all(|t| t.is_finite()),
                "protocol.thresholds",
                "None or Some([...]) of at most 16 finite returns",
                format!("{thresholds:?}"),
            )?;
        }
        if let Some(steps) = p.max_steps {
            check(
                (1..=MAX_STEPS).contains(&steps),
                "protocol.max_steps",
                &format!("None or Some(n) with 1 ≤ n ≤ {MAX_STEPS}"),
                format!("Some({steps})"),
            )?;
        }
        check(
            p.moving_average > 0,
            "protocol.moving_average",
            "at least 1",
            p.moving_average,
        )?;
        check(
            !p.methods.is_empty(),
            "protocol.methods",
            "at least one method",
            "[]",
        )?;
        for (i, method) in p.methods.iter().enumerate() {
            let field = format!("protocol.methods[{i}]");
            let method = method.definition();
            if let Some(hidden) = method.learner_hidden() {
                check(
                    hidden.len() <= MAX_HIDDEN_LAYERS,
                    &format!("{field}.hidden"),
                    &format!("at most {MAX_HIDDEN_LAYERS} hidden layers"),
                    format!("{} layers", hidden.len()),
                )?;
            }
            method.validate(&field)?;
        }
        let labels: Vec<String> = p.methods.iter().map(Method::label).collect();
        if let Some((i, twice)) = labels
            .iter()
            .enumerate()
            .find(|(i, l)| labels[..*i].contains(l))
        {
            return Err(format!(
                "field `protocol.methods[{i}]`: lists {twice} a second time; each method runs \
                 once per run (give a SapNetWith or Prql its own `label`)"
            ));
        }
        Ok(())
    }
}
