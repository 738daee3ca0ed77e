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
        "the step one source's P passed 0.99 (as the table and comparison.csv): SAP-Net and \
         PRQ-learning only, whose P is learned; - for the others",
    ),
    ("", ""),
    ("score, P(π)", "the table's two columns, by method:"),
    (
        "sapnet",
        "A: activation (eq. 5); P: the softmax of A (eq. 6)",
    ),
    ("prql", "W: mean scaled discounted return; P: softmax(τ·W)"),
    (
        "ucb1",
        "mean: scaled return of its pulls; P: 1 on the next pull",
    ),
    (
        "random",
        "acted: steps it acted; P: 1/N (per episode: the drawn one)",
    ),
    ("best-source", "score: its recorded score; P: 1 on the best"),
    (
        "gpi",
        "wins: steps whose action took its Q (the max); P: their share",
    ),
    (
        "qswitch",
        "followed: steps that followed its action; P: their share",
    ),
    (
        "qdagger",
        "λ: λ_t on the teacher's row; P: the teacher's share of steps",
    ),
    (
        "a2t",
        "w̄: mean attention weight over the run; P: its weight now",
    ),
];
