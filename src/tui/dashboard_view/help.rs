//! What the Run view's `?` says after its keys (which are its table's,
//! [`crate::tui::dashboard::KEYS`]): the mouse, what the table's symbols mean, and what
//! each method's score column and P(π) are.

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

/// What the table's score column and P(π) are, by the score's name (the column's
/// header), one line per method.
const COLUMNS: &[(&str, &str, &str)] = &[
    (
        "A",
        "sapnet",
        "A: activation (eq. 5); P: the softmax of A (eq. 6)",
    ),
    (
        "W",
        "prql",
        "W: mean scaled discounted return; P: softmax(τ·W)",
    ),
    (
        "mean",
        "ucb1",
        "mean: scaled return of its pulls; P: 1 on the next",
    ),
    (
        "acted",
        "random",
        "acted: steps it acted; P: 1/N (per episode: 1 drawn)",
    ),
    (
        "score",
        "best-source",
        "score: its recorded score; P: 1 on the best",
    ),
    (
        "wins",
        "gpi",
        "wins: steps its Q won the max; P: their share",
    ),
    (
        "followed",
        "qswitch",
        "followed: steps that took its action; P: their share",
    ),
    (
        "λ",
        "qdagger",
        "λ: λ_t on the teacher's row; P: the teacher's share",
    ),
    ("w̄", "a2t", "w̄: mean attention weight; P: its weight now"),
];

/// The lines after the keys: the mouse and the symbols, then what the score and P(π)
/// columns mean for the followed method (`score_name`) first, then for every other (the
/// overlay shows as many as its box holds).
pub fn legend(score_name: Option<&str>) -> Vec<(&'static str, &'static str)> {
    let mut lines = SYMBOLS.to_vec();
    let followed = COLUMNS
        .iter()
        .filter(|(name, ..)| Some(*name) == score_name);
    let others = COLUMNS
        .iter()
        .filter(|(name, ..)| Some(*name) != score_name);
    lines.extend(
        followed
            .chain(others)
            .map(|&(_, method, what)| (method, what)),
    );
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_followed_methods_columns_come_first() {
        let lines = legend(Some("wins"));
        assert_eq!(lines.len(), SYMBOLS.len() + COLUMNS.len());
        assert_eq!(lines[SYMBOLS.len()].0, "gpi", "the followed method first");
        assert_eq!(legend(None)[SYMBOLS.len()].0, "sapnet");
    }
}
