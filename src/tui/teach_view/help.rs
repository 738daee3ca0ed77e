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
        ("r", "run the spreading to its end (s, u, c stop it)"),
        ("u", "undo the last call, then the activation"),
        ("c", "back to the starting activations"),
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
            "+ / −",
            "turn it a step: the walk restarts, the change is shown",
        ),
        ("e", "the picked policy's next edge (for 5 and x)"),
        ("E", "add an edge I J W, or reweight it (as --add-edge)"),
        ("x", "cut the picked policy's selected edge"),
        (
            "M, click, click",
            "mouse edits M: click two policies to join them (0.4) or cut",
        ),
        (
            "n",
            "add a policy (its category asked where categories build M)",
        ),
        ("D", "remove the picked policy and its edges"),
        (
            "C",
            "change the picked policy's category (as --set-category)",
        ),
        (
            "w",
            "write the lesson as it stands to a file (--config reads it)",
        ),
        (
            "X",
            "exercise: s asks the next call's ΔA first and scores it",
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
