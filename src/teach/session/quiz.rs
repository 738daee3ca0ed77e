//! Teach mode's quiz: the exercise (`X`), where each call's ΔA is asked before it is made
//! (eq. 10), and the lesson's own questions, asked when a walk ends. Each answer is
//! checked, scored, and only then is the answer said.

use super::prompt::{Prompt, PromptKind};
use super::Teach;
use crate::sapnet::Call;
use crate::teach::questions::Question;

/// Answers right of answers given.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Score {
    pub right: usize,
    pub asked: usize,
}

impl Score {
    fn count(&mut self, right: bool) {
        self.asked += 1;
        if right {
            self.right += 1;
        }
    }
}

/// How far a typed ΔA may be from the call's and count as right: the screen gives ΔA to
/// six decimals, a student working by hand to three or four.
pub const ANSWER_TOLERANCE: f64 = 1e-3;

/// A predicted call checked against eq. 10: right or not, and the working that says why.
#[derive(Debug, Clone, PartialEq)]
struct Judged {
    right: bool,
    working: String,
}

/// Checks `answer` (a number, or `stop`) against `call`: eq. 10 deposits ΔA = η/(h×Ω)
/// where Ω < T_ω, else the call stops. `names` as the screen shows the policies.
fn judge(call: &Call, threshold: f64, names: &[String], answer: &str) -> Judged {
    let stops = call.omega >= threshold;
    let delta = call.eta / (call.h as f64 * call.omega);
    let said_stop = ["stop", "stops", "stopped"].contains(&answer.to_lowercase().as_str());
    let right = match (stops, said_stop, answer.parse::<f64>()) {
        (true, true, _) => true,
        (false, false, Ok(x)) => (x - delta).abs() <= ANSWER_TOLERANCE,
        _ => false,
    };
    let working = if stops {
        format!(
            "eq. 10: Ω < T_ω is {:.4} < {threshold}, false: the call stops, ΔA = 0",
            call.omega
        )
    } else {
        format!(
            "eq. 10: Ω < T_ω is {:.4} < {threshold}, true: ΔA[{}] = η/(h×Ω) = \
             {:.6}/({}×{:.4}) = {delta:.6}",
            call.omega, names[call.to], call.eta, call.h, call.omega
        )
    };
    Judged { right, working }
}

/// The lesson's questions, asked once each, in order, at the end of walks.
#[derive(Debug, Clone, Default)]
pub(super) struct Questions {
    list: Vec<Question>,
    /// The next question to ask.
    next: usize,
    score: Score,
}

impl Questions {
    pub(super) fn new(list: Vec<Question>) -> Self {
        Self {
            list,
            ..Self::default()
        }
    }

    /// The question's text as the prompt asks it.
    pub(super) fn text_of(&self, k: usize) -> Option<String> {
        self.list.get(k).map(Question::prompt)
    }

    /// The questions as the lesson file holds them.
    pub(super) fn list(&self) -> &[Question] {
        &self.list
    }

    /// The next question, if one is left to ask.
    fn due(&self) -> Option<usize> {
        (self.next < self.list.len()).then_some(self.next)
    }
}

impl Teach {
    /// `X`: exercise mode on (the score from 0) or off.
    pub fn toggle_exercise(&mut self) {
        self.exercise = match self.exercise {
            Some(_) => None,
            None => Some(Score::default()),
        };
        self.notice = Some(match self.exercise {
            Some(_) => format!(
                "exercise: s asks the next call's ΔA first (right within {ANSWER_TOLERANCE}); \
                 X ends it"
            ),
            None => "exercise ended".to_string(),
        });
    }

    /// The exercise's score, in exercise mode.
    pub fn score(&self) -> Option<Score> {
        self.exercise
    }

    /// Whether the screen keeps the next call's ΔA and eq. 10's outcome (deposit or stop)
    /// to itself: in the exercise they are what `s` asks, said once answered (and the
    /// call made).
    pub fn hides_next_answer(&self) -> bool {
        self.exercise.is_some()
    }

