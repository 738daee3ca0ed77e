//! Physical parameters of the environments, as read from a config.
//!
//! Defaults are Gymnasium's constants; a field left out of a config keeps its default.

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use super::gymnasium::{known_task, GymnasiumParams, PythonSettings};
use super::rules::Rules;

/// Which environment a config runs, with its physics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum EnvConfig {
    CartPole(CartPoleParams),
    MountainCar(MountainCarParams),
    Acrobot(AcrobotParams),
    /// Any registered Gymnasium task with `Discrete` actions and a 1-D `Box` observation,
    /// run by its Python worker ([`super::gymnasium`]).
    Gymnasium(GymnasiumParams),
}

impl EnvConfig {
    /// Short name used for the policy library's folder (`saved_policies/<task>/`): the
    /// native tasks' names, or a Gymnasium id in lower case with `_` for anything but
    /// letters and digits (`lunarlander_v3`).
    pub fn task_name(&self) -> String {
        match self {
            EnvConfig::CartPole(_) => "cartpole".into(),
            EnvConfig::MountainCar(_) => "mountain_car".into(),
            EnvConfig::Acrobot(_) => "acrobot".into(),
            EnvConfig::Gymnasium(p) => {
                p.id.chars()
                    .map(|c| {
                        if c.is_ascii_alphanumeric() {
                            c.to_ascii_lowercase()
                        } else {
                            '_'
                        }
                    })
                    .collect()
            }
        }
    }

    /// The task itself, without how this machine runs it (a Gymnasium task's `python` and
    /// `module_dir`): what a library and a results folder record, so that a folder shared
    /// between machines neither names nor depends on one's paths, and never names a program.
    pub fn as_recorded(&self) -> EnvConfig {
        match self {
            EnvConfig::Gymnasium(p) => EnvConfig::Gymnasium(p.as_recorded()),
            native => native.clone(),
        }
    }

    /// Sets how this machine runs the task from the user's own invocation (`--python`,
    /// `--module-dir`).
    pub fn run_with(&mut self, python: &PythonSettings) {
        if let EnvConfig::Gymnasium(p) = self {
            p.run_with(python);
        }
    }

    /// The Python module a Gymnasium id imports before making its task (`"my_envs:Maze-v0"`
    /// imports `my_envs`), if it names one.
    pub fn imported_module(&self) -> Option<&str> {
        match self {
            EnvConfig::Gymnasium(p) => p.imported_module(),
            _ => None,
        }
    }

    /// Checks a task read from a folder the user may have received: it may not choose code
    /// to run ([`GymnasiumParams::check_received`]). `field` is the task's path in the
    /// config, for the message.
    pub fn check_received(&self, field: &str, python: &PythonSettings) -> Result<(), String> {
        match self {
            EnvConfig::Gymnasium(p) => p.check_received(field, python),
            _ => Ok(()),
        }
    }

    /// Gymnasium's id of the task (`CartPole-v1`, `LunarLander-v3`), without starting it.
    pub fn gym_id(&self) -> String {
        match self {
            EnvConfig::CartPole(p) if p.max_episode_steps == 200 => "CartPole-v0".into(),
            EnvConfig::CartPole(_) => "CartPole-v1".into(),
            EnvConfig::MountainCar(_) => "MountainCar-v0".into(),
            EnvConfig::Acrobot(_) => "Acrobot-v1".into(),
            EnvConfig::Gymnasium(p) => p.id.clone(),
        }
    }

    /// The lowest and highest return an episode can have: each step gives +1 (CartPole) or
    /// −1 (MountainCar and Acrobot, until the goal), for at most the time limit. A
    /// Gymnasium task's is its `return_range`, else the one [`known`] for its id: a scale
    /// rather than a bound where the returns have none (LunarLander).
    pub fn return_range(&self) -> (f64, f64) {
        let steps = f64::from(self.max_episode_steps().unwrap_or(1));
        match self {
            EnvConfig::CartPole(_) => (0.0, steps),
            EnvConfig::MountainCar(_) | EnvConfig::Acrobot(_) => (-steps, 0.0),
            EnvConfig::Gymnasium(p) => p
                .return_range
                .as_deref()
                .and_then(|r| match *r {
                    [low, high] => Some((low, high)),
                    _ => None,
                })
                .or_else(|| known_task(&p.id).map(|k| k.return_range))
                .unwrap_or((0.0, 1.0)),
        }
    }

