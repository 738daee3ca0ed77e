//! A lesson's questions (issue 39, item 5): asked when a walk ends, each with a hidden
//! answer — a policy ("which policy has the highest P after this walk?") or a number
//! within a tolerance — checked and scored. The answer is said only once answered.

use serde::{Deserialize, Serialize};

/// The most questions a lesson may hold: a short list, asked one after another.
pub const MAX_QUESTIONS: usize = 50;

/// One question of a lesson file: `(ask: "…", answer: Policy(2))` or
/// `(ask: "…", answer: Number(value: 0.9375, tolerance: 0.001))`.
#[derive(Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Question {
    pub ask: String,
    pub answer: Answer,
}

/// A question's answer, hidden until the student has answered.
#[derive(Clone, PartialEq, Serialize, Deserialize)]
pub enum Answer {
    /// A policy, by its index (0-based, as the flags number them).
    Policy(usize),
    /// A number; an answer within `tolerance` of `value` is right.
    Number { value: f64, tolerance: f64 },
}

/// Questions are printed without their answers, even by `{:?}`: a debug print of a lesson
/// must not give them away.
impl std::fmt::Debug for Question {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Question")
            .field("ask", &self.ask)
            .field("answer", &"(hidden)")
            .finish()
    }
}

impl std::fmt::Debug for Answer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("(hidden)")
    }
}

/// A student's answer checked: right or not, and the answer to say after.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    pub right: bool,
    /// The answer in words (`π2`, `0.9375 ± 0.001`).
    pub answer: String,
}

impl Question {
    /// What the prompt asks: the question and the kind of answer it takes.
    pub fn prompt(&self) -> String {
        let takes = match self.answer {
            Answer::Policy(_) => "a policy's name or index",
            Answer::Number { .. } => "a number",
        };
        format!("{} ({takes}):", self.ask)
    }

    /// Checks `typed` against the answer; `names` are the policies as the screen shows
    /// them (a name, or an index from 0, is accepted).
    pub fn check(&self, typed: &str, names: &[String]) -> Verdict {
        let typed = typed.trim();
        match self.answer {
            Answer::Policy(i) => {
                let picked = typed.parse::<usize>().ok().or_else(|| {
                    names
                        .iter()
                        .position(|name| name.eq_ignore_ascii_case(typed))
                });
                Verdict {
                    right: picked == Some(i),
                    answer: names.get(i).cloned().unwrap_or_else(|| i.to_string()),
                }
            }
            Answer::Number { value, tolerance } => Verdict {
                right: typed
                    .parse::<f64>()
                    .is_ok_and(|x| (x - value).abs() <= tolerance),
                answer: format!("{value} ± {tolerance}"),
            },
        }
    }
}

/// Checks a lesson's questions against its `n` policies; the message names the field.
pub fn validate(questions: &[Question], n: usize) -> Result<(), String> {
    if questions.len() > MAX_QUESTIONS {
        return Err(format!(
            "field `questions`: expected at most {MAX_QUESTIONS} questions, got {}",
            questions.len()
        ));
    }
    for (k, question) in questions.iter().enumerate() {
        if question.ask.trim().is_empty() {
            return Err(format!(
                "field `questions[{k}].ask`: expected the question's text, got nothing"
            ));
        }
        match question.answer {
            Answer::Policy(i) if i >= n => {
                return Err(format!(
                    "field `questions[{k}].answer`: expected Policy(0) to Policy({}), the \
                     lesson's {n} policies, got Policy({i})",
                    n.saturating_sub(1)
                ))
            }
            Answer::Number { value, .. } if !value.is_finite() => {
                return Err(format!(
                    "field `questions[{k}].answer`: expected a finite value, got {value}"
                ))
            }
            Answer::Number { tolerance, .. } if !(tolerance.is_finite() && tolerance >= 0.0) => {
                return Err(format!(
                    "field `questions[{k}].answer`: expected a tolerance ≥ 0, got {tolerance}"
                ))
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<String> {
        (0..4).map(|i| format!("π{i}")).collect()
    }

    #[test]
    fn a_policy_is_answered_by_name_or_index_and_a_number_within_its_tolerance() {
        let which = Question {
            ask: "Which policy has the highest P?".into(),
            answer: Answer::Policy(1),
        };
        assert!(which.check("π1", &names()).right);
        assert!(which.check(" 1 ", &names()).right);
        assert!(!which.check("π0", &names()).right);
        assert_eq!(which.check("π0", &names()).answer, "π1");
        let how_much = Question {
            ask: "A[π0]?".into(),
            answer: Answer::Number {
                value: 0.9375,
                tolerance: 0.001,
            },
        };
        assert!(how_much.check("0.938", &names()).right);
        assert!(!how_much.check("0.94", &names()).right);
        assert!(!how_much.check("stop", &names()).right);
    }

    #[test]
    fn the_answer_is_not_in_a_debug_print() {
        let q = Question {
            ask: "Which?".into(),
            answer: Answer::Policy(3),
        };
        let printed = format!("{q:?}");
        assert!(!printed.contains('3'), "{printed}");
        assert!(!q.prompt().contains('3'));
    }

    #[test]
    fn bad_questions_are_named_by_field() {
        let policy = |i| Question {
            ask: "Which?".into(),
            answer: Answer::Policy(i),
        };
        assert!(validate(&[policy(3)], 4).is_ok());
        let e = validate(&[policy(3), policy(4)], 4).unwrap_err();
        assert!(
            e.starts_with("field `questions[1].answer`: expected Policy(0) to Policy(3)"),
            "{e}"
        );
        let number = Question {
            ask: " ".into(),
            answer: Answer::Number {
                value: 1.0,
                tolerance: 0.1,
            },
        };
        let e = validate(&[number], 4).unwrap_err();
        assert!(e.starts_with("field `questions[0].ask`"), "{e}");
    }
}
