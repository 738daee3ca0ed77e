//! What the keys and the mouse do to the dashboard (the Run view's state), and to teach
//! mode inside it. Its keys are one table, [`KEYS`]: the Run view matches it, the
//! dashboard's status bar and the Run view's `?` are made from it.

use crossterm::event::{KeyCode, KeyEvent};

use crate::teach::knobs::Knob;
use crate::teach::session::PromptKind;
use crate::teach::Teach;
use crate::trainer::Command;

use super::{Dashboard, Focus, Mode, SPEEDS};
use crate::tui::graph_layout;
use crate::tui::keys::{self, ch, code, Binding};

/// What the UI loop must do after a key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    None,
    /// Send this to the followed run (or the only run).
    Send(Command),
    /// Pause or resume the run (in a protocol's session, the followed one only).
    SendAll(Command),
    /// Follow the next run that trains now instead.
    FollowNext,
}

/// What a left click landed on, as the view that drew the screen tells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clicked {
    /// The policy table, on a policy's row or elsewhere in the panel.
    Table(Option<usize>),
    /// The graph, on a policy's node or between them.
    Graph(Option<usize>),
    /// A policy of teach mode's panels.
    Teach(usize),
}

/// What the dashboard's keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DashboardCommand {
    PauseResume,
    Step,
    Faster,
    Slower,
    Focus,
    Up,
    Down,
    Left,
    Right,
    Zoom,
    FollowNext,
    Relative,
    Teach,
}

use DashboardCommand as D;

/// The dashboard's keys, the Run view's own (the tabs, `?` and quitting are its screen's).
pub const KEYS: &[Binding<DashboardCommand>] = &[
    Binding {
        keys: &[(ch(' '), D::PauseResume)],
        help: (
            "space",
            "pause / resume the followed run (the others train on)",
        ),
        bar: Some(("space", "pause")),
    },
    Binding {
        keys: &[(ch('n'), D::Step)],
        help: ("n", "one training step while paused"),
        bar: Some(("n", "step")),
    },
    Binding {
        keys: &[
            (ch('+'), D::Faster),
            (ch('='), D::Faster),
            (ch('-'), D::Slower),
        ],
        help: (
            "+ / -",
            "faster / slower (delays training, never the screen)",
        ),
        bar: None,
    },
    Binding {
        keys: &[(code(KeyCode::Tab), D::Focus)],
        help: ("tab", "focus the graph or the table"),
        bar: None,
    },
    Binding {
        keys: &[
            (code(KeyCode::Up), D::Up),
            (ch('k'), D::Up),
            (code(KeyCode::Down), D::Down),
            (ch('j'), D::Down),
            (code(KeyCode::Left), D::Left),
            (ch('h'), D::Left),
            (code(KeyCode::Right), D::Right),
            (ch('l'), D::Right),
        ],
        help: (
            "↑↓←→ hjkl",
            "pick a policy (graph: the nearest node that way)",
        ),
        bar: None,
    },
    Binding {
        keys: &[(ch('z'), D::Zoom)],
        help: ("z", "enlarge the focused panel, or back"),
        bar: None,
    },
    Binding {
        keys: &[(ch('m'), D::FollowNext)],
        help: ("m", "the next run training (the one left runs full speed)"),
        bar: Some(("m", "next run")),
    },
    Binding {
        keys: &[(ch('d'), D::Relative)],
        help: ("d", "scores as A − max(A), readable when A saturates"),
        bar: None,
    },
    Binding {
        keys: &[(ch('t'), D::Teach)],
        help: ("t", "teach mode on the live graph (pauses; t or Esc: back)"),
        bar: Some(("t", "teach")),
    },
];

impl Dashboard {
    /// The number of policies the arrows move over.
    fn policy_count(&self) -> usize {
        self.library.as_ref().map_or(0, |v| v.policies.len())
    }

