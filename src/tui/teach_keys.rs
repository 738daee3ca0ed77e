//! Teach mode's one key table ([`TEACH_KEYS`]): its matcher ([`apply_teach_key`]), its
//! `?` lines and its status bar's keys are all read from it, alone or on the dashboard.
//! What each screen adds (`?`, quitting, the dashboard's `t`) is the screen's to say.

use crossterm::event::{KeyCode, KeyEvent};

use super::keys::{self, ch, code, Binding};
use crate::teach::knobs::Knob;
use crate::teach::session::PromptKind;
use crate::teach::Teach;

/// What a teach key does to the session.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TeachCommand {
    MoveCursor(isize),
    Activate,
    Step,
    Walk,
    Run,
    Speed { faster: bool },
    Undo,
    Reset,
    Numbering,
    Knob(Knob),
    Turn { up: bool },
    NextEdge,
    AddEdge,
    CutEdge,
    Linking,
    AddPolicy,
    RemovePolicy,
    ChangeCategory,
    NextPanel,
    Save,
    Exercise,
}

use TeachCommand as T;

const fn knob(k: Knob) -> (keys::Key, TeachCommand) {
    (ch(k.key()), T::Knob(k))
}

/// Teach mode's keys, in the order `?` lists them. The status bar offers them in groups: a
/// line's `bar` may name the lines after it that have none (`↑↓ a s`); its words are said
/// where the screen is wide enough, the keys alone where it is not.
pub const TEACH_KEYS: &[Binding<TeachCommand>] = &[
    Binding {
        keys: &[
            (code(KeyCode::Up), T::MoveCursor(-1)),
            (ch('k'), T::MoveCursor(-1)),
            (code(KeyCode::Left), T::MoveCursor(-1)),
            (ch('h'), T::MoveCursor(-1)),
            (code(KeyCode::Down), T::MoveCursor(1)),
            (ch('j'), T::MoveCursor(1)),
            (code(KeyCode::Right), T::MoveCursor(1)),
            (ch('l'), T::MoveCursor(1)),
        ],
        help: ("↑↓←→ hjkl, click", "pick a policy (its node or its row)"),
        bar: Some(("↑↓ a s", "")),
    },
    Binding {
        keys: &[(ch('a'), T::Activate)],
        help: ("a", "activate the picked policy (A += 𝒜, eq. 8)"),
        bar: None,
    },
    Binding {
        keys: &[(ch('s'), T::Step)],
        help: ("s", "make the next spread call (eq. 9–11)"),
        bar: None,
    },
    Binding {
        keys: &[(ch('r'), T::Walk), (ch('R'), T::Run)],
        help: (
            "r / R",
            "walk it call by call / run the spreading to its end",
        ),
        bar: Some(("r R", "walk run")),
    },
    Binding {
        keys: &[
            (ch('<'), T::Speed { faster: false }),
            (ch(','), T::Speed { faster: false }),
            (ch('>'), T::Speed { faster: true }),
            (ch('.'), T::Speed { faster: true }),
        ],
        help: (
            "< / >",
            "r walks slower / faster (0.5 to 16 calls a second)",
        ),
        bar: None,
    },
    Binding {
        keys: &[(ch('u'), T::Undo), (ch('c'), T::Reset)],
        help: (
            "u / c",
            "undo the last call / back to the starting activations",
        ),
        bar: Some(("u c", "")),
    },
    Binding {
        keys: &[(ch('p'), T::Numbering)],
        help: ("p", "number the policies π1…πN as the paper does, or π0…"),
        bar: None,
    },
    Binding {
        keys: &[
            knob(Knob::Threshold),
            knob(Knob::Coefficient),
            knob(Knob::Temperature),
            knob(Knob::Paths),
            knob(Knob::EdgeWeight),
        ],
        help: (
            "1 … 5",
            "edit T_ω, 𝒜, τ, the path mode or the weight M of an edge",
        ),
        bar: Some(("1–5 ±", "")),
    },
    Binding {
        keys: &[
            (ch('+'), T::Turn { up: true }),
            (ch('='), T::Turn { up: true }),
            (ch('-'), T::Turn { up: false }),
            (ch('e'), T::NextEdge),
        ],
        help: (
            "+ / − · e",
            "turn it a step (the walk restarts) · the next edge",
        ),
        bar: None,
    },
    Binding {
        keys: &[(ch('E'), T::AddEdge), (ch('x'), T::CutEdge)],
        help: (
            "E / x",
            "add or reweight an edge I J W / cut the selected edge",
        ),
        bar: Some(("E x M", "edges")),
    },
    Binding {
        keys: &[(ch('M'), T::Linking)],
        help: (
            "M",
            "clicks edit M: click two policies to join (0.4) or cut",
        ),
        bar: None,
    },
    Binding {
        keys: &[
            (ch('n'), T::AddPolicy),
            (ch('D'), T::RemovePolicy),
            (ch('C'), T::ChangeCategory),
        ],
        help: (
            "n / D / C",
            "add a policy / remove the picked / change its category",
        ),
        bar: Some(("n D C", "policy")),
    },
    Binding {
        keys: &[(ch('v'), T::NextPanel)],
        help: (
            "v",
            "show the trace, the tree, the chart, or A and P through time",
        ),
        bar: Some(("v", "view")),
    },
    Binding {
        keys: &[(ch('w'), T::Save), (ch('X'), T::Exercise)],
        help: (
            "w / X",
            "save the lesson (--config reads it) / exercise: predict ΔA",
        ),
        bar: Some(("w X", "save exercise")),
    },
];

