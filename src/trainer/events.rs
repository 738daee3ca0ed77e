//! The contract between the trainer and the front ends: the trainer only *sends* [`Event`]s,
//! front ends only render them and send [`Command`]s.
//!
//! A run sends, in order: `RunStarted`, then for every step a `Step` (only if its
//! [`StreamOptions::steps`] is on) and for every positive activation a `Trace` (only while
//! tracing is on), an `Activations` snapshot at most every
//! [`StreamOptions::snapshot_interval`] (every step while paused or throttled, and always
//! just before each `EpisodeEnded` of a run that reuses the library), then `EpisodeEnded` per episode and
//! `RunEnded` last.

use std::fmt;
use std::sync::Arc;
use std::time::Duration;

use std::borrow::Cow;

use serde::{Deserialize, Serialize, Serializer};

use crate::dqn::UpdateReport;
pub use crate::reuse::Deposit;
use crate::reuse::{Method, MethodKind, ScoreColumn};
use crate::sapnet::{PolicyDescription, SapNet, TraceStep};

/// Which learner a run trains: its place in `protocol.methods`, its kind and its label in
/// results (`sapnet`, `ucb1`, `dqn[100,100]`). Written as its label; ordered as the
/// protocol lists the methods.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MethodId {
    pub index: usize,
    pub kind: MethodKind,
    pub label: Arc<str>,
}

impl MethodId {
    /// The id of `method`, listed at `index` in the protocol.
    pub fn new(index: usize, method: &Method) -> Self {
        Self {
            index,
            kind: method.kind(),
            label: method.label().into(),
        }
    }

    pub fn label(&self) -> &str {
        &self.label
    }

    /// The ids of a protocol's `methods`, in their order.
    pub fn all(methods: &[Method]) -> Vec<MethodId> {
        methods
            .iter()
            .enumerate()
            .map(|(i, method)| MethodId::new(i, method))
            .collect()
    }
}

impl fmt::Display for MethodId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.label)
    }
}

impl Serialize for MethodId {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.label)
    }
}

/// One finished training episode: a row of `episodes.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpisodeRecord {
    /// Index of the independent run (0-based).
    pub run: u32,
    pub method: MethodId,
    /// 1-based, as the paper counts.
    pub episode: u32,
    pub reward: f64,
    pub steps: u32,
    /// Raw loss of the latest update at the end of the episode (empty before learning
    /// starts; with `update_interval` > 1 it may come from an earlier episode). For SAP-Net,
    /// the loss of the policy that acted last.
    pub loss: Option<f64>,
    /// The statistic loss E at the end of the episode (SAP-Net: of the policy that acted
    /// last).
    pub statistic_loss: f64,
    /// ε at the end of the episode.
    pub epsilon: f64,
    /// SAP-Net: the policy that acted most often in this episode (empty for DQN).
    pub policy: Option<u32>,
    /// Seconds since the run started.
    pub wall_s: f64,
}

/// The episode in progress when a step budget ran out, truncated there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CutEpisode {
    pub steps: u32,
    pub reward: f64,
}

/// The source a reusing run ends with: for SAP-Net the highest activation (Algorithm 3),
/// for the other selectors what [`crate::reuse::Selector::chosen`] says.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChosenPolicy {
    pub index: usize,
    /// Its name in the source library, e.g. `source-3`.
    pub name: String,
    pub hidden: Vec<usize>,
    /// Its score under the selector when the run ended (SAP-Net: its activation A).
    pub score: f64,
    /// What the score is (`A`, `mean`, `score`…).
    pub score_name: Cow<'static, str>,
}

