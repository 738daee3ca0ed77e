//! What the Run view's `?` says after its keys (which are its table's,
//! [`crate::tui::dashboard::KEYS`]): the mouse, what the table's symbols mean, and what
//! the followed method's score column and P(π) are.

use crate::reuse::ScoreColumn;

/// The mouse and the symbols, each beside what it does or means; an empty pair is a
/// blank line.
const SYMBOLS: &[(&str, &str)] = &[
    ("click", "pick a node's or a row's policy, focus its panel"),
    ("", ""),
    ("○ ◐ ●", "a node's A: < ¼, < ¾, ≥ ¾ of the highest A"),
    ("cat", "category: number of hidden layers (the prototype)"),
    ("+/−", "its positive / negative transitions so far (eq. 7)"),
    (
        "lock-in step",
        "P first above 0.99: sapnet, prql only; - elsewhere",
    ),
];

/// The lines after the keys: the mouse and the symbols, then what the followed method's
/// score column and P(π) are, as its selector's file says ([`ScoreColumn::meaning`]).
pub fn legend(score: Option<ScoreColumn>) -> Vec<(&'static str, &'static str)> {
    let mut lines = SYMBOLS.to_vec();
    if let Some(score) = score.filter(|s| !s.meaning.is_empty()) {
        lines.push(("score, P", score.meaning));
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_followed_methods_column_is_said_by_its_selector() {
        let lines = legend(Some(crate::reuse::gpi::SCORE));
        assert_eq!(lines.len(), SYMBOLS.len() + 1);
        assert!(lines[SYMBOLS.len()]
            .1
            .starts_with("wins: steps its Q won the max"));
        let dqn = crate::reuse::ScoreColumn::NONE;
        assert_eq!(legend(Some(dqn)).len(), SYMBOLS.len(), "no score, no line");
        assert_eq!(legend(None).len(), SYMBOLS.len());
    }
}
