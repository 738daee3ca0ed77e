//! The run configuration, read from RON (`assets/*.ron`).
//!
//! Every hyper-parameter of the method lives here with a doc line, none as a literal in
//! code. Defaults are the paper's Tables I and II and `DESIGN.md`; a field left out of a
//! file keeps its default, an unknown field or a wrong type is an error that names the
//! file, the line and column, and the field's path.

use std::fmt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::dqn::Init;
use crate::env::{CartPoleParams, EnvConfig, PythonSettings};
use crate::reuse::prql::PrqlKnobs;
use crate::reuse::sapnet::SapNetKnobs;
use crate::safe_io::Links;
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

/// How ε of ε-greedy evolves over the steps of a policy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Exploration {
    /// The paper: ε constant (Table I: 0.03).
    Constant { epsilon: f64 },
    /// ε falls linearly from `start` to `end` over `steps` steps, then stays at `end`.
    Linear { start: f64, end: f64, steps: u64 },
}

/// DQN hyper-parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DqnConfig {
    /// γ, the discount rate (Table I: 0.99).
    pub gamma: f64,
    /// Adam's learning rate (ChainerRL's default 1e-3).
    pub learning_rate: f64,
    /// Adam's ε (Table I: 1e-3).
    pub adam_epsilon: f64,
    /// Adam's β₁ and β₂.
    pub adam_betas: (f64, f64),
    /// Minibatch size of one update (ChainerRL: 32).
    pub batch_size: usize,
    /// Transitions the replay buffer holds (Table I: 1e6).
    pub replay_capacity: usize,
    /// Steps stored before updates begin (Table I: 50 CartPole, 100 MountainCar).
    pub replay_start_size: usize,
    /// Environment steps between rounds of updates (ChainerRL: 1).
    pub update_interval: u64,
    /// Gradient updates per round (ChainerRL: 1).
    pub gradient_steps: u32,
    /// Steps between hard copies of the online network into the target network
    /// (ChainerRL's default 10,000; decides whether the paper's setting learns at all).
    pub target_update_interval: u64,
    /// Huber loss threshold (ChainerRL `clip_delta=True`: 1).
    pub huber_delta: f64,
    /// Clip the gradients' global norm to this value (SB3: 10; ChainerRL: none).
    pub max_grad_norm: Option<f64>,
    /// Decay of the statistic loss, the moving average the SAP-Net judgment reads
    /// (ChainerRL's `average_loss`: 0.99).
    pub loss_decay: f64,
    pub exploration: Exploration,
    /// Treat a time-limit truncation as terminal (old Gym and ChainerRL did); Gymnasium
    /// semantics (`false`) keep bootstrapping through it.
    pub truncation_as_terminal: bool,
    /// How a new Q-network is drawn: `LecunNormal` (Chainer's, the paper's) or
    /// `TorchDefault` (PyTorch's, Stable-Baselines3's).
    pub init: Init,
}

impl Default for DqnConfig {
    fn default() -> Self {
        Self {
            gamma: 0.99,
            learning_rate: 1e-3,
            adam_epsilon: 1e-3,
            adam_betas: (0.9, 0.999),
            batch_size: 32,
            replay_capacity: 1_000_000,
            replay_start_size: 50,
            update_interval: 1,
            gradient_steps: 1,
            target_update_interval: 10_000,
            huber_delta: 1.0,
            max_grad_norm: None,
            loss_decay: 0.99,
            exploration: Exploration::Constant { epsilon: 0.03 },
            truncation_as_terminal: false,
            init: Init::LecunNormal,
        }
    }
}

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
    /// is reused: χ_X and χ_A (`crate::sources::mapping`, docs/FUTURE_WORK.md).
    #[serde(default)]
    pub mapping: Option<crate::sources::InterTaskMapping>,
}

