//! The Folders view: `sapnet open PARENT` on a folder that holds sapnet's folders rather
//! than being one (TensorBoard's `--logdir`, in the terminal) — every results, sweep and
//! compare folder found under it ([`crate::results::found`]), each with its task, methods,
//! runs and state; `/` filters them by what is typed, Enter opens the one picked.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::{Constraint, Rect};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Cell, Paragraph, Row, Table, Wrap};
use ratatui::Frame;

use crate::results::found::{self, Found, Search};
use crate::tui::keys::{ch, code, Binding};
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};

/// The folders found under a parent, as the view reads them.
pub struct FolderList {
    pub parent: std::path::PathBuf,
    pub search: Search,
}

impl FolderList {
    /// `found`'s folder as the list names it: its path under the parent.
    pub fn name(&self, found: &Found) -> String {
        let under = found.dir.strip_prefix(&self.parent).unwrap_or(&found.dir);
        let name = under.display().to_string();
        if name.is_empty() {
            ".".into()
        } else {
            name
        }
    }
}

/// What the view's keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FoldersCommand {
    Up,
    Down,
    Open,
    Filter,
    /// Esc with a filter: the filter goes (without one, Esc is the screen's).
    Unfilter,
}

/// What the view asks of its screen: open the folder of this index of the search.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FoldersIntent {
    Open(usize),
}

use FoldersCommand as C;

const KEYS: &[Binding<FoldersCommand>] = &[
    Binding {
        keys: &[
            (code(KeyCode::Up), C::Up),
            (ch('k'), C::Up),
            (code(KeyCode::Down), C::Down),
            (ch('j'), C::Down),
        ],
        help: ("↑ ↓ j k", "pick a folder"),
        bar: Some(("↑↓", "folder")),
    },
    Binding {
        keys: &[(code(KeyCode::Enter), C::Open)],
        help: (
            "Enter",
            "open the picked folder in its views (Esc there comes back here)",
        ),
        bar: Some(("⏎", "open")),
    },
    Binding {
        keys: &[(ch('/'), C::Filter)],
        help: (
            "/",
            "filter: type words of a path, task, method or state; Enter keeps the filter, Esc clears it",
        ),
        bar: Some(("/", "filter")),
    },
    Binding {
        keys: &[(code(KeyCode::Esc), C::Unfilter)],
        help: ("Esc", "clear the filter (without one: quit)"),
        bar: None,
    },
];

/// The list's state: the picked row (of the rows the filter keeps), the filter.
#[derive(Debug, Default)]
pub struct FoldersView {
    pub cursor: usize,
    pub filter: String,
    /// The filter is being typed.
    pub typing: bool,
}

impl FoldersView {
    /// The indices of the folders the filter keeps, in the search's order: every word
    /// typed is found (case aside) in the folder's path, kind, task, methods or state.
    pub fn shown(&self, model: &FolderList) -> Vec<usize> {
        let words: Vec<String> = self
            .filter
            .split_whitespace()
            .map(str::to_lowercase)
            .collect();
        model
            .search
            .found
            .iter()
            .enumerate()
            .filter(|(_, f)| {
                let text = format!(
                    "{} {} {} {} {}",
                    model.name(f),
                    f.kind.name(),
                    f.task,
                    f.methods.join(" "),
                    f.state
                )
                .to_lowercase();
                words.iter().all(|w| text.contains(w.as_str()))
            })
            .map(|(i, _)| i)
            .collect()
    }

    fn clamp(&mut self, model: &FolderList) {
        self.cursor = self.cursor.min(self.shown(model).len().saturating_sub(1));
    }

    /// The rows of a table of `height` lines that keep the cursor in sight.
    fn window(&self, model: &FolderList, height: usize) -> RowWindow {
        RowWindow::new(self.shown(model).len(), height, [self.cursor])
    }
}

impl View for FoldersView {
    type Model = FolderList;
    type Command = FoldersCommand;
    type Intent = FoldersIntent;