/// How a run ended. `M` is how the method is known: a [`MethodId`] in a process, its label
/// when read back from a results directory (see [`RunRecord::with_method`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRecord<M = MethodId> {
    pub run: u32,
    pub method: M,
    /// The seed of this run's random streams, derived from the config's run seed, the
    /// method's label and the run's index ([`crate::seeds::run_seed`]).
    pub seed: u64,
    /// Training episodes completed (a step budget cuts a last, partial episode, which is
    /// not counted: `cut_episode` keeps it, `steps` counts its steps).
    pub episodes: u32,
    /// Environment steps of training (the greedy tests' not counted).
    pub steps: u64,
    /// Gradient updates of every network the method trains (each source's copy, its
    /// learner, an attention, a value estimate), so that `updates / steps` says how much
    /// computation per transition a method was given.
    pub updates: u64,
    /// The episode a step budget truncated, if it cut one mid-way: its steps and its
    /// return so far. Not one of `episodes`: a partial return is not a score.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cut_episode: Option<CutEpisode>,
    /// For a method with a learner of its own: the steps whose action was not that
    /// learner's greedy action at the state (its exploration, and whatever the library
    /// changed of its behaviour).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub non_greedy_steps: Option<u64>,
    /// The chosen source, whose greedy returns `test_returns` are (`None` when the run's
    /// result is a learner of its own: DQN, PRQ-learning).
    pub chosen: Option<ChosenPolicy>,
    /// Steps each source acted after the warm-up (empty without a library).
    pub source_steps: Vec<u64>,
    /// The first step at which one source's probability of being picked exceeded 0.99
    /// (lock-in), for selectors with probabilities.
    pub lock_in_step: Option<u64>,
    /// Positive and negative judgments of each source over the run (SAP-Net's eq. 7 or
    /// its `judgment` knob; a judgment deferred to an episode's end counts if the episode
    /// ended). Zeros for a method that does not judge, empty without a library (and in
    /// results written before the field existed).
    #[serde(default)]
    pub positive: Vec<u64>,
    #[serde(default)]
    pub negative: Vec<u64>,
    /// Times a category was left out of the candidates (`SapNetWith(exclusion: …)`); 0 for
    /// a method without the knob, and in results written before the field existed.
    #[serde(default)]
    pub exclusions: u64,
    /// Returns of the greedy test episodes after training (empty if stopped before).
    pub test_returns: Vec<f64>,
    /// Stopped by the user before the planned episodes were done.
    pub stopped: bool,
    pub wall_s: f64,
}

impl<M> RunRecord<M> {
    /// The record of a run that has done nothing yet: the one place a record is made, so
    /// that a field added to it gets its starting value here and nowhere else.
    pub fn new(run: u32, method: M, seed: u64) -> Self {
        RunRecord {
            run,
            method,
            seed,
            episodes: 0,
            steps: 0,
            updates: 0,
            cut_episode: None,
            non_greedy_steps: None,
            chosen: None,
            source_steps: Vec::new(),
            lock_in_step: None,
            positive: Vec::new(),
            negative: Vec::new(),
            exclusions: 0,
            test_returns: Vec::new(),
            stopped: false,
            wall_s: 0.0,
        }
    }
}

impl RunRecord<String> {
    /// The record read back from disk, its method known again by its id in the protocol.
    pub fn with_method(self, method: MethodId) -> RunRecord<MethodId> {
        // Every field named: one added to the record and not carried over does not compile.
        let Self {
            run,
            method: _,
            seed,
            episodes,
            steps,
            updates,
            cut_episode,
            non_greedy_steps,
            chosen,
            source_steps,
            lock_in_step,
            positive,
            negative,
            exclusions,
            test_returns,
            stopped,
            wall_s,
        } = self;
        let mut record = RunRecord::new(run, method, seed);
        record.episodes = episodes;
        record.steps = steps;
        record.updates = updates;
        record.cut_episode = cut_episode;
        record.non_greedy_steps = non_greedy_steps;
        record.chosen = chosen;
        record.source_steps = source_steps;
        record.lock_in_step = lock_in_step;
        record.positive = positive;
        record.negative = negative;
        record.exclusions = exclusions;
        record.test_returns = test_returns;
        record.stopped = stopped;
        record.wall_s = wall_s;
        record
    }
}

/// A source policy as front ends show it.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceSummary {
    /// Its name in the library, e.g. `source-3`.
    pub name: String,
    pub description: PolicyDescription,
    /// Mean greedy return when it was trained, if it was tested.
    pub final_score: Option<f64>,
}

/// What a reusing run starts from: its policies and the SAP-Net over them (graph, weights
/// M, parameters and the initial activations), enough to draw the graph or teach on it.
/// For a selector that is not SAP-Net the graph is the library's under the config's
/// `sapnet` section, drawn with the selector's own scores.
#[derive(Debug, Clone, PartialEq)]
pub struct LibraryStart {
    pub policies: Vec<SourceSummary>,
    pub net: SapNet,
    /// What the selector's scores are: `A` for SAP-Net's activations, else its own.
    pub score: ScoreColumn,
}

/// One environment step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRecord {
    /// The run's method, by its index in the protocol ([`MethodId::index`]), and the run.
    pub method: usize,
    pub run: u32,
    /// Steps of the run so far, this one included.
    pub step: u64,
    /// The episode this step belongs to (1-based).
    pub episode: u32,
    /// The source that acted (`None`: the method's own learner).
    pub policy: Option<usize>,
    pub action: usize,
    pub reward: f64,
    /// The update this step made, if it made one: its loss and the learner's statistic
    /// loss before and after (`T_a = E_{t+1} − E_t`, eq. 7).
    pub update: Option<UpdateReport>,
    /// The selector's judgment of the step, if it judged one (SAP-Net: positive activated
    /// the policy and spread).
    pub judgment: Option<bool>,
    /// What a positive judgment deposited on the scores (SAP-Net: eq. 8–11).
    pub deposit: Option<Deposit>,
    /// One of the first `N × replay_start_size` steps, acted in turn without learning.
    pub warm_up: bool,
}

