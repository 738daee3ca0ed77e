//! Policy reuse: which source policy acts now, and what it learns from. The seam between
//! the run loop ([`crate::trainer`]) and the ways of reusing a library.
//!
//! A [`Selector`] answers three questions, and knows nothing of candle or the environment:
//! - *who acts* at this step ([`Selector::act`]): a source ε-greedily, a source greedily
//!   (π-reuse), or a learner that is not a source;
//! - *what feedback* it takes: each update's report from the source that acted
//!   ([`Selector::on_update`]), each step's end, each episode's end and return; and, when
//!   it asks for them ([`Selector::needs`]), each acting step's reward with the source's
//!   value estimate, and the TD error in the update's report;
//! - *what to show*: a score per source and the probability of picking it
//!   ([`Selector::view`]).
//!
//! *Who learns* is fixed per method ([`Learning`]): either the source that acted learns from
//! its step (SAP-Net, the paper), or a learner of its own learns from every step while the
//! sources only guide (π-reuse in PRQ-learning; DQN from scratch is a learner that always
//! acts).
//!
//! One file per method: [`sapnet`], [`random`], [`ucb1`], [`prql`], [`best_source`],
//! [`from_scratch`], [`gpi`], [`qswitch`], [`qdagger`], [`a2t`], [`frozen_oracle`], each
//! defining its [`ReuseMethod`]. Adding one is a new file here, a variant
//! of [`Method`] and its arm in [`Method::definition`]; the compiler points at the rest.

pub mod a2t;
pub mod best_source;
mod definition;
pub mod exclusion;
pub mod from_scratch;
pub mod frozen_oracle;
pub mod gpi;
pub mod lock_in;
mod method;
pub mod parameter_schedule;
pub mod prql;
pub mod qdagger;
pub mod qswitch;
pub mod random;
pub mod sapnet;
pub mod ucb1;

use std::fmt;

use rand::rngs::StdRng;

pub use definition::{check_label, MethodKind, ReuseMethod, Tested};
pub use method::Method;

use crate::sapnet::{PolicyDescription, SapNetError, SapNetParams, TraceStep};

/// Who chooses this step's action.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Actor {
    /// Source `i`, ε-greedily (it then learns from the step, if the method lets sources learn).
    Source(usize),
    /// Source `i`'s greedy action: π-reuse's "follow the past policy".
    SourceGreedy(usize),
    /// The method's own learner, ε-greedily.
    Learner,
    /// An action chosen by the selector from every network's Q-values of the state
    /// ([`Selector::combine`]), around the learner's ε-greedy exploration: GPI's maximum
    /// over the library, the Q-switch's critic.
    Combined,
}

impl Actor {
    /// The source this actor is, if it is one.
    pub fn source(self) -> Option<usize> {
        match self {
            Self::Source(i) | Self::SourceGreedy(i) => Some(i),
            Self::Learner | Self::Combined => None,
        }
    }
}

/// What an [`Actor::Combined`] step is chosen from: every network's Q-values of the state,
/// and the learner's exploration.
#[derive(Debug, Clone, Copy)]
pub struct StateValues<'a> {
    /// `Q_L(s, ·)` of the method's own learner (its online network).
    pub learner: &'a [f32],
    /// `Q_i(s, ·)` of each source, in the library's order.
    pub sources: &'a [Vec<f32>],
    /// The random action of the learner's ε-greedy exploration, when its coin fell on
    /// exploring at this step; `None` on a greedy step (and always when testing).
    pub explored: Option<usize>,
    /// The attention's weights of the state, the sources' then the learner's, for a
    /// method with an attention network (A2T).
    pub attention: Option<&'a [f32]>,
}

/// The action of an [`Actor::Combined`] step, and whose policy it followed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Combined {
    pub action: usize,
    /// The source whose Q-value or action was followed, or `None` for the learner (and
    /// for an exploring step).
    pub followed: Option<usize>,
}

/// Who learns from the steps of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Learning {
    /// The source that acted does one round of updates on its step (Algorithm 3). The run
    /// begins with the warm-up: `N × replay_start_size` steps acted by the sources in turn.
    ActingSource,
    /// A learner of the method's own, a fresh DQN, learns from every step; sources never
    /// learn.
    Learner,
    /// Nothing learns: the sources act as recorded (a control that shows what learning
    /// adds to them, or takes away).
    Frozen,
}

/// What a method's own learner does with the step just taken ([`Learning::Learner`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LearnerRound {
    /// DQN's round: an update once the replay buffer holds `replay_start_size`
    /// transitions.
    Online,
    /// Nothing: the step only fills the replay buffer (QDagger's teacher phase).
    Wait,
    /// `updates` updates on the replay buffer as it stands, the target network copied every
    /// `target_interval` of them, then a fresh buffer for the steps to come (QDagger's
    /// offline phase, CleanRL's new buffer for the online one).
    Offline { updates: u64, target_interval: u64 },
}

