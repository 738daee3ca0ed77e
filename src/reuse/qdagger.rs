//! QDagger (Agarwal et al., "Reincarnating Reinforcement Learning: Reusing Prior
//! Computation to Accelerate Progress", NeurIPS 2022), as CleanRL's `qdagger_dqn_*` runs it,
//! with a source of the library as the teacher.
//!
//! A student, a fresh DQN of the method's own, learns from a teacher in three phases:
//! 1. **teacher data**: the teacher acts for `teacher_steps` steps (ε-greedily, with the
//!    config's exploration) and its transitions fill the replay buffer; the student waits;
//! 2. **offline**: `offline_steps` updates of the student on that buffer with the loss
//!    `L = L_TD + 1 · L_distil` ([`crate::dqn::distillation_loss`]);
//! 3. **online**: a fresh buffer, the student acts ε-greedily and learns with
//!    `L = L_TD + λ_t · L_distil`, `λ_t = max(1 − R̄_student / R̄_teacher, 0)` (1 until the
//!    student has finished 10 episodes), R̄_student the mean return of its last 10.
//!
//! The run hands over the student. Choices a DQN library forced (docs/BASELINES.md):
//! - the teacher is the library's best source by its recorded score (the oracle's pick),
//!   or the one `teacher` names; R̄_teacher is that recorded score, not 10 new episodes;
//! - returns are scaled to [0, 1] by the task's range before the ratio, since CleanRL's
//!   Atari returns are ≥ 0 and Acrobot's or MountainCar's are not; on CartPole (0–500)
//!   the ratio is unchanged;
//! - the teacher phase's episodes are the run's first episodes, in its curve and budget:
//!   the library holds networks, not the teachers' replay data;
//! - the TD loss is the config's (Huber, as every learner here), not CleanRL's MSE;
//! - the phases' lengths default to 10,000 steps each, CleanRL's 500,000 (of 10M Atari
//!   steps) scaled to these tasks' budgets.

use std::collections::VecDeque;

use rand::rngs::StdRng;
use serde::{Deserialize, Serialize};

use super::definition::{check_label, MethodKind, ReuseMethod, Tested};
use super::{
    argmax_f32, Actor, Combined, Distillation, EpisodeEnd, LearnerRound, Learning, Library,
    ReuseError, Selector, SelectorView, StateValues,
};
use crate::ron_file::Got;
use crate::sapnet::SapNetParams;

/// Episodes of the student's mean return in `λ_t`, and before which `λ_t` is 1 (CleanRL's).
pub const RETURN_WINDOW: usize = 10;

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
        Ok(())
    }

    fn selector(
        &self,
        library: Library<'_>,
        _: &SapNetParams,
    ) -> Result<Box<dyn Selector>, ReuseError> {
        let (teacher, score) = pick_teacher(library, self.teacher)?;
        Ok(Box::new(QDagger::new(
            self,
            library.descriptions.len(),
            teacher,
            score,
            library.return_range,
        )))
    }
}

/// The teacher's index and recorded score: the given source, or the best recorded score.
fn pick_teacher(library: Library<'_>, given: Option<usize>) -> Result<(usize, f64), ReuseError> {
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
    let score = library
        .scores
        .get(index)
        .copied()
        .flatten()
        .ok_or_else(|| {
            ReuseError::Library(format!(
                "QDagger weighs its distillation by the teacher's recorded score, and source \
             {index} has none (its metadata's `final_score` is empty)"
            ))
        })?;
    Ok((index, score))
}

/// The phases and `λ_t`.
#[derive(Debug)]
pub struct QDagger {
    knobs: QDaggerKnobs,
    sources: usize,
    teacher: usize,
    /// R̄_teacher and the student's last returns, both scaled by the task's range.
    teacher_score: f64,
    student_returns: VecDeque<f64>,
    range: (f64, f64),
    /// Steps taken, and whether the offline phase is done.
    steps: u64,
    offline_done: bool,
    weight: f64,
    teacher_steps_acted: u64,
}

