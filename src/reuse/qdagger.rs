//! QDagger (Agarwal et al., "Reincarnating Reinforcement Learning: Reusing Prior
//! Computation to Accelerate Progress", NeurIPS 2022), as CleanRL's `qdagger_dqn_*` runs it,
//! with a source of the library as the teacher.
//!
//! A student, a fresh DQN of the method's own, learns from a teacher in four phases:
//! 0. **teacher evaluation**: the teacher plays `teacher_eval_episodes` episodes (10) of
//!    the target task at ε = 0.01 (CleanRL's `end_e`): R̄_teacher is their mean return;
//! 1. **teacher data**: the teacher acts for `teacher_steps` steps, ε-greedily with ε
//!    decaying linearly from 1.0 to 0.01 over the phase (CleanRL's `linear_schedule`),
//!    and its transitions fill the replay buffer; the student waits;
//! 2. **offline**: `offline_steps` updates of the student on that buffer with the loss
//!    `L = L_TD + 1 · L_distil` ([`crate::dqn::distillation_loss`]), its target network
//!    copied every `offline_target_interval` updates (CleanRL's 1,000);
//! 3. **online**: a fresh buffer, the student acts ε-greedily and learns with
//!    `L = L_TD + λ_t · L_distil`, `λ_t = max(1 − R̄_student / R̄_teacher, 0)` (1 until the
//!    student has finished 10 episodes), R̄_student the mean return of its last 10.
//!
//! The run hands over the student. Choices a DQN library forced (docs/BASELINES.md):
//! - the teacher is the library's best source by its recorded score (the oracle's pick),
//!   or the one `teacher` names: like the oracle, QDagger uses the recorded scores;
//! - returns are scaled to [0, 1] by the task's range before the ratio, since CleanRL's
//!   Atari returns are ≥ 0 and Acrobot's or MountainCar's are not; on CartPole (0–500)
//!   the ratio is unchanged;
//! - the teacher's episodes (evaluation and data) are the run's first episodes, in its
//!   curve and budget: the library holds networks, not the teachers' replay data, and a
//!   step-budget protocol gives every method the same steps; the evaluation's transitions
//!   stay in the teacher's buffer (CleanRL evaluates on an environment of its own);
//! - the TD loss is the config's (Huber, as every learner here), not CleanRL's MSE;
//! - the phases' lengths default to 10,000 steps each, CleanRL's 500,000 (of 10M Atari
//!   steps) scaled to these tasks' budgets.

use std::collections::VecDeque;

use rand::rngs::StdRng;
use rand::Rng;
use serde::{Deserialize, Serialize};

use super::definition::{check_label, MethodKind, ReuseMethod, Tested};
use super::{
    argmax_f32, Actor, Combined, Distillation, EpisodeEnd, LearnerRound, Learning, Library,
    ReuseError, ScoreColumn, Selector, SelectorView, StateValues,
};
use crate::ron_file::Got;
use crate::sapnet::SapNetParams;

/// Episodes of the student's mean return in `λ_t`, and before which `λ_t` is 1 (CleanRL's).
pub const RETURN_WINDOW: usize = 10;

/// The teacher's ε at the start and the end of its data phase, and in its evaluation
/// (CleanRL's `start_e` and `end_e`).
pub const TEACHER_START_EPSILON: f64 = 1.0;
pub const TEACHER_END_EPSILON: f64 = 0.01;

/// QDagger's knobs (`QDagger()` in `protocol.methods`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct QDaggerKnobs {
    /// The student's hidden layers.
    pub hidden: Vec<usize>,
    /// Steps the teacher acts to fill the replay buffer.
    pub teacher_steps: u64,
    /// Updates of the student on the teacher's data before it acts.
    pub offline_steps: u64,
    /// The offline phase's target copy interval, in updates (CleanRL's
    /// `target_network_frequency`).
    pub offline_target_interval: u64,
    /// Episodes the teacher plays first, at ε = [`TEACHER_END_EPSILON`], for R̄_teacher.
    pub teacher_eval_episodes: u32,
    /// τ of both softmaxes.
    pub temperature: f64,
    /// The teacher by its index in the library (`Some(3)` for `source-3`); default: the
    /// best recorded score.
    pub teacher: Option<usize>,
    /// The label of results; default `qdagger` (`qdagger[64,64]` for another student).
    pub label: Option<String>,
}

impl Default for QDaggerKnobs {
    fn default() -> Self {
        Self {
            hidden: vec![100],
            teacher_steps: 10_000,
            offline_steps: 10_000,
            offline_target_interval: 1_000,
            teacher_eval_episodes: 10,
            temperature: 1.0,
            teacher: None,
            label: None,
        }
    }
}