    /// What `key` does to the dashboard alone: teach mode's keys while it is on, else
    /// [`KEYS`]; `Action::None` for a key of neither (the screen's: `?`, `q`, the tabs).
    /// The Run view matches the same table and offers the rest to its screen.
    pub fn on_key(&mut self, key: KeyEvent) -> Action {
        self.notice = None;
        if let Some(action) = self.teach_key(&key) {
            return action;
        }
        keys::command(KEYS, &key).map_or(Action::None, |command| self.apply(command))
    }

    /// The bar's words for `command` now: space pauses or resumes.
    pub fn bar_words(&self, command: DashboardCommand) -> Option<&'static str> {
        (command == D::PauseResume && self.mode == Mode::Paused).then_some("resume")
    }

    /// What a command of [`KEYS`] does.
    pub fn apply(&mut self, command: DashboardCommand) -> Action {
        match command {
            D::PauseResume => match self.mode {
                Mode::Running => {
                    self.mode = Mode::Paused;
                    Action::SendAll(Command::Pause)
                }
                _ => {
                    self.mode = Mode::Running;
                    Action::SendAll(Command::Resume)
                }
            },
            D::Step if self.mode == Mode::Paused => Action::Send(Command::Step),
            D::Step => self.said("n steps while paused: space pauses first"),
            D::Faster if self.speed == 0 => self.said("already at full speed"),
            D::Slower if self.speed == SPEEDS.len() - 1 => {
                self.said("already at the slowest speed")
            }
            D::Faster => self.set_speed(self.speed - 1),
            D::Slower => self.set_speed(self.speed + 1),
            D::Focus => {
                self.focus = match self.focus {
                    Focus::Table => Focus::Graph,
                    Focus::Graph => Focus::Table,
                };
                Action::None
            }
            D::Up => self.move_toward(-1, (0.0, 1.0)),
            D::Down => self.move_toward(1, (0.0, -1.0)),
            D::Left => self.move_toward(-1, (-1.0, 0.0)),
            D::Right => self.move_toward(1, (1.0, 0.0)),
            D::Teach => self.enter_teach(),
            D::FollowNext => Action::FollowNext,
            D::Relative => {
                self.relative = !self.relative;
                Action::None
            }
            D::Zoom => {
                self.zoom = !self.zoom;
                Action::None
            }
        }
    }

    fn said(&mut self, notice: &'static str) -> Action {
        self.notice = Some(notice);
        Action::None
    }

    fn set_speed(&mut self, speed: usize) -> Action {
        self.speed = speed;
        Action::Send(Command::Throttle(SPEEDS[speed]))
    }

    /// An arrow: in the table the previous or next row (`delta`), in the graph the
    /// nearest node in `direction` on screen.
    fn move_toward(&mut self, delta: isize, direction: (f64, f64)) -> Action {
        match (&self.library, self.focus) {
            (Some(view), Focus::Graph) => {
                let positions =
                    graph_layout::positions(view.policies.len(), Some(&view.categories()));
                if let Some(next) = graph_layout::nearest_ahead(&positions, self.cursor, direction)
                {
                    self.cursor = next;
                }
            }
            _ => self.move_cursor(delta),
        }
        Action::None
    }

    /// A left click, found by the view under the mouse ([`super::click`]): picks the
    /// policy clicked, if any, and focuses its panel.
    pub fn on_click(&mut self, clicked: Clicked) {
        match clicked {
            Clicked::Teach(i) => {
                if let Some(teach) = &mut self.teach {
                    teach.pick(i);
                }
            }
            Clicked::Table(row) => {
                self.cursor = row.unwrap_or(self.cursor);
                self.focus = Focus::Table;
            }
            Clicked::Graph(node) => {
                self.cursor = node.unwrap_or(self.cursor);
                self.focus = Focus::Graph;
            }
        }
    }

    fn move_cursor(&mut self, delta: isize) {
        let n = self.policy_count() as isize;
        if n > 0 {
            self.cursor = (self.cursor as isize + delta).rem_euclid(n) as usize;
        }
    }

    /// `t`: pauses training and steps spreading by hand on a copy of the live net.
    fn enter_teach(&mut self) -> Action {
        let Some(view) = &self.library else {
            return self.said("teach mode needs a library's graph: this run reuses none");
        };
        let names = view.policies.iter().map(|p| p.name.clone()).collect();
        let mut teach = Teach::new(names, view.net.clone())
            .with_groups(view.categories())
            .with_excluded(view.excluded.clone());
        teach.move_cursor(self.cursor as isize);
        self.teach = Some(teach);
        let was_running = self.mode == Mode::Running;
        self.mode = Mode::Teach;
        if was_running {
            Action::SendAll(Command::Pause)
        } else {
            Action::None
        }
    }

    /// Teach mode takes every key but `?`, `q` and Ctrl-C (its screen's: the help, which
    /// then lists teach mode's keys, and quitting), and while a line is typed every key but
    /// Ctrl-C: what it did, or `None` outside teach mode and for those keys.
    pub fn teach_key(&mut self, key: &KeyEvent) -> Option<Action> {
        if self.mode != Mode::Teach {
            return None;
        }
        let Some(teach) = &mut self.teach else {
            self.mode = Mode::Paused;
            return Some(Action::None);
        };
        if keys::ctrl('c').matches(key) {
            return None;
        }
        if teach.prompt().is_some() {
            apply_teach_key(teach, *key);
            return Some(Action::None);
        }
        if [ch('q'), ch('?')].iter().any(|k| k.matches(key)) {
            return None;
        }
        if !apply_teach_key(teach, *key) && matches!(key.code, KeyCode::Char('t') | KeyCode::Esc) {
            // Back to the paused dashboard: the copy's activations are discarded, training
            // resumes from its own on space.
            self.teach = None;
            self.mode = Mode::Paused;
            self.notice = Some("training is still paused: space resumes it");
        }
        Some(Action::None)
    }
}

