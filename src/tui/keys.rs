//! One key table per view: each line of a table is a group of keys with the line `?` gives
//! them and the words the status bar gives them, beside what each key does. The matcher,
//! the status bar and the `?` overlay are all read from the table (gitui's `key_config`
//! beside its `strings::commands`), so a key is written once and the three cannot
//! disagree; `tests/it/key_tables.rs` sends every key of every table.
//!
//! What every screen shares is here too: `?` for the keys, `q` (Esc, Ctrl-C) for quitting,
//! and what a key does while `?`'s overlay is up.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

/// A key a table lists: a code, with Control or without. Shift is part of the character
/// (`L`, `R`), Alt is not looked at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Key {
    pub code: KeyCode,
    pub ctrl: bool,
}

/// A character key.
pub const fn ch(c: char) -> Key {
    Key {
        code: KeyCode::Char(c),
        ctrl: false,
    }
}

/// A key that is not a character (Enter, Esc, the arrows, Tab…).
pub const fn code(code: KeyCode) -> Key {
    Key { code, ctrl: false }
}

/// Control and a character.
pub const fn ctrl(c: char) -> Key {
    Key {
        code: KeyCode::Char(c),
        ctrl: true,
    }
}

impl Key {
    pub fn matches(self, event: &KeyEvent) -> bool {
        // Ctrl-C is not `c` (the Comparison), nor Ctrl-R `r`.
        self.code == event.code && self.ctrl == event.modifiers.contains(KeyModifiers::CONTROL)
    }

    /// The key as a terminal sends it (what the tests press).
    pub fn event(self) -> KeyEvent {
        let modifiers = if self.ctrl {
            KeyModifiers::CONTROL
        } else if self.code == KeyCode::BackTab {
            KeyModifiers::SHIFT
        } else {
            KeyModifiers::NONE
        };
        KeyEvent::new(self.code, modifiers)
    }
}

/// One line of a table: its keys, each with what it does, and how `?` and the status bar
/// say them.
#[derive(Debug, Clone, Copy)]
pub struct Binding<C: 'static> {
    pub keys: &'static [(Key, C)],
    /// The keys as `?` lists them, and what they do.
    pub help: (&'static str, &'static str),
    /// The keys and what they do in the status bar's few words, if the bar may offer them.
    pub bar: Option<(&'static str, &'static str)>,
}

/// What `key` does by `table`, if it lists it.
pub fn command<C: Copy>(table: &[Binding<C>], key: &KeyEvent) -> Option<C> {
    table
        .iter()
        .flat_map(|b| b.keys)
        .find(|(k, _)| k.matches(key))
        .map(|&(_, c)| c)
}

/// The binding of `command` (a line's first command names the line).
pub fn binding<C: PartialEq>(table: &[Binding<C>], command: C) -> Option<&Binding<C>> {
    table
        .iter()
        .find(|b| b.keys.first().is_some_and(|(_, c)| *c == command))
}

/// The lines `?` lists for `table`, in its order.
pub fn help_lines<C>(table: &[Binding<C>]) -> Vec<(&'static str, &'static str)> {
    table.iter().map(|b| b.help).collect()
}

/// `?`: every key; the overlay closes on any key.
pub const HELP_BAR: (&str, &str) = ("?", "keys");
pub const HELP_LINE: (&str, &str) = ("?", "every key (any key closes this; q still quits)");

/// Quitting, on every screen: `q`, Esc on a view (Esc closes an overlay or leaves a mode
/// first), Ctrl-C; as a screen's table lists them, each doing its `quit`.
pub const fn quit_keys<C: Copy>(quit: C) -> [(Key, C); 3] {
    [
        (ch('q'), quit),
        (code(KeyCode::Esc), quit),
        (ctrl('c'), quit),
    ]
}
pub const QUIT_BAR: (&str, &str) = ("q", "quit");
pub const QUIT_KEYS_SAID: &str = "q, Esc, Ctrl-C";
/// `?`'s line for quitting a screen that only reads its folder.
pub const QUIT_READING: (&str, &str) = (
    QUIT_KEYS_SAID,
    "quit (the folder is only read: nothing in it changes)",
);

/// What a key does while `?`'s overlay is up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OnHelp {
    /// `q` or Ctrl-C: the screen quits as it always does (asking first while a protocol
    /// trains).
    Quit,
    /// Any other key, Esc included, closes the overlay and does nothing else.
    Close,
}

pub fn on_help(key: &KeyEvent) -> OnHelp {
    if [ch('q'), ctrl('c')].iter().any(|k| k.matches(key)) {
        OnHelp::Quit
    } else {
        OnHelp::Close
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Did {
        Up,
        Down,
        Comparison,
    }

    const TABLE: &[Binding<Did>] = &[
        Binding {
            keys: &[(code(KeyCode::Up), Did::Up), (ch('j'), Did::Down)],
            help: ("↑ j", "move"),
            bar: Some(("↑j", "move")),
        },
        Binding {
            keys: &[(ch('c'), Did::Comparison)],
            help: ("c", "Comparison"),
            bar: None,
        },
    ];

    #[test]
    fn a_key_is_found_by_its_code_and_control() {
        assert_eq!(command(TABLE, &ch('j').event()), Some(Did::Down));
        assert_eq!(command(TABLE, &code(KeyCode::Up).event()), Some(Did::Up));
        assert_eq!(command(TABLE, &ch('c').event()), Some(Did::Comparison));
        assert_eq!(command(TABLE, &ctrl('c').event()), None, "Ctrl-C is not c");
        assert_eq!(binding(TABLE, Did::Up).map(|b| b.help.0), Some("↑ j"));
        assert_eq!(binding(TABLE, Did::Down).map(|b| b.help.0), None);
        assert_eq!(help_lines(TABLE), [("↑ j", "move"), ("c", "Comparison")]);
    }

    #[test]
    fn on_help_q_and_ctrl_c_quit_and_esc_closes() {
        assert_eq!(on_help(&ch('q').event()), OnHelp::Quit);
        assert_eq!(on_help(&ctrl('c').event()), OnHelp::Quit);
        assert_eq!(on_help(&code(KeyCode::Esc).event()), OnHelp::Close);
        assert_eq!(on_help(&ch(' ').event()), OnHelp::Close);
    }
}
