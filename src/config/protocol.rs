//! The `protocol` section: what an experiment runs (its methods, each defined in
//! [`crate::reuse`]) and how often.

use serde::{Deserialize, Serialize};

use crate::env::EnvConfig;
use crate::limits::{MAX_EPISODES, MAX_HIDDEN_LAYERS, MAX_RUNS, MAX_STEPS, MAX_TEST_EPISODES};
use crate::reuse::Method;
use crate::ron_file::check;
pub use crate::trainer::Budget;

/// What an experiment runs and how often (paper III-B).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ProtocolFields", into = "ProtocolFields")]
pub struct ProtocolConfig {
    /// Each run's budget: `Episodes(5000)` (the paper's) or `Steps(n)`.
    pub budget: Budget,
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

/// The `protocol` section as a file writes it: `budget`, or the fields that said it before
/// there was one (`episodes: N`, with `max_steps: Some(n)` for a step budget), so that
/// every config and results folder written before still reads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
struct ProtocolFields {
    #[serde(
        skip_serializing_if = "Option::is_none",
        serialize_with = "bare",
        deserialize_with = "present"
    )]
    budget: Option<Budget>,
    // Written bare (`episodes: 5000`), as before `budget`.
    #[serde(skip_serializing_if = "Option::is_none", deserialize_with = "present")]
    episodes: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    max_steps: Option<u64>,
    runs: u32,
    test_episodes: u32,
    moving_average: usize,
    thresholds: Option<Vec<f64>>,
    methods: Vec<Method>,
}

/// A field present, written bare (`budget: Steps(1000)`, not `Some(…)`), as [`present`]
/// reads it back.
fn bare<S: serde::Serializer, T: Serialize>(
    value: &Option<T>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    match value {
        Some(value) => value.serialize(serializer),
        None => serializer.serialize_none(),
    }
}

/// A field written bare (`budget: Steps(1000)`, not `Some(…)`), present.
fn present<'de, D, T>(deserializer: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    T::deserialize(deserializer).map(Some)
}

impl Default for ProtocolFields {
    /// The defaults, the budget left for [`TryFrom`] to tell from what the file wrote.
    fn default() -> Self {
        Self {
            budget: None,
            ..ProtocolConfig::default().into()
        }
    }
}

impl TryFrom<ProtocolFields> for ProtocolConfig {
    type Error = String;

    fn try_from(f: ProtocolFields) -> Result<Self, String> {
        let budget = match (f.budget, f.episodes, f.max_steps) {
            (Some(budget), None, None) => budget,
            (Some(_), _, _) => {
                return Err(
                    "field `protocol.budget`: expected the budget once, as `budget: \
                     Steps(n)` or `budget: Episodes(n)`, got it beside the older `episodes` or \
                     `max_steps`"
                        .into(),
                )
            }
            // Before `budget`, a step budget was `max_steps` beside an episode count set
            // beyond reach.
            (None, _, Some(steps)) => Budget::Steps(steps),
            (None, Some(episodes), None) => Budget::Episodes(episodes),
            (None, None, None) => ProtocolConfig::default().budget,
        };
        Ok(Self {
            budget,
            runs: f.runs,
            test_episodes: f.test_episodes,
            moving_average: f.moving_average,
            thresholds: f.thresholds,
            methods: f.methods,
        })
    }
}

impl From<ProtocolConfig> for ProtocolFields {
    fn from(p: ProtocolConfig) -> Self {
        Self {
            budget: Some(p.budget),
            episodes: None,
            max_steps: None,
            runs: p.runs,
            test_episodes: p.test_episodes,
            moving_average: p.moving_average,
            thresholds: p.thresholds,
            methods: p.methods,
        }
    }
}

impl Default for ProtocolConfig {
    fn default() -> Self {
        Self {
            budget: Budget::Episodes(5000),
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
        match p.budget {
            Budget::Episodes(n) => check(
                (1..=MAX_EPISODES).contains(&n),
                "protocol.budget",
                &format!("Episodes(n) with 1 ≤ n ≤ {MAX_EPISODES}"),
                format!("Episodes({n})"),
            )?,
            Budget::Steps(n) => check(
                (1..=MAX_STEPS).contains(&n),
                "protocol.budget",
                &format!("Steps(n) with 1 ≤ n ≤ {MAX_STEPS}"),
                format!("Steps({n})"),
            )?,
        }
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