/// A learner an experiment compares (`protocol.methods`). Each reusing method's selector is
/// a file of [`crate::reuse`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Method {
    /// Transfer learning with SAP-Net over the source library (Algorithm 3), as the paper
    /// specifies it.
    SapNet,
    /// SAP-Net with knobs beyond the paper: a temperature schedule, another judgment
    /// (`Episode`, `KSteps(k)`, `TdChange`, `Advantage`, `EpisodeAndLoss`: docs/REUSE.md,
    /// docs/FUTURE_WORK.md), activation decay (`SapNetWith(judgment: Episode)`; every knob
    /// left out is the paper's).
    SapNetWith(SapNetKnobs),
    /// A uniformly random source acts (and fine-tunes) at every step.
    Random,
    /// A uniformly random source acts (and fine-tunes) for a whole episode.
    RandomPerEpisode,
    /// UCB1 over the sources, one pull per episode, on the return scaled to [0, 1].
    Ucb1,
    /// PRQ-learning: a new learner, guided by sources through π-reuse
    /// (`Prql()` for the paper's defaults).
    Prql(PrqlKnobs),
    /// Fine-tune the library's best source by its recorded score: the selection oracle.
    BestSource,
    /// DQN from scratch with these hidden layers (the paper's baselines: `[100]`,
    /// `[100, 100]`, `[100, 100, 100]`).
    Dqn { hidden: Vec<usize> },
}

/// What kind of learner a method is, without its knobs: what front ends and results branch
/// on, where they must.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum MethodKind {
    SapNet,
    Random,
    RandomPerEpisode,
    Ucb1,
    Prql,
    BestSource,
    Dqn,
}

impl MethodKind {
    /// Whether the method draws on the source library.
    pub fn reuses(self) -> bool {
        self != Self::Dqn
    }

    /// Whether the method picks sources with probabilities, so that lock-in (one source
    /// above 0.99) is measured; UCB1 and a random source per episode pick by rule.
    pub fn picks_by_probability(self) -> bool {
        matches!(
            self,
            Self::SapNet | Self::Random | Self::Prql | Self::BestSource
        )
    }

    /// What the method hands over to be tested greedily and written as the run's result:
    /// one rule per method, fixed before the run, as `comparison.csv`'s `tested` column
    /// names it.
    pub fn tested(self) -> Tested {
        match self {
            Self::SapNet => Tested::HighestActivation,
            Self::Random | Self::RandomPerEpisode => Tested::DrawnAtStart,
            Self::Ucb1 => Tested::MostPlayed,
            Self::BestSource => Tested::BestRecorded,
            Self::Prql | Self::Dqn => Tested::Learner,
        }
    }
}

/// What a method's run hands over for its greedy tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tested {
    /// The source with the highest activation when the run ends (Algorithm 3).
    HighestActivation,
    /// A source drawn uniformly when the run starts, whatever the run then does: a random
    /// selector has no preference to hand over. (Handing over the source that acted most
    /// would select by return: the longest episodes are the best source's.)
    DrawnAtStart,
    /// The source played in most episodes: a bandit's recommendation.
    MostPlayed,
    /// The source with the best recorded score: the oracle's pick, made before training.
    BestRecorded,
    /// The method's own learner, not a source.
    Learner,
}

impl Tested {
    /// The rule's name in `comparison.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Self::HighestActivation => "highest-activation",
            Self::DrawnAtStart => "drawn-at-start",
            Self::MostPlayed => "most-played",
            Self::BestRecorded => "best-recorded",
            Self::Learner => "learner",
        }
    }
}

impl Method {
    pub fn kind(&self) -> MethodKind {
        match self {
            Self::SapNet | Self::SapNetWith(_) => MethodKind::SapNet,
            Self::Random => MethodKind::Random,
            Self::RandomPerEpisode => MethodKind::RandomPerEpisode,
            Self::Ucb1 => MethodKind::Ucb1,
            Self::Prql(_) => MethodKind::Prql,
            Self::BestSource => MethodKind::BestSource,
            Self::Dqn { .. } => MethodKind::Dqn,
        }
    }