impl QDagger {
    pub fn new(
        knobs: &QDaggerKnobs,
        sources: usize,
        teacher: usize,
        teacher_score: f64,
        range: (f64, f64),
    ) -> Self {
        let mut qdagger = Self {
            knobs: knobs.clone(),
            sources,
            teacher,
            teacher_score: 0.0,
            student_returns: VecDeque::with_capacity(RETURN_WINDOW),
            range,
            steps: 0,
            offline_done: false,
            weight: 1.0,
            teacher_steps_acted: 0,
        };
        qdagger.teacher_score = qdagger.scaled(teacher_score);
        qdagger
    }

    fn scaled(&self, episode_return: f64) -> f64 {
        let (low, high) = self.range;
        ((episode_return - low) / (high - low)).clamp(0.0, 1.0)
    }

    fn in_teacher_phase(&self) -> bool {
        self.steps < self.knobs.teacher_steps
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

impl Selector for QDagger {
    fn learning(&self) -> Learning {
        Learning::Learner
    }

    /// The teacher acts (around the learner's ε coin) in the teacher phase, the student
    /// after it.
    fn act(&mut self, _rng: &mut StdRng) -> Actor {
        if self.in_teacher_phase() {
            Actor::Combined
        } else {
            Actor::Learner
        }
    }

    /// The teacher's greedy action, or the exploring one.
    fn combine(&self, values: &StateValues<'_>) -> Combined {
        match values.explored {
            Some(action) => Combined {
                action,
                followed: None,
            },
            None => Combined {
                action: argmax_f32(&values.sources[self.teacher]),
                followed: Some(self.teacher),
            },
        }
    }

    fn on_combined(&mut self, _: &StateValues<'_>, _: Combined) {
        self.teacher_steps_acted += 1;
    }

    fn learner_round(&mut self) -> LearnerRound {
        self.steps += 1;
        if self.in_teacher_phase() {
            LearnerRound::Wait
        } else if !self.offline_done {
            self.offline_done = true;
            LearnerRound::Offline {
                updates: self.knobs.offline_steps,
            }
        } else {
            LearnerRound::Online
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
        // Episodes the teacher acted are not the student's.
        if !self.offline_done {
            return;
        }
        if self.student_returns.len() == RETURN_WINDOW {
            self.student_returns.pop_front();
        }
        self.student_returns
            .push_back(self.scaled(end.episode_return));
        self.weight = Self::distillation_weight(&self.student_returns, self.teacher_score);
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
        SelectorView {
            score_name: "λ",
            scores,
            probabilities,
            positive: vec![0; n],
            negative: vec![0; n],
            excluded: Vec::new(),
        }
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

    #[test]
    fn returns_are_scaled_by_the_tasks_range_before_the_ratio() {
        // Acrobot's returns: −500 … 0. Teacher −100 → 0.8; student −300 → 0.4; λ = ½.
        let knobs = QDaggerKnobs::default();
        let mut q = QDagger::new(&knobs, 3, 1, -100.0, (-500.0, 0.0));
        q.offline_done = true;
        for _ in 0..RETURN_WINDOW {
            q.on_episode_end(&EpisodeEnd {
                episode_return: -300.0,
                discounted_return: 0.0,
            });
        }
        assert!((q.distillation().unwrap().weight - 0.5).abs() < 1e-12);
    }

    #[test]
    fn the_phases_follow_each_other() {
        let knobs = QDaggerKnobs {
            teacher_steps: 3,
            offline_steps: 7,
            ..QDaggerKnobs::default()
        };
        let mut q = QDagger::new(&knobs, 2, 0, 500.0, (0.0, 500.0));
        let mut rng = rand::SeedableRng::seed_from_u64(0);
        let mut rounds = Vec::new();
        for _ in 0..5 {
            let actor = q.act(&mut rng);
            rounds.push((actor, q.learner_round()));
        }
        use LearnerRound::*;
        assert_eq!(
            rounds,
            [
                (Actor::Combined, Wait),
                (Actor::Combined, Wait),
                (Actor::Combined, Offline { updates: 7 }),
                (Actor::Learner, Online),
                (Actor::Learner, Online),
            ]
        );
        // The teacher's greedy action, unless the coin explores.
        let sources = vec![vec![0.0, 1.0], vec![5.0, 0.0]];
        let values = |explored| StateValues {
            learner: &[0.0, 0.0],
            sources: &sources,
            explored,
            attention: None,
        };
        assert_eq!(q.combine(&values(None)).action, 1);
        assert_eq!(q.combine(&values(Some(0))).action, 0);
    }
}