/// The state of a run's selector at a step.
#[derive(Debug, Clone, PartialEq)]
pub struct ActivationSnapshot {
    pub run: u32,
    pub method: MethodId,
    pub step: u64,
    pub episode: u32,
    /// What the scores are: `A` for SAP-Net's activations 𝔸, or the selector's own.
    pub score: ScoreColumn,
    /// The selector's score of each source (SAP-Net: 𝔸).
    pub activations: Vec<f64>,
    /// The probability of picking each source next (SAP-Net: P(π_i), eq. 6).
    pub probabilities: Vec<f64>,
    /// Steps each policy acted after the warm-up, since the run started.
    pub selections: Vec<u64>,
    /// Positive and negative transitions of each policy (eq. 7), since the run started.
    pub positive: Vec<u64>,
    pub negative: Vec<u64>,
    /// The run's lock-in so far, as its record will give it (`lock_in_step`): the first
    /// step at which one source's probability exceeded [`super::LOCK_IN`], and which. A
    /// screen shows this figure, not the step of the first frame that noticed it.
    pub lock_in: Option<LockIn>,
    /// Per source, whether it is out of eq. 6's candidates now (its category excluded,
    /// `SapNetWith(exclusion: …)`); empty when the method excludes none.
    pub excluded: Vec<bool>,
}

/// The first step at which `source`'s probability of being picked exceeded
/// [`super::LOCK_IN`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LockIn {
    pub source: usize,
    pub step: u64,
}

/// Every `spread` call of one activation (eq. 8–11), in the order they were made.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceRecord {
    pub run: u32,
    pub method: MethodId,
    pub step: u64,
    /// The activated policy.
    pub policy: usize,
    pub calls: Vec<TraceStep>,
}

/// What the trainer tells the front ends.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    RunStarted {
        run: u32,
        method: MethodId,
        /// Episodes or environment steps the run is given.
        budget: crate::trainer::Budget,
        /// Present for runs that reuse the library.
        library: Option<Box<LibraryStart>>,
    },
    Step(StepRecord),
    Activations(ActivationSnapshot),
    Trace(TraceRecord),
    EpisodeEnded(EpisodeRecord),
    RunEnded(RunRecord),
    /// The run could not go on (a diverged loss, a network that would not build): sent
    /// instead of `RunEnded` by a run on its own thread ([`super::spawn`]), so that a
    /// front end can say so at once; the thread's result carries the error itself.
    RunFailed {
        run: u32,
        method: MethodId,
        error: String,
    },
}

/// What a front end can ask of the trainer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// Finish the current step, then end the run as stopped.
    Stop,
    /// Wait before the next step until `Resume`, `Step` or `Stop`.
    Pause,
    Resume,
    /// While paused: take one step, then wait again.
    Step,
    /// Sleep this long before every step (zero: full speed). Slows the trainer so that a
    /// person can follow it; the front end never slows it otherwise.
    Throttle(Duration),
    /// Send a `Trace` of every positive activation (SAP-Net runs).
    Trace(bool),
    /// Stream as a run followed live ([`StreamOptions::live`]: every step, snapshots about
    /// 30 a second), or only what results need ([`StreamOptions::episodes`]): a front end
    /// that follows another run moves the stream to it.
    Stream(bool),
}

/// What a run streams besides episodes, chosen by the front end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamOptions {
    /// Send a `Step` for every step.
    pub steps: bool,
    /// Start with tracing on (see [`Command::Trace`]).
    pub trace: bool,
    /// Least time between two `Activations` snapshots while running at full speed.
    pub snapshot_interval: Duration,
}

impl StreamOptions {
    /// Episodes and per-episode snapshots only: what results on disk need.
    pub fn episodes() -> Self {
        Self {
            steps: false,
            trace: false,
            snapshot_interval: Duration::MAX,
        }
    }

    /// Steps and about 30 snapshots a second: what a live view needs.
    pub fn live() -> Self {
        Self {
            steps: true,
            trace: false,
            snapshot_interval: Duration::from_millis(33),
        }
    }
}

impl Default for StreamOptions {
    fn default() -> Self {
        Self::episodes()
    }
}