/// Applies a teach-mode key (arrows, `a`, `s`, `r`, `R`, `<`, `>`, `v`, `u`, `c`, `p`, the edits `1`…`5`, `+`,
/// `−`, `e`, the graph's `E`, `x`, `n`, `D`, `C`, `M`, `w`, `X`); `false` if it is not one.
pub fn apply_teach_key(teach: &mut Teach, key: KeyEvent) -> bool {
    // A line being typed takes every key until Enter or Esc.
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
    match key.code {
        KeyCode::Char('w') => teach.open_prompt(PromptKind::Save),
        KeyCode::Char('E') => teach.open_prompt(PromptKind::AddEdge),
        KeyCode::Char('x') => teach.cut_selected_edge(),
        KeyCode::Char('n') => teach.add_policy(),
        KeyCode::Char('D') => teach.remove_policy(),
        KeyCode::Char('C') => teach.change_category(),
        KeyCode::Char('M') => teach.toggle_linking(),
        KeyCode::Char(c) if Knob::from_key(c).is_some() => {
            teach.choose_knob(Knob::from_key(c).expect("checked"));
        }
        KeyCode::Char('+') | KeyCode::Char('=') => teach.edit(true),
        KeyCode::Char('-') => teach.edit(false),
        KeyCode::Char('e') => teach.next_edge(),
        KeyCode::Up | KeyCode::Char('k') | KeyCode::Left | KeyCode::Char('h') => {
            teach.move_cursor(-1)
        }
        KeyCode::Down | KeyCode::Char('j') | KeyCode::Right | KeyCode::Char('l') => {
            teach.move_cursor(1)
        }
        KeyCode::Char('a') => teach.activate(),
        KeyCode::Char('s') => teach.step_or_ask(),
        KeyCode::Char('X') => teach.toggle_exercise(),
        KeyCode::Char('r') => teach.animate(),
        KeyCode::Char('R') => teach.run(),
        KeyCode::Char('<') | KeyCode::Char(',') => teach.change_speed(false),
        KeyCode::Char('>') | KeyCode::Char('.') => teach.change_speed(true),
        KeyCode::Char('v') => teach.next_panel(),
        KeyCode::Char('u') => teach.undo(),
        KeyCode::Char('c') => teach.reset(),
        KeyCode::Char('p') => {
            teach.toggle_numbering();
        }
        _ => return false,
    }
    true
}
