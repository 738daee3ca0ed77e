//! What the keys and the mouse do to the dashboard, and to teach mode inside it.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

use crate::teach::knobs::Knob;
use crate::teach::session::PromptKind;
use crate::teach::Teach;
use crate::trainer::Command;

use super::{Dashboard, Focus, Mode, SPEEDS};
use crate::tui::graph_layout;

/// What the UI loop must do after a key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    None,
    /// Send this to the followed run (or the only run).
    Send(Command),
    /// Pause or resume every run.
    SendAll(Command),
    /// Stop following this method's run and follow the next method's same run instead.
    FollowNext,
    Quit,
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

impl Dashboard {
    /// The number of policies the arrows move over.
    fn policy_count(&self) -> usize {
        self.library.as_ref().map_or(0, |v| v.policies.len())
    }

    /// What `key` does. Keys in teach mode go to [`Teach`]; `t` or Esc leaves it.
    pub fn on_key(&mut self, key: KeyEvent) -> Action {
        let ctrl_c =
            key.code == KeyCode::Char('c') && key.modifiers.contains(KeyModifiers::CONTROL);
        let typing = self.teach.as_ref().is_some_and(|t| t.prompt().is_some());
        if ctrl_c || (key.code == KeyCode::Char('q') && !typing) {
            return Action::Quit;
        }
        self.notice = None;
        if self.help {
            // Any key closes the help overlay.
            self.help = false;
            return Action::None;
        }
        if self.mode == Mode::Teach {
            return self.on_teach_key(key);
        }
        match key.code {
            KeyCode::Esc => Action::Quit,
            KeyCode::Char('?') => {
                self.help = true;
                Action::None
            }
            KeyCode::Char(' ') => match self.mode {
                Mode::Running => {
                    self.mode = Mode::Paused;
                    Action::SendAll(Command::Pause)
                }
                _ => {
                    self.mode = Mode::Running;
                    Action::SendAll(Command::Resume)
                }
            },
            KeyCode::Char('n') if self.mode == Mode::Paused => Action::Send(Command::Step),
            KeyCode::Char('m') => Action::FollowNext,
            KeyCode::Char('+') | KeyCode::Char('=') if self.speed == 0 => {
                self.notice = Some("already at full speed");
                Action::None
            }
            KeyCode::Char('-') if self.speed == SPEEDS.len() - 1 => {
                self.notice = Some("already at the slowest speed");
                Action::None
            }
            KeyCode::Char('+') | KeyCode::Char('=') => self.set_speed(self.speed - 1),
            KeyCode::Char('-') => self.set_speed(self.speed + 1),
            KeyCode::Tab => {
                self.focus = match self.focus {
                    Focus::Table => Focus::Graph,
                    Focus::Graph => Focus::Table,
                };
                Action::None
            }
            KeyCode::Up | KeyCode::Char('k') => self.move_toward(-1, (0.0, 1.0)),
            KeyCode::Down | KeyCode::Char('j') => self.move_toward(1, (0.0, -1.0)),
            KeyCode::Left | KeyCode::Char('h') => self.move_toward(-1, (-1.0, 0.0)),
            KeyCode::Right | KeyCode::Char('l') => self.move_toward(1, (1.0, 0.0)),
            KeyCode::Char('t') => self.enter_teach(),
            KeyCode::Char('v') => {
                self.relative = !self.relative;
                Action::None
            }
            KeyCode::Char('z') => {
                self.zoom = !self.zoom;
                Action::None
            }
            _ => Action::None,
        }
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
        if self.help {
            return;
        }
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
            return Action::None;
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

    fn on_teach_key(&mut self, key: KeyEvent) -> Action {
        let Some(teach) = &mut self.teach else {
            self.mode = Mode::Paused;
            return Action::None;
        };
        if !apply_teach_key(teach, key) {
            match key.code {
                KeyCode::Char('t') | KeyCode::Esc => {
                    // Back to the paused dashboard: the copy's activations are discarded,
                    // training resumes from its own on space.
                    self.teach = None;
                    self.mode = Mode::Paused;
                    self.notice = Some("training is still paused: space resumes it");
                }
                KeyCode::Char('?') => self.help = true,
                _ => {}
            }
        }
        Action::None
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