/// Whose value on the target task the step just stored goes to estimate, for a method that
/// evaluates its sources ([`ReuseMethod::source_evaluation`]): GPI needs each source's
/// `Q^{π_i}` of the target task, which a network trained on its own task is not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Evaluate {
    Nobody,
    Source(usize),
    Every,
}

/// A teacher among the sources whose Q-values the learner distils (QDagger).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Distillation {
    pub teacher: usize,
    pub temperature: f64,
    /// The weight of the distillation term now, `λ_t`.
    pub weight: f64,
}

/// How an episode ended, for selectors that judge per episode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpisodeEnd {
    /// The undiscounted return.
    pub episode_return: f64,
    /// Σ_t γ^t r_t, with the DQN's γ.
    pub discounted_return: f64,
}

/// What one round of a source's learning did, as a selector judges it (eq. 7): filled by
/// the run from the learner's own report.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Feedback {
    /// The raw loss of the last gradient update of the round.
    pub loss: f64,
    /// The statistic loss `E_t` before the round.
    pub previous_statistic_loss: f64,
    /// The statistic loss `E_{t+1}` after it.
    pub statistic_loss: f64,
    /// The TD error of the step's transition before and after the round, when the selector
    /// asked for it ([`Needs::td_error`]).
    pub td: Option<TdError>,
}

/// The TD error of one transition before and after a round of updates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TdError {
    pub before: f64,
    pub after: f64,
}

/// What a selector asks the run to measure beyond what every method hears, each costing a
/// forward pass or a few: off by default, so that other methods' runs do neither.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Needs {
    /// Every [`Feedback`] carries the TD error of the step's transition before and after
    /// the round.
    pub td_error: bool,
    /// [`Selector::on_acted`] hears every acting step with the source's value estimate,
    /// and [`Selector::on_truncated`] the sources' values where a time limit cut an
    /// episode.
    pub values: bool,
}

/// One activation of a policy, with every `spread` call it made (eq. 8–11).
#[derive(Debug, Clone, PartialEq)]
pub struct Activation {
    pub policy: usize,
    pub calls: Vec<TraceStep>,
}

/// What a selector's scores are, as its own file says: the column's header, what the
/// column and P(π) mean (the Run view's `?` line), and whether the scores count steps
/// (shown as whole numbers).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScoreColumn {
    /// The column's header: `A` (SAP-Net's activation), `mean`, `W`…
    pub name: &'static str,
    pub meaning: &'static str,
    pub counted: bool,
}

impl ScoreColumn {
    /// A method with no sources to score (DQN from scratch).
    pub const NONE: Self = Self {
        name: "",
        meaning: "",
        counted: false,
    };
}

/// What a selector shows of itself: one score and one probability per source.
#[derive(Debug, Clone, PartialEq)]
pub struct SelectorView {
    pub score: ScoreColumn,
    pub scores: Vec<f64>,
    /// The probability that each source is picked at the next choice.
    pub probabilities: Vec<f64>,
    /// Judgments per source (eq. 7 for SAP-Net), for methods that judge, counted when they
    /// are made: a judgment deferred to the episode's end counts then.
    pub positive: Vec<u64>,
    pub negative: Vec<u64>,
    /// Per source, whether it is out of the candidates now ([`exclusion`]); empty for a
    /// method that excludes none.
    pub excluded: Vec<bool>,
}

impl SelectorView {
    /// The view of a selector that judges nothing and excludes no source: no judgments,
    /// one zero per source.
    pub fn unjudged(score: ScoreColumn, scores: Vec<f64>, probabilities: Vec<f64>) -> Self {
        let n = scores.len();
        Self {
            score,
            scores,
            probabilities,
            positive: vec![0; n],
            negative: vec![0; n],
            excluded: Vec::new(),
        }
    }
}

/// The change of the scores that a positive judgment made: on the judged source (eq. 8,
/// plus whatever the walk brought back to it) and on all the others together (eq. 10–11).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Deposit {
    pub own: f64,
    pub others: f64,
}

/// Which source acts and what it hears back. See the [module](self) documentation.
pub trait Selector: Send + fmt::Debug {
    /// Who learns from the run's steps.
    fn learning(&self) -> Learning;

    /// Times a category was left out of the candidates so far ([`exclusion`]).
    fn exclusions_made(&self) -> u64 {
        0
    }

    /// Who chooses the action of the next step (after the warm-up).
    fn act(&mut self, rng: &mut StdRng) -> Actor;

    /// The action of an [`Actor::Combined`] step from every network's Q-values of the
    /// state. Pure: the run also asks it for the greedy tests of a method that hands over
    /// its combination ([`Tested::Combined`]). By default the learner's own ε-greedy
    /// action: a selector that combines nothing follows its learner.
    fn combine(&self, values: &StateValues<'_>) -> Combined {
        Combined {
            action: values
                .explored
                .unwrap_or_else(|| argmax_f32(values.learner)),
            followed: None,
        }
    }