/// QDagger in `protocol.methods`, in magenta.
pub const KIND: MethodKind = MethodKind {
    family: "QDagger",
    hue: 320,
    saturation: 60,
    reuses: true,
    tested: Tested::Learner,
    picks_by_probability: false,
    spreads: false,
};

impl ReuseMethod for QDaggerKnobs {
    fn label(&self) -> String {
        super::gpi::learner_label("qdagger", &self.hidden, self.label.as_deref())
    }

    fn kind(&self) -> MethodKind {
        KIND
    }

    fn learner_hidden(&self) -> Option<&[usize]> {
        Some(&self.hidden)
    }

    fn validate(&self, field: &str) -> Result<(), String> {
        super::gpi::check_learner(field, &self.hidden, self.label.as_deref())?;
        if !(self.temperature > 0.0 && self.temperature.is_finite()) {
            return Err(format!(
                "field `{field}.temperature`: expected a finite τ > 0, got {}",
                self.temperature.got()
            ));
        }
        if let Some(label) = &self.label {
            check_label(field, label)?;
        }
        if self.teacher_eval_episodes == 0 || self.offline_target_interval == 0 {
            return Err(format!(
                "field `{field}`: expected `teacher_eval_episodes` and \
                 `offline_target_interval` of at least 1, got {} and {}",
                self.teacher_eval_episodes, self.offline_target_interval
            ));
        }
        Ok(())
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        let teacher = pick_teacher(library, self.teacher)?;
        Ok(Box::new(QDagger::new(
            self,
            library.descriptions.len(),
            teacher,
            library.return_range,
        )))
    }
}

/// The teacher's index: the given source, or the best recorded score.
fn pick_teacher(library: Library<'_>, given: Option<usize>) -> Result<usize, ReuseError> {
    let n = library.descriptions.len();
    let index = match given {
        Some(index) if index < n => index,
        Some(index) => {
            return Err(ReuseError::Library(format!(
                "QDagger's teacher: expected a source of the library's {n} (0 to {}), got {index}",
                n.saturating_sub(1)
            )))
        }
        None => {
            let best = super::best_source::BestSource::new(library.scores)?;
            best.chosen().expect("the oracle always has a pick")
        }
    };
    Ok(index)
}

/// Where a run of QDagger is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// The teacher plays for R̄_teacher.
    TeacherEvaluation,
    /// The teacher fills the replay buffer; `steps` of it taken.
    TeacherData { steps: u64 },
    /// The student learns from the buffer (one step's round), then acts.
    Student { offline_done: bool },
}

/// The phases and `λ_t`.
#[derive(Debug)]
pub struct QDagger {
    knobs: QDaggerKnobs,
    sources: usize,
    teacher: usize,
    phase: Phase,
    /// The teacher's evaluation returns, then R̄_teacher; the student's last returns; all
    /// scaled by the task's range.
    teacher_returns: Vec<f64>,
    teacher_score: f64,
    student_returns: VecDeque<f64>,
    range: (f64, f64),
    weight: f64,
    /// This step's draws for the teacher's ε-greedy choice (made in `act`, read in
    /// `combine`): whether it explores, and where in the actions.
    explore_coin: f64,
    explore_pick: f64,
    /// Steps the teacher acted, and steps in all.
    teacher_steps_acted: u64,
    steps: u64,
}

impl QDagger {
    pub fn new(knobs: &QDaggerKnobs, sources: usize, teacher: usize, range: (f64, f64)) -> Self {
        Self {
            knobs: knobs.clone(),
            sources,
            teacher,
            phase: Phase::TeacherEvaluation,
            teacher_returns: Vec::new(),
            teacher_score: 0.0,
            student_returns: VecDeque::with_capacity(RETURN_WINDOW),
            range,
            weight: 1.0,
            explore_coin: 1.0,
            explore_pick: 0.0,
            teacher_steps_acted: 0,
            steps: 0,
        }
    }

    fn scaled(&self, episode_return: f64) -> f64 {
        let (low, high) = self.range;
        ((episode_return - low) / (high - low)).clamp(0.0, 1.0)
    }

    /// The teacher's ε now: [`TEACHER_END_EPSILON`] in its evaluation, decaying linearly
    /// from [`TEACHER_START_EPSILON`] over its data phase (CleanRL's `linear_schedule`).
    pub fn teacher_epsilon(&self) -> f64 {
        match self.phase {
            Phase::TeacherData { steps } => {
                let duration = self.knobs.teacher_steps.max(1) as f64;
                let slope = (TEACHER_END_EPSILON - TEACHER_START_EPSILON) / duration;
                (slope * steps as f64 + TEACHER_START_EPSILON).max(TEACHER_END_EPSILON)
            }
            _ => TEACHER_END_EPSILON,
        }
    }

