//! `L`'s picker: the training configs shipped in `assets/` (each with the first line of
//! its opening comment), or a path typed by hand. Lessons and sweep grids, which the
//! folder holds too, are left out and counted: they are not protocols.

use std::path::{Path, PathBuf};

use crossterm::event::{KeyCode, KeyEvent};

use crate::config::Config;

/// A config the picker offers.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    pub path: PathBuf,
    /// The first line of its opening comment, or nothing.
    pub about: String,
}

/// What a key did to the picker.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Picked {
    Nothing,
    Closed,
    /// Launch this config.
    Config(PathBuf),
}

/// The picker's state.
#[derive(Debug, Clone, PartialEq)]
pub struct Picker {
    /// Where the configs were looked for.
    pub dir: PathBuf,
    pub entries: Vec<Entry>,
    /// Files there that are not training configs (lessons, grids).
    pub left_out: usize,
    /// The row picked; `entries.len()` is the last row, "a path…".
    pub cursor: usize,
    /// The path being typed, once the last row was chosen.
    pub typing: Option<String>,
    /// Why the config last picked was not launched: the file, the field, what was
    /// expected.
    pub error: Option<String>,
}

impl Picker {
    /// The configs of `./assets`, else of the source tree's `assets/` (a binary run from
    /// its checkout's `target/`).
    pub fn open() -> Self {
        let here = PathBuf::from("assets");
        let dir = if here.is_dir() {
            here
        } else {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets")
        };
        Self::of(&dir)
    }

    /// The training configs in `dir`, sorted by name.
    pub fn of(dir: &Path) -> Self {
        let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
            .map(|entries| {
                entries
                    .flatten()
                    .map(|e| e.path())
                    .filter(|p| p.extension().is_some_and(|e| e == "ron") && p.is_file())
                    .collect()
            })
            .unwrap_or_default();
        paths.sort();
        let mut entries = Vec::new();
        let mut left_out = 0;
        for path in paths {
            let Ok(text) = crate::ron_file::read_text(&path) else {
                left_out += 1;
                continue;
            };
            if Config::from_ron(&text, &path.display().to_string()).is_err() {
                left_out += 1;
                continue;
            }
            entries.push(Entry {
                about: first_comment_line(&text),
                path,
            });
        }
        Self {
            dir: dir.to_path_buf(),
            entries,
            left_out,
            cursor: 0,
            typing: None,
            error: None,
        }
    }

    pub fn on_key(&mut self, key: KeyEvent) -> Picked {
        if let Some(typed) = &mut self.typing {
            match key.code {
                KeyCode::Esc => self.typing = None,
                KeyCode::Backspace => {
                    typed.pop();
                }
                KeyCode::Enter if !typed.trim().is_empty() => {
                    return Picked::Config(PathBuf::from(typed.trim()));
                }
                KeyCode::Char(c) => typed.push(c),
                _ => {}
            }
            return Picked::Nothing;
        }
        let rows = self.entries.len() + 1;
        match key.code {
            KeyCode::Esc | KeyCode::Char('q') => return Picked::Closed,
            KeyCode::Up | KeyCode::Char('k') => self.cursor = (self.cursor + rows - 1) % rows,
            KeyCode::Down | KeyCode::Char('j') => self.cursor = (self.cursor + 1) % rows,
            KeyCode::Enter => match self.entries.get(self.cursor) {
                Some(entry) => return Picked::Config(entry.path.clone()),
                None => self.typing = Some(String::new()),
            },
            _ => {}
        }
        Picked::Nothing
    }
}

/// The first line of a config's opening `//` comment, without its slashes.
fn first_comment_line(text: &str) -> String {
    text.lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .and_then(|l| l.strip_prefix("//"))
        .map_or(String::new(), |l| l.trim().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crossterm::event::KeyModifiers;

    fn key(code: KeyCode) -> KeyEvent {
        KeyEvent::new(code, KeyModifiers::NONE)
    }

    #[test]
    fn the_shipped_configs_are_offered_with_their_first_comment_line() {
        let picker = Picker::of(&Path::new(env!("CARGO_MANIFEST_DIR")).join("assets"));
        let reuse = picker
            .entries
            .iter()
            .find(|e| e.path.ends_with("reuse_cartpole.ron"))
            .expect("reuse_cartpole.ron is offered");
        assert_eq!(
            reuse.about,
            "Policy reuse compared on CartPole-v1: the paper's settings (Tables I and II) and its"
        );
        // The lessons and the sweep grids are not protocols.
        for not in ["teach_fig2.ron", "teach_table2.ron", "sweep_example.ron"] {
            assert!(
                !picker.entries.iter().any(|e| e.path.ends_with(not)),
                "{not} offered"
            );
        }
        assert!(picker.left_out >= 3, "{}", picker.left_out);
    }

    #[test]
    fn the_last_row_takes_a_typed_path() {
        let mut picker = Picker {
            dir: PathBuf::from("assets"),
            entries: vec![Entry {
                path: PathBuf::from("assets/a.ron"),
                about: String::new(),
            }],
            left_out: 0,
            cursor: 0,
            typing: None,
            error: None,
        };
        assert_eq!(
            picker.on_key(key(KeyCode::Enter)),
            Picked::Config(PathBuf::from("assets/a.ron"))
        );
        picker.on_key(key(KeyCode::Up));
        assert_eq!(picker.cursor, 1);
        assert_eq!(picker.on_key(key(KeyCode::Enter)), Picked::Nothing);
        for c in "my.ron".chars() {
            picker.on_key(key(KeyCode::Char(c)));
        }
        // `q` types a q while a path is typed.
        picker.on_key(key(KeyCode::Char('q')));
        picker.on_key(key(KeyCode::Backspace));
        assert_eq!(
            picker.on_key(key(KeyCode::Enter)),
            Picked::Config(PathBuf::from("my.ron"))
        );
        picker.on_key(key(KeyCode::Esc));
        assert_eq!(picker.on_key(key(KeyCode::Esc)), Picked::Closed);
    }
}
