//! Sources from other agents: the declaration of an inter-task mapping (Taylor, Stone &
//! Liu, "Transfer Learning via Inter-Task Mappings for Temporal Difference Learning", JMLR 8,
//! 2007) and whether it fits the two tasks' spaces. How a network is rewritten through it is
//! the library's ([`crate::sources::mapping`]).
//!
//! - χ_X maps the target's state variables to the source's: the source's j-th input is the
//!   target's `state[j]`-th observation value;
//! - χ_A maps the source's actions to the target's: the source's a-th action is the
//!   target's `actions[a]`, or `None` when the target has nothing like it (a three-action
//!   CartPole's "no push").

use serde::{Deserialize, Serialize};

use super::EnvConfig;

/// χ_X and χ_A, as a library's RON declares them for a source task:
/// `mapping: Some(state: [2, 3, 0, 1], actions: [Some(0), None, Some(1)])`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterTaskMapping {
    /// χ_X: for each of the source's state variables, the target's variable it reads.
    pub state: Vec<usize>,
    /// χ_A: for each of the source's actions, the target's action it is, if any.
    pub actions: Vec<Option<usize>>,
}

/// An observation size and an action count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Spaces {
    pub observation_size: usize,
    pub action_count: usize,
}

impl std::fmt::Display for Spaces {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} observation values and {} actions",
            self.observation_size, self.action_count
        )
    }
}

impl InterTaskMapping {
    /// Whether the mapping fits a source of `source` spaces reused on a target of `target`
    /// spaces; the first misfit names its field under `field` (e.g.
    /// `sources.tasks[1].mapping`) and what was expected.
    pub fn check(&self, field: &str, source: Spaces, target: Spaces) -> Result<(), String> {
        if self.state.len() != source.observation_size {
            return Err(format!(
                "field `{field}.state`: expected {} entries, one per state variable of the \
                 source's agent (the target's variable it reads), got {}",
                source.observation_size,
                self.state.len()
            ));
        }
        if let Some((j, &v)) = self
            .state
            .iter()
            .enumerate()
            .find(|(_, &v)| v >= target.observation_size)
        {
            return Err(format!(
                "field `{field}.state[{j}]`: expected one of the target's state variables 0 to \
                 {}, got {v}",
                target.observation_size - 1
            ));
        }
        if self.actions.len() != source.action_count {
            let missing = self.actions.len();
            return Err(if missing < source.action_count {
                format!(
                    "field `{field}.actions`: source action {missing} has no image: expected \
                     {} entries, one per action of the source's agent (`Some(target action)`, \
                     or `None` for one the target has nothing like), got {missing}",
                    source.action_count
                )
            } else {
                format!(
                    "field `{field}.actions`: expected {} entries, one per action of the \
                     source's agent, got {missing}",
                    source.action_count
                )
            });
        }
        for (a, image) in self.actions.iter().enumerate() {
            let Some(t) = *image else { continue };
            if t >= target.action_count {
                return Err(format!(
                    "field `{field}.actions[{a}]`: expected one of the target's actions 0 to \
                     {} or None, got Some({t})",
                    target.action_count - 1
                ));
            }
            if let Some(b) = self.actions[..a].iter().position(|&i| i == Some(t)) {
                return Err(format!(
                    "field `{field}.actions[{a}]`: target action {t} is already the image of \
                     source action {b}; each target action may stand for one source action"
                ));
            }
        }
        if self.actions.iter().all(Option::is_none) {
            return Err(format!(
                "field `{field}.actions`: expected at least one source action mapped to a \
                 target action, got none"
            ));
        }
        Ok(())
    }

    /// One line for a listing: `χ_X [2, 3, 0, 1] · χ_A [0, –, 1]`.
    pub fn summary(&self) -> String {
        let actions: Vec<String> = self
            .actions
            .iter()
            .map(|a| a.map_or("–".to_string(), |t| t.to_string()))
            .collect();
        format!("χ_X {:?} · χ_A [{}]", self.state, actions.join(", "))
    }
}

/// The spaces of a native task, known without running it; `None` for a Gymnasium task.
pub fn native_spaces(env: &EnvConfig) -> Option<Spaces> {
    if matches!(env, EnvConfig::Gymnasium(_)) {
        return None;
    }
    super::spaces(env)
        .ok()
        .map(|(observation_size, action_count)| Spaces {
            observation_size,
            action_count,
        })
}

/// Whether a source task of `source` spaces can be reused on a target of `target` spaces:
/// with equal spaces and no mapping as it is, otherwise through a mapping that fits.
/// `field` is the task's place (`sources.tasks[1]`).
pub fn check_fit(
    field: &str,
    mapping: Option<&InterTaskMapping>,
    source: Spaces,
    target: Spaces,
) -> Result<(), String> {
    match mapping {
        Some(mapping) => mapping.check(&format!("{field}.mapping"), source, target),
        None if source == target => Ok(()),
        None => Err(format!(
            "field `{field}`: its agent has {source}, the target's {target}: give its \
             `mapping: Some(state: [..], actions: [..])` (docs/FUTURE_WORK.md)"
        )),
    }
}
