//! `sapnet open`'s screen: the workbench's views of a folder, or the dashboard of one of
//! its finished runs, made from the run's files ([`super::recorded`]): Enter in the Runs
//! view shows it; `r` and `c` come back, as from a session's Run view (the dashboard keeps
//! its own keys, `v` among them). Nothing is written: the folder is only read.

use crossterm::event::{KeyCode, KeyEvent, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Clear, Paragraph};
use ratatui::Frame;

use super::session::RunKey;
use super::session_view;
use super::state::{Action, View, Workbench};
use super::{mouse, recorded, view};
use crate::tui::dashboard::{Action as DashboardAction, Dashboard, Mode};
use crate::tui::dashboard_view;
use crate::tui::screen;
use crate::tui::theme::Theme;

/// The keys `sapnet open` adds to the workbench's.
const OPEN_KEYS: [(&str, &str); 1] = [(
    "Enter",
    "Runs: the finished run under the cursor on its dashboard, made from its files (r and c \
     come back)",
)];

/// The workbench, and the finished run shown on its dashboard, if one is.
pub struct Opened {
    pub workbench: Workbench,
    pub run: Option<(RunKey, Dashboard)>,
    /// Why the last key did nothing, shown until the next key.
    pub notice: Option<String>,
}

impl Opened {
    pub fn new(mut workbench: Workbench) -> Self {
        workbench.host_bar = vec![("⏎", "dashboard")];
        workbench.host_overlay = OPEN_KEYS.to_vec();
        Self {
            workbench,
            run: None,
            notice: None,
        }
    }

    pub fn on_key(&mut self, key: KeyEvent) -> Action {
        self.notice = None;
        if let Some((_, dashboard)) = &mut self.run {
            let teaching = dashboard.mode == Mode::Teach || dashboard.help;
            if !teaching && matches!(key.code, KeyCode::Char('r' | 'c')) {
                self.run = None;
                return self.workbench.on_key(key);
            }
            // The run ended: what the dashboard would send a training run goes nowhere.
            return match dashboard.on_key(key) {
                DashboardAction::Quit => Action::Quit,
                _ => Action::None,
            };
        }
        let workbench = &self.workbench;
        if key.code == KeyCode::Enter && workbench.view == View::Runs && !workbench.help {
            self.show_cursor_run();
            return Action::None;
        }
        self.workbench.on_key(key)
    }

    /// The run under the Runs view's cursor on its dashboard, if it finished.
    fn show_cursor_run(&mut self) {
        let folder = &self.workbench.folder;
        let Some(row) = folder.runs.get(self.workbench.run_cursor) else {
            return;
        };
        let label = row.method.label().to_string();
        if folder.finished(&row.method, row.run).is_none() {
            self.notice = Some(format!(
                "{label} run {} is {}: a run's dashboard is made from the files of its end",
                row.run,
                row.status.name()
            ));
            return;
        }
        let task = folder.config.env.gym_id();
        match recorded::dashboard(folder, &row.method, row.run, &task, &[]) {
            Ok(dashboard) => self.run = Some(((label, row.run), dashboard)),
            Err(error) => self.notice = Some(format!("{error:#}")),
        }
    }

    /// A mouse event on a `screen`-sized terminal: a left click on the dashboard's panels,
    /// or whatever the workbench's views do with it.
    pub fn on_mouse(&mut self, mouse: MouseEvent, screen: Rect) {
        let Some((_, dashboard)) = &mut self.run else {
            mouse::on_mouse(&mut self.workbench, mouse, screen);
            return;
        };
        if mouse.kind != MouseEventKind::Down(MouseButton::Left) {
            return;
        }
        let below = session_view::dashboard_area(screen);
        if let Some(clicked) = dashboard_view::clicked(dashboard, below, mouse.column, mouse.row) {
            dashboard.on_click(clicked);
        }
    }
}

pub fn draw(frame: &mut Frame, opened: &Opened, theme: Theme) {
    let area = frame.area();
    if screen::too_small(frame, area) {
        return;
    }
    match &opened.run {
        None => view::draw(frame, &opened.workbench, theme),
        Some(((method, run), dashboard)) => {
            session_view::draw_dashboard_at(
                frame,
                session_view::dashboard_area(area),
                dashboard,
                theme,
            );
            let top = Rect::new(area.x, area.y, area.width, 1);
            frame.render_widget(Clear, top);
            let mut spans = vec![
                Span::styled(format!(" ▶ {method} run {run} "), theme.title()),
                Span::raw(format!(
                    "· {} · read from its files",
                    opened.workbench.folder.dir.display()
                )),
                Span::styled("  │ ", theme.dim()),
            ];
            for (key, what) in [("r", "runs"), ("c", "comparison")] {
                spans.push(Span::styled(key, theme.title()));
                spans.push(Span::raw(format!(" {what}  ")));
            }
            frame.render_widget(Paragraph::new(Line::from(spans)), top);
        }
    }
    if let Some(notice) = &opened.notice {
        session_view::draw_notice(frame, area, notice, theme);
    }
}
