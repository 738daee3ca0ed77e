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
];