    /// The method's name in results: `sapnet`, `ucb1`, `dqn[100,100]`…
    pub fn label(&self) -> String {
        match self {
            Self::SapNet => "sapnet".into(),
            Self::SapNetWith(knobs) => knobs.label(),
            Self::Random => "random".into(),
            Self::RandomPerEpisode => "random-episode".into(),
            Self::Ucb1 => "ucb1".into(),
            Self::Prql(knobs) => knobs.label(),
            Self::BestSource => "best-source".into(),
            Self::Dqn { hidden } => {
                let layers: Vec<String> = hidden.iter().map(ToString::to_string).collect();
                format!("dqn[{}]", layers.join(","))
            }
        }
    }

    /// The hidden layers of the method's own learner, if it has one.
    pub fn learner_hidden(&self) -> Option<&[usize]> {
        match self {
            Self::Dqn { hidden } => Some(hidden),
            Self::Prql(knobs) => Some(&knobs.hidden),
            _ => None,
        }
    }
}

pub use crate::limits::{
    MAX_BATCH, MAX_EPISODES, MAX_GRADIENT_STEPS, MAX_HIDDEN_LAYERS, MAX_RUNS, MAX_SOURCES,
    MAX_STEPS, MAX_TEST_EPISODES,
};

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

/// A config that could not be read: where, and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    // The OS error is part of the message, not a `source`: a chain prints it once.
    #[error("reading {}: {cause}", path.display())]
    Io {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error(
        "{} is larger than {} bytes: not a config, lesson or policy file (those are a few \
         kilobytes of RON text)",
        path.display(),
        MAX_TEXT_BYTES
    )]
    TooLarge { path: PathBuf },
    #[error("{} is not UTF-8 text", path.display())]
    NotText { path: PathBuf },
    #[error("{0}")]
    Parse(Box<ParseError>),
    #[error("config {}: {message}", origin)]
    Invalid { origin: String, message: String },
}

/// The largest RON file read (configs, teach lessons, policy metadata, manifests): 16 MiB,
/// room for a lesson listing every edge of a 1,000-policy graph, so that `--config
/// /dev/zero` is an error, not a machine out of memory.
pub const MAX_TEXT_BYTES: u64 = 16 << 20;

/// Reads the RON text at `path`, a file the user named (a link is followed), refusing
/// more than [`MAX_TEXT_BYTES`] and anything but a regular file (a FIFO would block).
pub fn read_text(path: &Path) -> Result<String, ConfigError> {
    read_text_with(path, Links::Follow)
}

/// [`read_text`] of a file inside a folder that may have come from elsewhere (a library's
/// manifest and metadata, a sweep's cells): a symbolic link there is refused.
pub fn read_folder_text(path: &Path) -> Result<String, ConfigError> {
    read_text_with(path, Links::Refuse)
}

fn read_text_with(path: &Path, links: Links) -> Result<String, ConfigError> {
    use std::io::Read;
    let io = |cause| ConfigError::Io {
        path: path.to_path_buf(),
        cause,
    };
    let file = crate::safe_io::open(path, links, u64::MAX).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_TEXT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_TEXT_BYTES {
        return Err(ConfigError::TooLarge {
            path: path.to_path_buf(),
        });
    }
    String::from_utf8(bytes).map_err(|_| ConfigError::NotText {
        path: path.to_path_buf(),
    })
}

/// A located syntax or type error in a RON file.
#[derive(Debug)]
pub struct ParseError {
    /// What the file is, as messages name it: `config`, `policy metadata`, ….
    pub kind: &'static str,
    /// The file name, or a label for text that did not come from a file.
    pub origin: String,
    pub line: usize,
    pub column: usize,
    /// Dotted path of the field being read, e.g. `dqn.gamma` (empty at the top level).
    pub field: String,
    pub message: String,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} {}: line {}, column {}",
            self.kind, self.origin, self.line, self.column
        )?;
        if !self.field.is_empty() && self.field != "." {
            write!(f, ", field `{}`", self.field)?;
        }
        write!(f, ": {}", self.message)
    }
}

/// The RON options every file of this project is read with: a newtype variant's struct may
/// drop its extra parentheses (`CartPole(gravity: 9.8)` rather than `CartPole((…))`).
pub fn ron_options() -> ron::Options {
    ron::Options::default()
        .with_default_extension(ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES)
}

