//! Drawing a protocol run in the UI: the workbench's views (drawn by [`super::view`]) or
//! the Run view (the followed run's dashboard under a line saying where the protocol is),
//! and over them the stop question, `L`'s picker and the last key's notice. Pure
//! functions of [`Session`].

use ratatui::backend::TestBackend;
use ratatui::layout::{Constraint, Layout, Position, Rect};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Wrap};
use ratatui::{Frame, Terminal};

use super::picker::Picker;
use super::session::{Overlay, Phase, Screen, Session};
use super::view;
use crate::results::Status;
use crate::tui::dashboard::{Clicked, Dashboard};
use crate::tui::dashboard_view;
use crate::tui::screen;
use crate::tui::theme::Theme;

pub fn draw(frame: &mut Frame, session: &Session, theme: Theme) {
    let area = frame.area();
    if screen::too_small(frame, area) {
        return;
    }
    match (session.screen, &session.workbench) {
        (Screen::Views, Some(workbench)) => view::draw(frame, workbench, theme),
        (Screen::Views, None) => draw_preparing(frame, area, session, theme),
        (Screen::Run, _) => draw_run(frame, area, session, theme),
    }
    match &session.overlay {
        Some(Overlay::Stop { then_quit }) => draw_stop_question(frame, area, *then_quit, theme),
        Some(Overlay::Picker(picker)) => draw_picker(frame, area, picker, theme),
        None => {}
    }
    if let Some(notice) = &session.notice {
        draw_notice(frame, area, notice, theme);
    }
}

/// What the last key did or why it did nothing, over the status bar.
pub fn draw_notice(frame: &mut Frame, area: Rect, notice: &str, theme: Theme) {
    let bar = Rect::new(area.x, area.bottom() - 1, area.width, 1);
    frame.render_widget(Clear, bar);
    frame.render_widget(
        Paragraph::new(Line::from(Span::styled(
            format!(" {notice}"),
            theme.active(),
        ))),
        bar,
    );
}

/// The area the followed run's dashboard takes in the Run view: all but the top line; on
/// the smallest terminal the dashboard needs, all of it (the line then takes the panels'
/// top border).
pub fn dashboard_area(area: Rect) -> Rect {
    if area.height <= screen::MIN_HEIGHT {
        return area;
    }
    Rect::new(
        area.x,
        area.y + 1,
        area.width,
        area.height.saturating_sub(1),
    )
}

/// What a left click in the Run view lands on, in the rectangles the dashboard was drawn in.
pub fn clicked(session: &Session, area: Rect, column: u16, row: u16) -> Option<Clicked> {
    if session.screen != Screen::Run || session.overlay.is_some() {
        return None;
    }
    let run = session.followed_run()?;
    dashboard_view::clicked(&run.dashboard, dashboard_area(area), column, row)
}

/// The protocol's state in a few words.
fn phase_words(session: &Session) -> String {
    match &session.phase {
        Phase::Running => "training".into(),
        Phase::Stopping => "stopping: the runs finish their step…".into(),
        Phase::Ended(Status::Complete) => "complete".into(),
        Phase::Ended(Status::Stopped) => "stopped: R resumes it".into(),
        Phase::Ended(status) => format!("{status:?}").to_lowercase(),
        Phase::Failed(error) => format!("failed: {error}"),
        Phase::Idle => session
            .workbench
            .as_ref()
            .map_or(String::new(), |w| view::protocol_state(&w.folder)),
    }
}

/// The Run view: a line for the protocol, then the followed run's dashboard, drawn off
/// screen at its own size and copied below the line (the dashboard fills whatever frame
/// it is given).
fn draw_run(frame: &mut Frame, area: Rect, session: &Session, theme: Theme) {
    let [top, _] = Layout::vertical([Constraint::Length(1), Constraint::Fill(1)]).areas::<2>(area);
    let below = dashboard_area(area);
    draw_dashboard_in(frame, below, session, theme);
    frame.render_widget(Clear, top);
    frame.render_widget(Paragraph::new(run_line(session, theme)), top);
}