    /// `s`: in exercise mode, asks the next call's ΔA before making it; else makes it.
    pub fn step_or_ask(&mut self) {
        let next = self.walk.as_ref().and_then(|w| w.next_call());
        if self.exercise.is_some() && next.is_some() {
            self.open_prompt(PromptKind::Predict);
        } else {
            self.step();
        }
    }

    /// Checks `answer` against the next call (eq. 10: ΔA = η/(h×Ω) where Ω < T_ω, else
    /// the call stops), says right or the working, counts it, then makes the call.
    pub(super) fn check_prediction(&mut self, answer: &str) {
        let Some(call) = self.walk.as_ref().and_then(|w| w.next_call()) else {
            return;
        };
        let answer = answer.trim();
        let threshold = self.net.params().threshold;
        let Judged { right, working } = judge(&call, threshold, self.names(), answer);
        let score = self.exercise.get_or_insert_with(Score::default);
        score.count(right);
        let score = *score;
        let verdict = if right {
            format!("right ({working})")
        } else if answer.is_empty() {
            format!("no answer: {working}")
        } else {
            format!("not {answer}: {working}")
        };
        self.step();
        self.notice = Some(format!("{verdict} · score {}/{}", score.right, score.asked));
    }

    /// The questions' score, once one is answered.
    pub fn quiz(&self) -> Option<Score> {
        (self.questions.score.asked > 0).then_some(self.questions.score)
    }

    /// How many questions the lesson holds, and how many are asked.
    pub fn questions(&self) -> (usize, usize) {
        (self.questions.list.len(), self.questions.next)
    }

    /// At a walk's end, the next of the lesson's questions is asked.
    pub(super) fn ask_at_walk_end(&mut self) {
        let done = self.walk.as_ref().is_some_and(|w| w.is_done());
        let Some(k) = self.questions.due() else {
            return;
        };
        if done && self.prompt.is_none() {
            self.playback.stop();
            self.prompt = Some(Prompt {
                kind: PromptKind::Question(k),
                text: String::new(),
            });
        }
    }

    /// Checks the answer to question `k`, says right or the answer, and asks the next.
    pub(super) fn check_question(&mut self, k: usize, typed: &str) {
        let Some(question) = self.questions.list.get(k) else {
            return;
        };
        let verdict = question.check(typed, self.names());
        self.questions.next = k + 1;
        self.questions.score.count(verdict.right);
        let said = if verdict.right {
            format!("right: {}", verdict.answer)
        } else if typed.trim().is_empty() {
            format!("no answer: it is {}", verdict.answer)
        } else {
            format!("not {}: it is {}", typed.trim(), verdict.answer)
        };
        let score = self.questions.score;
        self.notice = Some(format!(
            "{said} · questions {}/{}",
            score.right, score.asked
        ));
        self.ask_at_walk_end();
    }

    /// Esc on question `k`: its answer stays hidden, the next is asked.
    pub(super) fn skip_question(&mut self, k: usize) {
        self.questions.next = k + 1;
        self.notice = Some("question skipped".to_string());
        self.ask_at_walk_end();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<String> {
        (0..4).map(|i| format!("π{i}")).collect()
    }

    /// Fig. 2's first call from π1: η = 1/3, h = 1, Ω = 0.4 < T_ω = 1, so ΔA =
    /// (1/3)/(1×0.4) = 0.833333; at Ω = 1.2 the same call stops.
    #[test]
    fn a_prediction_is_right_within_the_tolerance_or_as_stop() {
        let call = Call {
            from: 1,
            to: 0,
            h: 1,
            omega: 0.4,
            eta: 1.0 / 3.0,
        };
        assert!(judge(&call, 1.0, &names(), "0.8333").right);
        assert!(!judge(&call, 1.0, &names(), "0.83").right);
        assert!(!judge(&call, 1.0, &names(), "stop").right);
        let stopping = Call { omega: 1.2, ..call };
        let judged = judge(&stopping, 1.0, &names(), "Stop");
        assert!(judged.right);
        assert_eq!(
            judged.working,
            "eq. 10: Ω < T_ω is 1.2000 < 1, false: the call stops, ΔA = 0"
        );
        assert!(!judge(&stopping, 1.0, &names(), "0").right);
    }
}