    fn keys(&self) -> &'static [Binding<FoldersCommand>] {
        KEYS
    }

    fn apply(&mut self, model: &FolderList, command: FoldersCommand) -> Outcome<FoldersIntent> {
        let shown = self.shown(model);
        match command {
            C::Up if self.cursor > 0 => self.cursor -= 1,
            C::Down if self.cursor + 1 < shown.len() => self.cursor += 1,
            C::Up | C::Down => return Outcome::Said("no folder further that way".into()),
            C::Open => {
                return match shown.get(self.cursor) {
                    Some(&i) => Outcome::Intent(FoldersIntent::Open(i)),
                    None => Outcome::Said("no folder to open: / changes the filter".into()),
                }
            }
            C::Filter => self.typing = true,
            C::Unfilter if !self.filter.is_empty() => {
                self.filter.clear();
                self.clamp(model);
            }
            C::Unfilter => return Outcome::Ignored,
        }
        Outcome::Done
    }

    /// While the filter is typed, every key but Ctrl-C is the filter's.
    fn capture(&mut self, model: &FolderList, key: &KeyEvent) -> Option<Outcome<FoldersIntent>> {
        if !self.typing || key.modifiers.contains(KeyModifiers::CONTROL) {
            return None;
        }
        match key.code {
            KeyCode::Enter => self.typing = false,
            KeyCode::Esc => {
                self.typing = false;
                self.filter.clear();
            }
            KeyCode::Backspace => {
                self.filter.pop();
            }
            KeyCode::Char(c) => self.filter.push(c),
            _ => return Some(Outcome::Done),
        }
        self.cursor = 0;
        self.clamp(model);
        Some(Outcome::Done)
    }

    fn mode_help(&self, _model: &FolderList) -> Option<Vec<(&'static str, &'static str)>> {
        self.typing.then(|| {
            vec![
                ("any character", "typed into the filter"),
                ("Backspace", "the last character out"),
                ("Enter", "keep the filter, back to the list"),
                ("Esc", "clear the filter, back to the list"),
            ]
        })
    }

    fn legend(&self, _model: &FolderList) -> Vec<(&'static str, &'static str)> {
        vec![
            ("found", "every folder sapnet wrote under the one opened, at most 4 folders down; links are not followed"),
            ("click", "a folder's line picks it"),
        ]
    }

    fn on_mouse(
        &mut self,
        model: &FolderList,
        mouse: MouseEvent,
        area: Rect,
    ) -> Outcome<FoldersIntent> {
        if mouse.kind != MouseEventKind::Down(MouseButton::Left) {
            return Outcome::Ignored;
        }
        // The border, the header row, then the rows.
        let first = area.y + 2;
        if mouse.row < first || mouse.row + 1 >= area.y + area.height {
            return Outcome::Ignored;
        }
        let height = usize::from(area.height.saturating_sub(3));
        let window = self.window(model, height);
        match window.row_at(usize::from(mouse.row - first)) {
            Some(row) => {
                self.cursor = row;
                Outcome::Done
            }
            None => Outcome::Ignored,
        }
    }

    fn draw(&self, model: &FolderList, frame: &mut Frame, area: Rect, theme: Theme) {
        let shown = self.shown(model);
        let total = model.search.found.len();
        let mut title = vec![Span::styled(" Folders ", theme.title())];
        title.push(Span::raw(if self.filter.is_empty() && !self.typing {
            format!("· {total} found ")
        } else {
            format!("· {} of {total} kept by ", shown.len())
        }));
        if self.typing || !self.filter.is_empty() {
            let cursor = if self.typing { "▏" } else { "" };
            title.push(Span::styled(
                format!("/{}{cursor} ", self.filter),
                theme.active(),
            ));
        }
        let block = Block::bordered().title(Line::from(title));
        if total == 0 {
            let text = format!(
                "No folder sapnet wrote under {} (looked {} folders down, links not \
                 followed): a results folder holds summary.json, a sweep folder sweep.ron, a \
                 compare folder comparison.csv and runs.csv.",
                model.parent.display(),
                found::MAX_DEPTH
            );
            frame.render_widget(
                Paragraph::new(text).wrap(Wrap { trim: true }).block(block),
                area,
            );
            return;
        }
        let height = usize::from(area.height.saturating_sub(3));
        let window = self.window(model, height);
        let name_width = shown
            .iter()
            .map(|&i| model.name(&model.search.found[i]).chars().count())
            .max()
            .unwrap_or(6)
            .clamp(6, 48);
        let rows: Vec<Row> = window
            .rows()
            .map(|row| {
                let f = &model.search.found[shown[row]];
                let style = if row == self.cursor {
                    theme.cursor()
                } else {
                    Style::new()
                };
                Row::new(vec![
                    Cell::from(crate::shown_text::cut(&model.name(f), name_width)),
                    Cell::from(f.kind.name()),
                    Cell::from(f.task.clone()),
                    Cell::from(f.methods.join(", ")),
                    Cell::from(f.runs.to_string()),
                    Cell::from(f.state.clone()),
                ])
                .style(style)
            })
            .collect();
        // Every column but the methods as wide as its widest cell (the state at most 40):
        // the methods take what is left, cut.
        let widest = |cell: &dyn Fn(&Found) -> usize, least: usize, most: usize| {
            shown
                .iter()
                .map(|&i| cell(&model.search.found[i]))
                .max()
                .unwrap_or(least)
                .clamp(least, most) as u16
        };
        let widths = [
            Constraint::Length(name_width as u16),
            Constraint::Length(8),
            Constraint::Length(widest(&|f| f.task.chars().count(), 4, 24)),
            Constraint::Fill(1),
            Constraint::Length(widest(&|f| f.runs.to_string().len(), 4, 8)),
            Constraint::Length(widest(&|f| f.state.chars().count(), 5, 40)),
        ];
        let header =
            Row::new(["folder", "kind", "task", "methods", "runs", "state"]).style(theme.title());
        let mut block = block;
        if let Some(cut) = &model.search.cut {
            block = block.title_bottom(Span::styled(format!(" {cut} "), theme.dim()));
        }
        frame.render_widget(
            Table::new(rows, widths)
                .header(header)
                .block(block)
                .column_spacing(2),
            area,
        );
    }
}