/// The `?` lines of [`TEACH_KEYS`] for `teach`: `p` only where it renumbers the policies
/// (they are called π0…).
pub fn help_lines(teach: &Teach) -> Vec<(&'static str, &'static str)> {
    TEACH_KEYS
        .iter()
        .filter(|b| teach.numbering().is_some() || b.keys[0].1 != T::Numbering)
        .map(|b| b.help)
        .collect()
}

/// The status bar's keys, a group to a line that offers them: with their words (`r R
/// walk run`) between dots, or, narrow, the keys alone between spaces.
pub fn bar(words: bool) -> String {
    let groups = TEACH_KEYS.iter().filter_map(|b| b.bar);
    if words {
        groups
            .map(|(keys, said)| {
                if said.is_empty() {
                    keys.to_string()
                } else {
                    format!("{keys} {said}")
                }
            })
            .collect::<Vec<_>>()
            .join(" · ")
    } else {
        groups.map(|(keys, _)| keys).collect::<Vec<_>>().join(" ")
    }
}

/// Applies a teach-mode key by [`TEACH_KEYS`] (a line being typed, `w` or `E`, takes every
/// key until Enter or Esc); `false` if it is not one.
pub fn apply_teach_key(teach: &mut Teach, key: KeyEvent) -> bool {
    if teach.prompt().is_some() {
        match key.code {
            KeyCode::Enter => teach.prompt_submit(),
            KeyCode::Esc => teach.prompt_cancel(),
            KeyCode::Backspace => teach.prompt_backspace(),
            KeyCode::Char(c) => teach.prompt_type(c),
            _ => {}
        }
        return true;
    }
    let Some(command) = keys::command(TEACH_KEYS, &key) else {
        return false;
    };
    match command {
        T::MoveCursor(delta) => teach.move_cursor(delta),
        T::Activate => teach.activate(),
        T::Step => teach.step_or_ask(),
        T::Walk => teach.animate(),
        T::Run => teach.run(),
        T::Speed { faster } => teach.change_speed(faster),
        T::Undo => teach.undo(),
        T::Reset => teach.reset(),
        T::Numbering => {
            teach.toggle_numbering();
        }
        T::Knob(knob) => teach.choose_knob(knob),
        T::Turn { up } => teach.edit(up),
        T::NextEdge => teach.next_edge(),
        T::AddEdge => teach.open_prompt(PromptKind::AddEdge),
        T::CutEdge => teach.cut_selected_edge(),
        T::Linking => teach.toggle_linking(),
        T::AddPolicy => teach.add_policy(),
        T::RemovePolicy => teach.remove_policy(),
        T::ChangeCategory => teach.change_category(),
        T::NextPanel => teach.next_panel(),
        T::Save => teach.open_prompt(PromptKind::Save),
        T::Exercise => teach.toggle_exercise(),
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each key of the table is its own: no key is listed twice, so the matcher cannot
    /// shadow a line `?` shows.
    #[test]
    fn no_key_is_listed_twice() {
        let all: Vec<keys::Key> = TEACH_KEYS
            .iter()
            .flat_map(|b| b.keys)
            .map(|&(k, _)| k)
            .collect();
        for (i, k) in all.iter().enumerate() {
            assert!(!all[..i].contains(k), "{k:?} listed twice");
        }
    }

    #[test]
    fn the_bar_offers_the_lines_in_groups_and_narrows_to_the_keys() {
        assert_eq!(bar(false), "↑↓ a s r R u c 1–5 ± E x M n D C v w X");
        assert_eq!(
            bar(true),
            "↑↓ a s · r R walk run · u c · 1–5 ± · E x M edges · n D C policy · v view · w X \
             save exercise"
        );
    }
}