/// Reads a config, lesson or grid from RON, with located errors. `origin` names the text
/// in messages.
pub fn parse_ron<T: serde::de::DeserializeOwned>(
    text: &str,
    origin: &str,
) -> Result<T, ConfigError> {
    parse_ron_as(text, origin, "config")
}

/// Reads any RON document, with located errors naming it as `kind` (`policy metadata`,
/// `library manifest`, …) and `origin`.
pub fn parse_ron_as<T: serde::de::DeserializeOwned>(
    text: &str,
    origin: &str,
    kind: &'static str,
) -> Result<T, ConfigError> {
    let options = ron_options();
    let mut de = ron::Deserializer::from_str_with_options(text, &options).map_err(|e| {
        ConfigError::Parse(Box::new(ParseError {
            kind,
            origin: origin.to_string(),
            line: e.span.start.line,
            column: e.span.start.col,
            field: String::new(),
            message: e.code.to_string(),
        }))
    })?;
    let located = |de: &ron::Deserializer, field: String, code: ron::Error| {
        let spanned = de.span_error(code);
        let (line, column) = (spanned.span.start.line, spanned.span.start.col);
        let (field, message) = explained(text, line, column, field, spanned.code.to_string());
        ConfigError::Parse(Box::new(ParseError {
            kind,
            origin: origin.to_string(),
            line,
            column,
            field,
            message,
        }))
    };
    let value = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        // A syntax error between fields ends the path in `?` (no field was being read):
        // name the innermost field that was, and let the line and column say the rest.
        let path = e.path().to_string();
        let field = path.trim_end_matches(['?', '.']).to_string();
        located(&de, field, e.into_inner())
    })?;
    de.end().map_err(|e| located(&de, String::new(), e))?;
    Ok(value)
}