    /// The lowest and highest discounted return `Σ_{t<T} γ^t r_t` an episode can have: each
    /// step's reward lies in `return_range / T` (the rewards here are constant per step), so
    /// the bounds are those times `Σ_{t<T} γ^t = (1 − γ^T)/(1 − γ)`.
    /// A Gymnasium task, whose rewards vary from step to step, keeps its undiscounted
    /// range: PRQ-learning's W is then on about the same scale.
    pub fn discounted_return_range(&self, gamma: f64) -> (f64, f64) {
        let steps = match (self, self.max_episode_steps()) {
            (EnvConfig::Gymnasium(_), _) | (_, None) => return self.return_range(),
            (_, Some(steps)) => f64::from(steps),
        };
        let horizon = if gamma == 1.0 {
            steps
        } else {
            (1.0 - gamma.powf(steps)) / (1.0 - gamma)
        };
        let (low, high) = self.return_range();
        (low / steps * horizon, high / steps * horizon)
    }

    /// Moving averages of returns a comparison reports reaching: Gymnasium's "solved"
    /// levels (CartPole-v1 475, v0 195; MountainCar −110; Acrobot −100; LunarLander 200)
    /// and an easier one; none for a Gymnasium task sapnet does not know
    /// (`protocol.thresholds` gives them).
    pub fn return_thresholds(&self) -> Vec<f64> {
        match self {
            EnvConfig::CartPole(_) => vec![195.0, 475.0],
            EnvConfig::MountainCar(_) => vec![-150.0, -110.0],
            EnvConfig::Acrobot(_) => vec![-150.0, -100.0],
            EnvConfig::Gymnasium(p) => {
                known_task(&p.id).map_or_else(Vec::new, |k| k.thresholds.to_vec())
            }
        }
    }

    /// The task and what differs from its defaults, e.g. `cartpole` or
    /// `cartpole(force_mag=-10.0, length=1.0)` (fields in name order): tells variants of one
    /// family apart in results and SAP-Net's `SourceTask` categories.
    pub fn label(&self) -> String {
        let defaults = match self {
            EnvConfig::CartPole(_) => EnvConfig::CartPole(CartPoleParams::default()),
            EnvConfig::MountainCar(_) => EnvConfig::MountainCar(MountainCarParams::default()),
            EnvConfig::Acrobot(_) => EnvConfig::Acrobot(AcrobotParams::default()),
            // `LunarLander-v3(gravity=-8.0)`: the id, then its kwargs and attributes.
            EnvConfig::Gymnasium(p) => {
                let mut changed: Vec<String> = p
                    .kwargs
                    .iter()
                    .chain(&p.attributes)
                    .map(|(name, value)| format!("{name}={}", value_text(value)))
                    .collect();
                if let Some(steps) = p.max_episode_steps {
                    changed.push(format!("max_episode_steps={steps}"));
                }
                changed.sort();
                return if changed.is_empty() {
                    p.id.clone()
                } else {
                    format!("{}({})", p.id, changed.join(", "))
                };
            }
        };
        let fields = |env: &EnvConfig| -> serde_json::Map<String, serde_json::Value> {
            match serde_json::to_value(env) {
                Ok(serde_json::Value::Object(outer)) => outer
                    .into_iter()
                    .next()
                    .and_then(|(_, inner)| inner.as_object().cloned())
                    .unwrap_or_default(),
                _ => serde_json::Map::new(),
            }
        };
        let (mine, default) = (fields(self), fields(&defaults));
        let mut changed: Vec<String> = mine
            .iter()
            .filter(|(name, value)| default.get(*name) != Some(value))
            .map(|(name, value)| format!("{name}={}", value_text(value)))
            .collect();
        changed.sort();
        if changed.is_empty() {
            self.task_name().to_string()
        } else {
            format!("{}({})", self.task_name(), changed.join(", "))
        }
    }

    /// The time limit; a Gymnasium task's given one, else the registered one of a task
    /// sapnet knows, else unknown until the task is made.
    pub fn max_episode_steps(&self) -> Option<u32> {
        match self {
            EnvConfig::CartPole(p) => Some(p.max_episode_steps),
            EnvConfig::MountainCar(p) => Some(p.max_episode_steps),
            EnvConfig::Acrobot(p) => Some(p.max_episode_steps),
            EnvConfig::Gymnasium(p) => p
                .max_episode_steps
                .or_else(|| known_task(&p.id).map(|k| k.max_episode_steps)),
        }
    }
}