/// The followed run's dashboard in `below`, or why there is none.
fn draw_dashboard_in(frame: &mut Frame, below: Rect, session: &Session, theme: Theme) {
    let Some(run) = session.followed_run() else {
        let text = match &session.followed {
            Some((method, run)) => format!(
                "{method} run {run} has not started: its library is loading, or it waits \
                 for a free job. r lists the runs; Enter on a running one follows it."
            ),
            None => "No run is followed: r lists the runs; Enter on a running one follows it."
                .to_string(),
        };
        frame.render_widget(
            Paragraph::new(text)
                .wrap(Wrap { trim: true })
                .block(Block::bordered().border_style(theme.dim())),
            below,
        );
        return;
    };
    draw_dashboard_at(frame, below, &run.dashboard, theme);
}

/// `dashboard` in `below`, drawn off screen at that size and copied in (the dashboard fills
/// whatever frame it is given).
pub fn draw_dashboard_at(frame: &mut Frame, below: Rect, dashboard: &Dashboard, theme: Theme) {
    let Ok(mut off_screen) = Terminal::new(TestBackend::new(below.width, below.height));
    if off_screen
        .draw(|f| dashboard_view::draw_dashboard(f, dashboard, theme))
        .is_err()
    {
        return;
    }
    let drawn = off_screen.backend().buffer();
    let buffer = frame.buffer_mut();
    for y in 0..below.height {
        for x in 0..below.width {
            if let (Some(from), Some(to)) = (
                drawn.cell(Position::new(x, y)),
                buffer.cell_mut(Position::new(below.x + x, below.y + y)),
            ) {
                *to = from.clone();
            }
        }
    }
}

/// The Run view's top line: which run is followed, the protocol's state and progress, and
/// the keys to the other views and to the protocol.
fn run_line(session: &Session, theme: Theme) -> Line<'static> {
    let followed = match &session.followed {
        Some((method, run)) => format!(" ▶ {method} run {run} "),
        None => " no run followed ".into(),
    };
    let progress = session.workbench.as_ref().map_or(String::new(), |w| {
        format!(
            " · {} of {} runs finished",
            w.folder.finished_runs(),
            w.folder.runs.len()
        )
    });
    let mut spans = vec![
        Span::styled(followed, theme.title()),
        Span::raw("· "),
        Span::styled(
            phase_words(session),
            if session.is_running() {
                theme.active()
            } else {
                Style::new()
            },
        ),
        Span::raw(progress),
        Span::styled("  │ ", theme.dim()),
    ];
    let mut keys = vec![("r", "runs"), ("c", "comparison"), ("m", "next run")];
    keys.extend(session.phase_keys());
    for (key, what) in keys {
        spans.push(Span::styled(key, theme.title()));
        spans.push(Span::raw(format!(" {what}  ")));
    }
    Line::from(spans)
}

/// Before the folder can be read: the protocol loads (or trains) its library and plans.
fn draw_preparing(frame: &mut Frame, area: Rect, session: &Session, theme: Theme) {
    let mut lines = vec![
        Line::from(Span::styled(
            format!(" {} ", session.dir.display()),
            theme.title(),
        )),
        Line::from(""),
        Line::from(match &session.phase {
            Phase::Running | Phase::Stopping => {
                "preparing: the source library loads (or trains, the first time) and the \
                 runs are planned; the views open once summary.json is written"
                    .to_string()
            }
            _ => phase_words(session),
        }),
    ];
    if let Some(error) = &session.read_error {
        lines.push(Line::from(""));
        lines.push(Line::from(Span::styled(error.clone(), theme.dim())));
    }
    lines.push(Line::from(""));
    lines.push(Line::from(" f run view · L launch · ? keys · q quit"));
    frame.render_widget(Paragraph::new(lines).wrap(Wrap { trim: true }), area);
}