    fn teacher_acts(&self) -> bool {
        !matches!(self.phase, Phase::Student { .. })
    }

    /// `λ_t = max(1 − R̄_student / R̄_teacher, 0)`, 1 before 10 student episodes (and for a
    /// teacher that scores the task's lowest return, which has nothing to compare with).
    pub fn distillation_weight(student: &VecDeque<f64>, teacher: f64) -> f64 {
        if student.len() < RETURN_WINDOW || teacher <= 0.0 {
            return 1.0;
        }
        let mean = student.iter().sum::<f64>() / student.len() as f64;
        (1.0 - mean / teacher).max(0.0)
    }
}

/// QDagger's score: the distillation weight λ_t, on its teacher's row.
pub const SCORE: ScoreColumn = ScoreColumn {
    name: "λ",
    meaning: "λ: λ_t on the teacher's row; P: the teacher's share",
    counted: false,
};

impl Selector for QDagger {
    fn learning(&self) -> Learning {
        Learning::Learner
    }

    /// The teacher acts (with its own ε) until the student's phase, the student after.
    fn act(&mut self, rng: &mut StdRng) -> Actor {
        if self.teacher_acts() {
            self.explore_coin = rng.random::<f64>();
            self.explore_pick = rng.random::<f64>();
            Actor::Combined
        } else {
            Actor::Learner
        }
    }

    /// The teacher's ε-greedy action, with the draws `act` made (the learner's coin,
    /// `values.explored`, is the student's and not the teacher's).
    fn combine(&self, values: &StateValues<'_>) -> Combined {
        let actions = values.learner.len();
        if self.explore_coin < self.teacher_epsilon() {
            let action = ((self.explore_pick * actions as f64) as usize).min(actions - 1);
            return Combined {
                action,
                followed: None,
            };
        }
        Combined {
            action: argmax_f32(&values.sources[self.teacher]),
            followed: Some(self.teacher),
        }
    }

    fn on_combined(&mut self, _: &StateValues<'_>, _: Combined) {
        self.teacher_steps_acted += 1;
    }

    fn learner_round(&mut self) -> LearnerRound {
        self.steps += 1;
        match self.phase {
            Phase::TeacherEvaluation => LearnerRound::Wait,
            Phase::TeacherData { steps } => {
                let steps = steps + 1;
                self.phase = if steps >= self.knobs.teacher_steps {
                    Phase::Student {
                        offline_done: false,
                    }
                } else {
                    Phase::TeacherData { steps }
                };
                LearnerRound::Wait
            }
            Phase::Student {
                offline_done: false,
            } => {
                self.phase = Phase::Student { offline_done: true };
                LearnerRound::Offline {
                    updates: self.knobs.offline_steps,
                    target_interval: self.knobs.offline_target_interval,
                }
            }
            Phase::Student { offline_done: true } => LearnerRound::Online,
        }
    }

    fn distillation(&self) -> Option<Distillation> {
        Some(Distillation {
            teacher: self.teacher,
            temperature: self.knobs.temperature,
            weight: self.weight,
        })
    }

    fn on_episode_end(&mut self, end: &EpisodeEnd) {
        let scaled = self.scaled(end.episode_return);
        match self.phase {
            Phase::TeacherEvaluation => {
                self.teacher_returns.push(scaled);
                if self.teacher_returns.len() >= self.knobs.teacher_eval_episodes as usize {
                    self.teacher_score = self.teacher_returns.iter().sum::<f64>()
                        / self.teacher_returns.len() as f64;
                    self.phase = if self.knobs.teacher_steps == 0 {
                        Phase::Student {
                            offline_done: false,
                        }
                    } else {
                        Phase::TeacherData { steps: 0 }
                    };
                }
            }
            // Episodes the teacher acted are not the student's; the offline round runs on
            // the first step of the student's phase, so its episodes are after it.
            Phase::TeacherData { .. }
            | Phase::Student {
                offline_done: false,
            } => {}
            Phase::Student { offline_done: true } => {
                if self.student_returns.len() == RETURN_WINDOW {
                    self.student_returns.pop_front();
                }
                self.student_returns.push_back(scaled);
                self.weight = Self::distillation_weight(&self.student_returns, self.teacher_score);
            }
        }
    }

    /// Scores: λ_t on the teacher's row; probabilities: the teacher's share of the steps.
    fn view(&self) -> SelectorView {
        let n = self.sources;
        let mut scores = vec![0.0; n];
        scores[self.teacher] = self.weight;
        let mut probabilities = vec![0.0; n];
        if self.steps > 0 {
            probabilities[self.teacher] = self.teacher_steps_acted as f64 / self.steps as f64;
        }
        SelectorView::unjudged(SCORE, scores, probabilities)
    }