impl EnvConfig {
    /// The physics serde cannot check: each constant finite, masses, lengths, time steps
    /// and thresholds > 0, a time limit of at least one step. `field` is where the task
    /// sits in the config (`env`, `sources.env`). A negative `force_mag` is allowed: it
    /// mirrors CartPole's actions.
    pub fn validate(&self, field: &str) -> Result<(), String> {
        let task = self.task_name();
        let mut rules = Rules::new(field, &task);
        match self {
            EnvConfig::Gymnasium(p) => p.check(&mut rules),
            EnvConfig::CartPole(p) => {
                rules.time_limit(p.max_episode_steps);
                rules.finite("gravity", p.gravity);
                rules.finite("force_mag", p.force_mag);
                for (name, value) in [
                    ("masscart", p.masscart),
                    ("masspole", p.masspole),
                    ("length", p.length),
                    ("tau", p.tau),
                    ("theta_threshold_radians", p.theta_threshold_radians),
                    ("x_threshold", p.x_threshold),
                ] {
                    rules.positive(name, value);
                }
                let mut sorted = p.observation_order.clone();
                sorted.sort_unstable();
                rules.holds(
                    "observation_order",
                    sorted == CARTPOLE_ORDER,
                    &format!(
                        "each of the state's indices 0, 1, 2, 3 once, got {:?}",
                        p.observation_order
                    ),
                );
            }
            EnvConfig::MountainCar(p) => {
                rules.time_limit(p.max_episode_steps);
                for (name, value) in [
                    ("min_position", p.min_position),
                    ("max_position", p.max_position),
                    ("goal_position", p.goal_position),
                    ("goal_velocity", p.goal_velocity),
                    ("force", p.force),
                    ("gravity", p.gravity),
                ] {
                    rules.finite(name, value);
                }
                rules.positive("max_speed", p.max_speed);
                rules.holds(
                    "goal_position",
                    p.min_position < p.goal_position && p.goal_position <= p.max_position,
                    "min_position < goal_position <= max_position, or the flag cannot be \
                     reached",
                );
            }
            EnvConfig::Acrobot(p) => {
                rules.time_limit(p.max_episode_steps);
                for (name, value) in [
                    ("dt", p.dt),
                    ("link_length_1", p.link_length_1),
                    ("link_length_2", p.link_length_2),
                    ("link_mass_1", p.link_mass_1),
                    ("link_mass_2", p.link_mass_2),
                    ("link_moi", p.link_moi),
                    ("max_vel_1", p.max_vel_1),
                    ("max_vel_2", p.max_vel_2),
                ] {
                    rules.positive(name, value);
                }
                rules.finite("link_com_pos_1", p.link_com_pos_1);
                rules.finite("link_com_pos_2", p.link_com_pos_2);
                for torque in p.available_torque {
                    rules.finite("available_torque", torque);
                }
                rules.holds(
                    "torque_noise_max",
                    p.torque_noise_max >= 0.0 && p.torque_noise_max.is_finite(),
                    "a finite number >= 0",
                );
            }
        }
        rules.result()
    }
}

/// A physics constant as a label shows it: numbers in their shortest form, names bare.
fn value_text(value: &serde_json::Value) -> String {
    match value {
        serde_json::Value::Number(n) => match n.as_f64() {
            Some(x) if n.is_f64() => format!("{x:?}"),
            _ => n.to_string(),
        },
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// CartPole's integrator (Gymnasium's `kinematics_integrator`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Integrator {
    /// Position from the old velocity (Gymnasium's default `"euler"`).
    Euler,
    /// Position from the new velocity (`"semi-implicit euler"`).
    SemiImplicitEuler,
}

/// What an agent's discrete actions do to a task that pushes left or right: the agent,
/// rather than the physics, of an other agent's source policy (docs/FUTURE_WORK.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ActionSet {
    /// 0 pushes left, 1 right (CartPole's).
    LeftRight,
    /// 0 pushes left, 1 not at all, 2 right (MountainCar's).
    LeftNoneRight,
}

impl ActionSet {
    pub fn count(self) -> usize {
        match self {
            ActionSet::LeftRight => 2,
            ActionSet::LeftNoneRight => 3,
        }
    }

    /// The push of `action`: −1 left, 0 none, +1 right.
    ///
    /// # Panics
    /// If `action` is not below [`count`](Self::count): a bug in the caller.
    #[inline]
    pub fn direction(self, action: usize) -> f64 {
        match (self, action) {
            (ActionSet::LeftRight, 0) | (ActionSet::LeftNoneRight, 0) => -1.0,
            (ActionSet::LeftRight, 1) | (ActionSet::LeftNoneRight, 2) => 1.0,
            (ActionSet::LeftNoneRight, 1) => 0.0,
            _ => panic!("action {action} is not one of {self:?}'s {}", self.count()),
        }
    }
}

fn is_left_right(actions: &ActionSet) -> bool {
    *actions == ActionSet::LeftRight
}

fn is_left_none_right(actions: &ActionSet) -> bool {
    *actions == ActionSet::LeftNoneRight
}

/// CartPole's own order of its observation, `[x, x_dot, theta, theta_dot]`.
pub const CARTPOLE_ORDER: [usize; 4] = [0, 1, 2, 3];

fn is_cartpole_order(order: &Vec<usize>) -> bool {
    order.as_slice() == CARTPOLE_ORDER
}

