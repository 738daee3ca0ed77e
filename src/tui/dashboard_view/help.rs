//! The dashboard's keys, and what the table's symbols mean, for its `?` overlay (drawn by
//! [`crate::tui::screen::draw_help`]).

/// Each key (or symbol) beside what it does (or means); an empty pair is a blank line.
pub(super) const KEYS: &[(&str, &str)] = &[
    ("space", "pause / resume training"),
    ("n", "one training step while paused"),
    (
        "+ / -",
        "faster / slower (delays training, never the screen)",
    ),
    ("tab / click", "focus the graph or the table"),
    (
        "↑↓←→ hjkl",
        "pick a policy (graph: the nearest node that way)",
    ),
    ("click", "pick the policy of a node or a row"),
    ("z", "enlarge the focused panel, or back"),
    ("m", "follow the next reusing method's run"),
    ("v", "scores as A − max(A), readable when A saturates"),
    ("t", "teach mode on the live graph (pauses training)"),
    ("?", "this help (any key closes it)"),
    ("q / Esc / Ctrl-C", "quit"),
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

/// The overlay's lines: the keys and symbols, then what the score and P(π) columns mean
/// for the followed method (`score_name`) and, when `room` lines allow, for every other.
pub(super) fn keys(score_name: Option<&str>, room: usize) -> Vec<(&'static str, &'static str)> {
    let mut lines = KEYS.to_vec();
    let followed = COLUMNS
        .iter()
        .filter(|(name, ..)| Some(*name) == score_name);
    let others = COLUMNS
        .iter()
        .filter(|(name, ..)| Some(*name) != score_name);
    let all = lines.len() + COLUMNS.len() <= room;
    lines.extend(
        followed
            .chain(others.filter(|_| all))
            .map(|&(_, method, what)| (method, what)),
    );
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_followed_methods_columns_first_and_the_others_where_they_fit() {
        let short = keys(Some("wins"), KEYS.len() + 3);
        assert_eq!(short.len(), KEYS.len() + 1);
        assert_eq!(short.last().unwrap().0, "gpi");
        let tall = keys(Some("wins"), 40);
        assert_eq!(tall.len(), KEYS.len() + COLUMNS.len());
        assert_eq!(tall[KEYS.len()].0, "gpi", "the followed method first");
        assert_eq!(keys(None, KEYS.len()).len(), KEYS.len());
    }
}