/// RON's wording for two number mistakes, said as the field sees them: a fraction where a
/// whole number belongs reads to RON as a number followed by something other than a comma
/// (`episodes: 5.5` → "Expected comma", at the struct around it), and a negative count as
/// "Integer is out of bounds" without the bound.
fn explained(
    text: &str,
    line: usize,
    column: usize,
    field: String,
    message: String,
) -> (String, String) {
    let Some(row) = text.lines().nth(line.saturating_sub(1)) else {
        return (field, message);
    };
    let chars: Vec<char> = row.chars().collect();
    let at = column.saturating_sub(1).min(chars.len());
    // The token around the error: back to `:`, forward to `,` or `)`.
    let start = chars[..at]
        .iter()
        .rposition(|c| *c == ':' || *c == '(' || *c == ',')
        .map_or(0, |i| i + 1);
    let end = chars[at..]
        .iter()
        .position(|c| *c == ',' || *c == ')')
        .map_or(chars.len(), |i| at + i);
    let token: String = chars[start..end]
        .iter()
        .collect::<String>()
        .trim()
        .to_string();
    let name: String = chars[..start.saturating_sub(1)]
        .iter()
        .rev()
        .skip_while(|c| c.is_whitespace())
        .take_while(|c| c.is_alphanumeric() || **c == '_')
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    let is_fraction = message == "Expected comma"
        && chars.get(at) == Some(&'.')
        && token.parse::<f64>().is_ok()
        && !name.is_empty();
    if is_fraction {
        let field = if field.is_empty() {
            name
        } else {
            format!("{field}.{name}")
        };
        return (field, format!("expected a whole number, got {token}"));
    }
    if message == "Integer is out of bounds" {
        let why = if token.starts_with('-') {
            format!("expected a whole number ≥ 0, got {token}")
        } else {
            format!("{token} is too large a whole number for this field")
        };
        return (field, why);
    }
    (field, message)
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
        let config: Config = parse_ron(text, origin).map_err(|e| {
            // A lesson given where a training config is expected: say what each reads.
            if parse_ron::<crate::teach::config::TeachConfig>(text, origin).is_ok() {
                ConfigError::Invalid {
                    origin: origin.to_string(),
                    message: "this is a lesson, for `sapnet teach --config`; runs, `env` and \
                              `sources` read a training config (e.g. assets/cartpole.ron, \
                              assets/mountain_car.ron)"
                        .to_string(),
                }
            } else {
                e
            }
        })?;
        config.validate().map_err(|message| ConfigError::Invalid {
            origin: origin.to_string(),
            message,
        })?;
        Ok(config)
    }

    /// `sources.tasks` and `sources.name`: tasks that make sense, as many policies as
    /// `count`, a plain folder name.
    fn check_source_tasks(&self) -> Result<(), String> {
        let s = &self.sources;
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
            if let (Some(source), Some(target)) = (
                crate::sources::native_spaces(&task.env),
                crate::sources::native_spaces(&self.env),
            ) {
                crate::sources::check_fit(
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

    /// Cuts the protocol for a smoke run: 1/20 of the episodes, at most 2 runs per method.
    /// The source library is the real one (a library trained on a cut budget would be
    /// reused by later full runs).
    pub fn quick(&mut self) {
        self.protocol.episodes = (self.protocol.episodes / 20).max(1);
        self.protocol.max_steps = self.protocol.max_steps.map(|s| (s / 20).max(1));
        self.protocol.runs = self.protocol.runs.min(2);
    }

    /// Checks the values serde cannot: ranges and relations between fields.
    pub fn validate(&self) -> Result<(), String> {
        self.env.validate("env")?;
        if let Some(env) = &self.sources.env {
            env.validate("sources.env")?;
        }
        self.check_source_tasks()?;
        check_dqn(&self.dqn, "dqn")?;
        if let Some(sources) = &self.sources.dqn {
            check_dqn(sources, "sources.dqn")?;
        }
        // 𝒜 > 0 among them: SAP-Net's own parameters refuse what the net cannot run on.
        self.sapnet.validate().map_err(|e| {
            sapnet_field(&e, "sapnet.").unwrap_or_else(|| format!("section `sapnet`: {e}"))
        })?;
        let src = &self.sources;
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
        )?;
        let p = &self.protocol;
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
        check(
            src.training_episodes <= MAX_EPISODES,
            "sources.training_episodes",
            &format!("at most {MAX_EPISODES}"),
            src.training_episodes,
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
            if let Some(hidden) = method.learner_hidden() {
                check(
                    hidden.len() <= MAX_HIDDEN_LAYERS,
                    &format!("{field}.hidden"),
                    &format!("at most {MAX_HIDDEN_LAYERS} hidden layers"),
                    format!("{} layers", hidden.len()),
                )?;
            }
            match method {
                Method::Dqn { hidden } => check(
                    !hidden.is_empty() && hidden.iter().all(|&u| u > 0),
                    &format!("{field}.hidden"),
                    "a non-empty list of layer sizes > 0",
                    format!("{hidden:?}"),
                )?,
                Method::SapNetWith(knobs) => knobs.validate(&field)?,
                Method::Prql(knobs) => knobs.validate(&field)?,
                _ => {}
            }
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

fn check(ok: bool, field: &str, expected: &str, got: impl Shown) -> Result<(), String> {
    if ok {
        Ok(())
    } else {
        Err(format!(
            "field `{field}`: expected {expected}, got {}",
            got.shown()
        ))
    }
}

/// A value as an error message shows it: numbers in their shortest form (`1e308`, not 309
/// digits).
/// A bad SAP-Net parameter worded as every field of a config is (`field `sapnet.delta`:
/// expected …, got …`), `prefix` naming where the parameters sit; `None` for other errors.
pub fn sapnet_field(error: &crate::sapnet::SapNetError, prefix: &str) -> Option<String> {
    match error {
        crate::sapnet::SapNetError::BadParameter {
            name,
            value,
            expected,
        } => Some(format!(
            "field `{prefix}{name}`: expected {expected}, got {}",
            value.shown()
        )),
        _ => None,
    }
}

pub trait Shown {
    fn shown(&self) -> String;
}

impl Shown for f64 {
    fn shown(&self) -> String {
        format!("{self:?}")
    }
}

macro_rules! shown_as_displayed {
    ($($t:ty),*) => {$(
        impl Shown for $t {
            fn shown(&self) -> String {
                self.to_string()
            }
        }
    )*};
}
shown_as_displayed!(u32, u64, usize, i64, String, &str);

/// The ranges of a DQN config found at `prefix` (`dqn`, `sources.dqn`).
fn check_dqn(d: &DqnConfig, prefix: &str) -> Result<(), String> {
    check(
        d.gamma >= 0.0 && d.gamma <= 1.0,
        &format!("{prefix}.gamma"),
        "a number in [0, 1]",
        d.gamma,
    )?;
    let positive = |x: f64| x > 0.0 && x.is_finite();
    check(
        positive(d.learning_rate),
        &format!("{prefix}.learning_rate"),
        "a finite number > 0",
        d.learning_rate,
    )?;
    check(
        positive(d.adam_epsilon),
        &format!("{prefix}.adam_epsilon"),
        "a finite number > 0",
        d.adam_epsilon,
    )?;
    let (beta1, beta2) = d.adam_betas;
    check(
        (0.0..1.0).contains(&beta1) && (0.0..1.0).contains(&beta2),
        &format!("{prefix}.adam_betas"),
        "(β₁, β₂) with each in [0, 1)",
        format!("({beta1}, {beta2})"),
    )?;
    check(
        d.batch_size > 0,
        &format!("{prefix}.batch_size"),
        "at least 1",
        d.batch_size,
    )?;
    check(
        d.replay_capacity >= d.batch_size,
        &format!("{prefix}.replay_capacity"),
        "at least dqn.batch_size",
        d.replay_capacity,
    )?;
    check(
        d.update_interval > 0,
        &format!("{prefix}.update_interval"),
        "at least 1",
        d.update_interval,
    )?;
    check(
        (1..=MAX_GRADIENT_STEPS).contains(&d.gradient_steps),
        &format!("{prefix}.gradient_steps"),
        &format!("1 to {MAX_GRADIENT_STEPS} updates per round (0 never learns)"),
        d.gradient_steps,
    )?;
    check(
        d.batch_size <= MAX_BATCH,
        &format!("{prefix}.batch_size"),
        &format!("at most {MAX_BATCH}"),
        d.batch_size,
    )?;
    check(
        d.replay_start_size <= d.replay_capacity,
        &format!("{prefix}.replay_start_size"),
        &format!(
            "at most {prefix}.replay_capacity ({}): a buffer that never holds that many \
             never starts learning",
            d.replay_capacity
        ),
        d.replay_start_size,
    )?;
    check(
        d.target_update_interval > 0,
        &format!("{prefix}.target_update_interval"),
        "at least 1",
        d.target_update_interval,
    )?;
    check(
        positive(d.huber_delta),
        &format!("{prefix}.huber_delta"),
        "a number > 0",
        d.huber_delta,
    )?;
    check(
        d.loss_decay >= 0.0 && d.loss_decay < 1.0,
        &format!("{prefix}.loss_decay"),
        "a number in [0, 1)",
        d.loss_decay,
    )?;
    if let Some(norm) = d.max_grad_norm {
        check(
            norm > 0.0,
            &format!("{prefix}.max_grad_norm"),
            "a number > 0",
            norm,
        )?;
    }
    check_exploration(&d.exploration, &format!("{prefix}.exploration"))
}

/// ε values are probabilities; `field` is where the schedule sits in the config.
fn check_exploration(exploration: &Exploration, field: &str) -> Result<(), String> {
    let probability = |value: f64, name: &str| {
        check(
            (0.0..=1.0).contains(&value),
            &format!("{field}.{name}"),
            "a number in [0, 1]",
            value,
        )
    };
    match *exploration {
        Exploration::Constant { epsilon } => probability(epsilon, "epsilon"),
        Exploration::Linear { start, end, .. } => {
            probability(start, "start").and_then(|()| probability(end, "end"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn a_lesson_given_as_a_training_config_is_named_as_such() {
        let lesson = include_str!("../assets/teach_fig2.ron");
        let err = Config::from_ron(lesson, "fig2.ron")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("fig2.ron: this is a lesson, for `sapnet teach --config`"),
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
        assert_eq!(c.protocol.episodes, 5000);
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