    fn chosen(&self) -> Option<usize> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lambda_falls_as_the_student_nears_the_teacher() {
        let mut returns: VecDeque<f64> = [0.5; 9].into_iter().collect();
        // Fewer than 10 student episodes: 1.
        assert_eq!(QDagger::distillation_weight(&returns, 0.8), 1.0);
        returns.push_back(0.5);
        // 1 − 0.5 / 0.8 = 0.375.
        assert!((QDagger::distillation_weight(&returns, 0.8) - 0.375).abs() < 1e-12);
        // A student better than its teacher distils nothing.
        let better: VecDeque<f64> = [0.9; 10].into_iter().collect();
        assert_eq!(QDagger::distillation_weight(&better, 0.8), 0.0);
    }

    fn end(q: &mut QDagger, episode_return: f64) {
        q.on_episode_end(&EpisodeEnd {
            episode_return,
            discounted_return: 0.0,
        });
    }

    #[test]
    fn the_teachers_score_is_measured_on_the_target_and_returns_are_scaled_by_its_range() {
        // Acrobot's returns: −500 … 0. The teacher plays −100 and −60 → 0.8 and 0.88,
        // R̄_teacher = 0.84; the student −290 → 0.42: λ = 1 − 0.42/0.84 = ½.
        let knobs = QDaggerKnobs {
            teacher_eval_episodes: 2,
            ..QDaggerKnobs::default()
        };
        let mut q = QDagger::new(&knobs, 3, 1, (-500.0, 0.0));
        end(&mut q, -100.0);
        assert_eq!(q.phase, Phase::TeacherEvaluation);
        end(&mut q, -60.0);
        assert_eq!(q.phase, Phase::TeacherData { steps: 0 });
        assert!((q.teacher_score - 0.84).abs() < 1e-12);
        q.phase = Phase::Student { offline_done: true };
        for _ in 0..RETURN_WINDOW {
            end(&mut q, -290.0);
        }
        assert!((q.distillation().unwrap().weight - 0.5).abs() < 1e-12);
    }

    /// CleanRL's `linear_schedule(1.0, 0.01, teacher_steps, t)`: ε = 1 − 0.99·t/T, from
    /// 1.0 at t = 0 to 0.01 at T, and 0.01 in the evaluation.
    #[test]
    fn the_teachers_epsilon_decays_over_its_data_phase() {
        let knobs = QDaggerKnobs {
            teacher_steps: 100,
            ..QDaggerKnobs::default()
        };
        let mut q = QDagger::new(&knobs, 2, 0, (0.0, 500.0));
        assert_eq!(q.teacher_epsilon(), TEACHER_END_EPSILON);
        for (t, epsilon) in [(0, 1.0), (50, 0.505), (100, 0.01)] {
            q.phase = Phase::TeacherData { steps: t };
            assert!((q.teacher_epsilon() - epsilon).abs() < 1e-12, "t = {t}");
        }
    }

    #[test]
    fn the_phases_follow_each_other() {
        let knobs = QDaggerKnobs {
            teacher_eval_episodes: 1,
            teacher_steps: 3,
            offline_steps: 7,
            offline_target_interval: 2,
            ..QDaggerKnobs::default()
        };
        let mut q = QDagger::new(&knobs, 2, 0, (0.0, 500.0));
        let mut rng = rand::SeedableRng::seed_from_u64(0);
        let mut rounds = Vec::new();
        for step in 0..7 {
            let actor = q.act(&mut rng);
            rounds.push((actor, q.learner_round()));
            if step == 1 {
                // The evaluation's one episode ends after two steps.
                end(&mut q, 500.0);
            }
        }
        use LearnerRound::*;
        let offline = Offline {
            updates: 7,
            target_interval: 2,
        };
        assert_eq!(
            rounds,
            [
                (Actor::Combined, Wait),
                (Actor::Combined, Wait),
                (Actor::Combined, Wait),
                (Actor::Combined, Wait),
                (Actor::Combined, Wait),
                (Actor::Learner, offline),
                (Actor::Learner, Online),
            ]
        );
        // The teacher's greedy action, unless its own coin explores; the learner's coin
        // (`explored`) is not the teacher's.
        let sources = vec![vec![0.0, 1.0], vec![5.0, 0.0]];
        let values = |explored| StateValues {
            learner: &[0.0, 0.0],
            sources: &sources,
            explored,
            attention: None,
        };
        q.phase = Phase::TeacherEvaluation;
        q.explore_coin = 0.5;
        assert_eq!(q.combine(&values(Some(0))).action, 1);
        q.explore_coin = 0.001;
        q.explore_pick = 0.2;
        assert_eq!(
            q.combine(&values(None)),
            Combined {
                action: 0,
                followed: None
            }
        );
    }
}