/// A box of `width` × `height` in the middle of `area`, cleared.
fn centered(frame: &mut Frame, area: Rect, width: u16, height: u16) -> Rect {
    let width = width.min(area.width);
    let height = height.min(area.height);
    let rect = Rect::new(
        area.x + (area.width - width) / 2,
        area.y + (area.height - height) / 2,
        width,
        height,
    );
    frame.render_widget(Clear, rect);
    rect
}

fn draw_stop_question(frame: &mut Frame, area: Rect, then_quit: bool, theme: Theme) {
    let rect = centered(frame, area, 60, 6);
    let yes = if then_quit {
        "y stops it and quits"
    } else {
        "y stops it"
    };
    let lines = vec![
        Line::from(Span::styled(
            "protocol running: stop it? the folder stays resumable",
            theme.title(),
        )),
        Line::from(""),
        Line::from(format!("{yes} · any other key: it goes on")),
        Line::from(Span::styled(
            "(R here, or --headless --resume, finishes it later)",
            theme.dim(),
        )),
    ];
    frame.render_widget(
        Paragraph::new(lines).wrap(Wrap { trim: true }).block(
            Block::bordered()
                .title(" stop ")
                .border_style(theme.title()),
        ),
        rect,
    );
}

fn draw_picker(frame: &mut Frame, area: Rect, picker: &Picker, theme: Theme) {
    let error_lines = picker.error.as_ref().map_or(0, |_| 4);
    let wanted = picker.entries.len() as u16 + 7 + error_lines;
    let rect = centered(
        frame,
        area,
        area.width.saturating_sub(4).min(110),
        wanted.min(area.height.saturating_sub(2)),
    );
    let inner_width = usize::from(rect.width.saturating_sub(2));
    let rows = usize::from(rect.height.saturating_sub(7 + error_lines));
    // The rows shown: a window that keeps the cursor in sight.
    let total = picker.entries.len() + 1;
    let first = picker.cursor.saturating_sub(rows.saturating_sub(1));
    let name_width = picker
        .entries
        .iter()
        .map(|e| file_name(&e.path).chars().count())
        .max()
        .unwrap_or(0);
    let mut lines: Vec<Line> = Vec::new();
    for i in first..total.min(first + rows) {
        let style = if i == picker.cursor {
            theme.cursor()
        } else {
            Style::new()
        };
        let text = match picker.entries.get(i) {
            Some(entry) => format!(" {:<name_width$}  {}", file_name(&entry.path), entry.about),
            None => match &picker.typing {
                Some(typed) => format!(" path: {typed}▏"),
                None => " a path… (Enter, then type it)".into(),
            },
        };
        let text: String = text.chars().take(inner_width).collect();
        lines.push(Line::from(Span::styled(text, style)));
    }
    lines.push(Line::from(""));
    if let Some(error) = &picker.error {
        lines.push(Line::from(Span::styled(error.clone(), theme.stopped())));
    }
    lines.push(Line::from(vec![
        Span::styled("⏎", theme.title()),
        Span::raw(" launch into a new folder · "),
        Span::styled("↑↓", theme.title()),
        Span::raw(" pick · "),
        Span::styled("Esc", theme.title()),
        Span::raw(" close"),
    ]));
    lines.push(Line::from(Span::styled(
        format!(
            "{}/ ({} lessons and grids left out), run with this session's --quick, \
             --episodes, --runs, --jobs, --library",
            picker.dir.display(),
            picker.left_out
        ),
        theme.dim(),
    )));
    frame.render_widget(
        Paragraph::new(lines).wrap(Wrap { trim: false }).block(
            Block::bordered()
                .title(" launch a protocol into a new folder ")
                .border_style(theme.title()),
        ),
        rect,
    );
}

fn file_name(path: &std::path::Path) -> String {
    path.file_name().map_or(path.display().to_string(), |n| {
        n.to_string_lossy().into_owned()
    })
}