    /// What the learner does with the step just taken (after [`act`](Self::act)'s step).
    fn learner_round(&mut self) -> LearnerRound {
        LearnerRound::Online
    }

    /// Whose value estimate on the target task learns from the step just taken, for a
    /// method that evaluates its sources.
    fn evaluate(&self) -> Evaluate {
        Evaluate::Nobody
    }

    /// The teacher the learner distils, and the term's weight now; `None` for a method
    /// that distils nothing.
    fn distillation(&self) -> Option<Distillation> {
        None
    }

    /// A step was acted as [`Actor::Combined`]: `choice` made from `values`.
    fn on_combined(&mut self, _values: &StateValues<'_>, _choice: Combined) {}

    /// What the run must measure for this selector.
    fn needs(&self) -> Needs {
        Needs::default()
    }

    /// The report of the update `source` just made on its step
    /// ([`Learning::ActingSource`] only); returns the judgment it made of it, if it made
    /// one now (`None` also when the judgment waits for the episode's end).
    fn on_update(&mut self, _source: usize, _feedback: &Feedback) -> Option<bool> {
        None
    }

    /// A step (after the warm-up) that `source` acted, before its update: its reward, and
    /// `value` = `max_a Q_i(s_t, a)` of the source's online network on the observation it
    /// acted on. Called only when [`needs`](Self::needs) asks for values.
    fn on_acted(&mut self, _source: usize, _reward: f64, _value: f64) {}

    /// The episode in progress was cut by its time limit with its last state still
    /// bootstrapped (Gymnasium semantics, not `truncation_as_terminal`): `values[j]` =
    /// `max_a Q_j(s_{T+1}, a)` of every source's online network on the state it was cut
    /// at. Called before [`on_episode_end`](Self::on_episode_end), only when
    /// [`needs`](Self::needs) asks for values.
    fn on_truncated(&mut self, _values: &[f64]) {}

    /// A step (after the warm-up) is over: time-driven changes go here.
    fn on_step(&mut self) {}

    /// The episode in progress ended (episodes cut by a step budget never end).
    fn on_episode_end(&mut self, _end: &EpisodeEnd) {}

    /// Scores and probabilities for display.
    fn view(&self) -> SelectorView;

    /// What the latest positive judgment of [`on_update`](Self::on_update) deposited on
    /// the scores, for a live view; `None` for selectors that do not deposit.
    fn last_deposit(&self) -> Option<Deposit> {
        None
    }

    /// The largest probability of picking one source, where the method has probabilities:
    /// what lock-in (one source above 0.99) is measured on.
    fn top_probability(&self) -> Option<f64> {
        None
    }

    /// The source the run ends with (tested and written to the library), or `None` when
    /// the run's result is its learner: the method's [`Tested`] rule.
    fn chosen(&self) -> Option<usize>;

    /// The graph the selector spreads activation over, if it spreads (SAP-Net): for drawing
    /// and teaching.
    fn graph(&self) -> Option<&crate::sapnet::SapNet> {
        None
    }

    /// Record the activations of the next feedback for a trace.
    fn set_tracing(&mut self, _on: bool) {}

    /// Activations recorded since the last call (with tracing on).
    fn take_activations(&mut self) -> Vec<Activation> {
        Vec::new()
    }
}

/// What a selector needs to know of the library.
#[derive(Debug, Clone, Copy)]
pub struct Library<'a> {
    pub descriptions: &'a [PolicyDescription],
    /// Mean greedy return each source scored when it was trained, if tested.
    pub scores: &'a [Option<f64>],
    /// The DQN's discount γ.
    pub gamma: f64,
    /// The target task's possible returns per episode, (lowest, highest).
    pub return_range: (f64, f64),
    /// The same for discounted returns, with the DQN's γ.
    pub discounted_return_range: (f64, f64),
}

/// Why a selector could not be built.
#[derive(Debug, thiserror::Error)]
pub enum ReuseError {
    #[error(transparent)]
    SapNet(#[from] SapNetError),
    #[error("{0}")]
    Library(String),
}

/// The selector of `method` over `library`; `sapnet` is the config's SAP-Net section.
pub fn build(
    method: &Method,
    library: Library<'_>,
    sapnet: &SapNetParams,
) -> Result<Box<dyn Selector>, ReuseError> {
    method.definition().selector(library, sapnet)
}

/// Index of the largest Q-value, the lowest on a tie, as a network's greedy action is.
pub(crate) fn argmax_f32(values: &[f32]) -> usize {
    let mut best = 0;
    for (i, &v) in values.iter().enumerate() {
        if v > values[best] {
            best = i;
        }
    }
    best
}

/// Index of the largest value, the lowest on a tie.
pub(crate) fn argmax(values: &[f64]) -> usize {
    let mut best = 0;
    for (i, &v) in values.iter().enumerate() {
        if v > values[best] {
            best = i;
        }
    }
    best
}
