//! Teach mode's keys, for its `?` overlay (drawn by [`crate::tui::screen::draw_help`]),
//! alone or on the dashboard.

use crate::teach::Teach;

/// Teach mode's own keys, for its `?`. `p` is listed where it renumbers the policies (they
/// are called π0…); Esc quits stand-alone teach mode, and on the dashboard goes back to it.
pub(crate) fn teach_help(
    teach: &Teach,
    on_the_dashboard: bool,
) -> Vec<(&'static str, &'static str)> {
    let mut keys = vec![
        ("↑↓←→ hjkl, click", "pick a policy (its node or its row)"),
        ("a", "activate the picked policy (A += 𝒜, eq. 8)"),
        ("s", "make the next spread call (eq. 9–11)"),
        (
            "r / R",
            "walk it call by call / run the spreading to its end",
        ),
        (
            "< / >",
            "r walks slower / faster (0.5 to 16 calls a second)",
        ),
        (
            "u / c",
            "undo the last call / back to the starting activations",
        ),
    ];
    if teach.numbering().is_some() {
        keys.push(("p", "number the policies π1…πN as the paper does, or π0…"));
    }
    keys.extend([
        (
            "1 … 5",
            "edit T_ω, 𝒜, τ, the path mode or the weight M of an edge",
        ),
        (
            "+ / − · e",
            "turn it a step (the walk restarts) · the next edge",
        ),
        (
            "E / x",
            "add or reweight an edge I J W / cut the selected edge",
        ),
        (
            "M",
            "clicks edit M: click two policies to join (0.4) or cut",
        ),
        (
            "n / D / C",
            "add a policy / remove the picked / change its category",
        ),
        (
            "v",
            "show the trace, the tree, the chart, or A and P through time",
        ),
        (
            "w / X",
            "save the lesson (--config reads it) / exercise: predict ΔA",
        ),
        ("?", "this help (any key closes it)"),
    ]);
    if on_the_dashboard {
        keys.extend([
            ("t / Esc", "back to the paused dashboard"),
            ("q / Ctrl-C", "quit"),
        ]);
    } else {
        keys.push(("q / Esc / Ctrl-C", "quit"));
    }
    keys
}