/// CartPole (Barto, Sutton & Anderson). `max_episode_steps` 500 is v1, 200 is v0.
/// `actions` and `observation_order` change the agent, not the physics: a three-action
/// CartPole, or one whose agent sees its state variables in another order. Left at their
/// defaults they are not written, so every file of the task as Gymnasium has it reads as
/// before they existed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CartPoleParams {
    /// Time limit (sets `truncated`): 500 for CartPole-v1, 200 for CartPole-v0.
    pub max_episode_steps: u32,
    /// m/s².
    pub gravity: f64,
    /// kg.
    pub masscart: f64,
    /// kg.
    pub masspole: f64,
    /// Half the pole's length, m.
    pub length: f64,
    /// Magnitude of the push, N.
    pub force_mag: f64,
    /// Seconds between state updates.
    pub tau: f64,
    pub integrator: Integrator,
    /// Pole angle beyond which the episode terminates, rad (12°).
    pub theta_threshold_radians: f64,
    /// Cart position beyond which the episode terminates, m.
    pub x_threshold: f64,
    /// `LeftRight` (Gymnasium's) or `LeftNoneRight` (a push of 0 N as action 1).
    #[serde(skip_serializing_if = "is_left_right")]
    pub actions: ActionSet,
    /// The observation's k-th value is the state's `observation_order[k]`-th, e.g.
    /// `[2, 3, 0, 1]` puts the pole first: a permutation of 0..4.
    #[serde(skip_serializing_if = "is_cartpole_order")]
    pub observation_order: Vec<usize>,
}

impl Default for CartPoleParams {
    fn default() -> Self {
        Self {
            max_episode_steps: 500,
            gravity: 9.8,
            masscart: 1.0,
            masspole: 0.1,
            length: 0.5,
            force_mag: 10.0,
            tau: 0.02,
            integrator: Integrator::Euler,
            // Same operation order as Gymnasium: 12 * 2 * math.pi / 360.
            theta_threshold_radians: 12.0 * 2.0 * PI / 360.0,
            x_threshold: 2.4,
            actions: ActionSet::LeftRight,
            observation_order: CARTPOLE_ORDER.to_vec(),
        }
    }
}

/// MountainCar-v0 (Moore), discrete actions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MountainCarParams {
    /// Time limit (sets `truncated`): 200 for MountainCar-v0.
    pub max_episode_steps: u32,
    pub min_position: f64,
    pub max_position: f64,
    pub max_speed: f64,
    pub goal_position: f64,
    pub goal_velocity: f64,
    /// Engine force per unit of action.
    pub force: f64,
    pub gravity: f64,
    /// `LeftNoneRight` (Gymnasium's) or `LeftRight`: a two-action agent that cannot coast.
    #[serde(skip_serializing_if = "is_left_none_right")]
    pub actions: ActionSet,
}

impl Default for MountainCarParams {
    fn default() -> Self {
        Self {
            max_episode_steps: 200,
            min_position: -1.2,
            max_position: 0.6,
            max_speed: 0.07,
            goal_position: 0.5,
            goal_velocity: 0.0,
            force: 0.001,
            gravity: 0.0025,
            actions: ActionSet::LeftNoneRight,
        }
    }
}

/// Acrobot-v1 (Sutton), "book" dynamics, RK4 integration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AcrobotParams {
    /// Time limit (sets `truncated`): 500 for Acrobot-v1.
    pub max_episode_steps: u32,
    /// Seconds per step.
    pub dt: f64,
    pub link_length_1: f64,
    pub link_length_2: f64,
    pub link_mass_1: f64,
    pub link_mass_2: f64,
    /// Position of the centre of mass of link 1.
    pub link_com_pos_1: f64,
    /// Position of the centre of mass of link 2.
    pub link_com_pos_2: f64,
    /// Moment of inertia of both links.
    pub link_moi: f64,
    pub max_vel_1: f64,
    pub max_vel_2: f64,
    /// Torque applied by actions 0, 1, 2.
    pub available_torque: [f64; 3],
    /// Uniform noise added to the torque (Gymnasium's default 0: none).
    pub torque_noise_max: f64,
}

impl Default for AcrobotParams {
    fn default() -> Self {
        Self {
            max_episode_steps: 500,
            dt: 0.2,
            link_length_1: 1.0,
            link_length_2: 1.0,
            link_mass_1: 1.0,
            link_mass_2: 1.0,
            link_com_pos_1: 0.5,
            link_com_pos_2: 0.5,
            link_moi: 1.0,
            max_vel_1: 4.0 * PI,
            max_vel_2: 9.0 * PI,
            available_torque: [-1.0, 0.0, 1.0],
            torque_noise_max: 0.0,
        }
    }
}
