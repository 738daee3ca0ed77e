//! Drawing a protocol run in the UI: the workbench ([`super::super::workbench`]) with the
//! protocol's state in its lines and its controls in its bar, and over it the stop
//! question or `L`'s picker. Pure functions of [`Session`].

use ratatui::layout::Rect;
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Wrap};
use ratatui::Frame;

use super::picker::Picker;
use super::{Overlay, Phase, Session};
use crate::results::Status;
use crate::tui::theme::Theme;
use crate::tui::workbench::frame::protocol_state;
use crate::tui::workbench::screens::workbench::{Host, SESSION_KEYS};

pub fn draw(frame: &mut Frame, session: &Session, theme: Theme) {
    let host = Host {
        keys: SESSION_KEYS,
        controls: session.controls(),
        dir: session.dir.display().to_string(),
        state: phase_words(session),
        active: session.is_running(),
        waiting: match &session.phase {
            Phase::Running | Phase::Stopping => {
                "preparing: the source library loads (or trains, the first time) and the \
                 runs are planned; the views open once summary.json is written"
                    .to_string()
            }
            _ => phase_words(session),
        },
    };
    let overlay = |frame: &mut Frame, area: Rect| match &session.overlay {
        Some(Overlay::Stop { then_quit }) => {
            draw_stop_question(frame, area, &session.dir, *then_quit, theme);
        }
        Some(Overlay::Picker(picker)) => draw_picker(frame, area, picker, theme),
        None => {}
    };
    session.workbench.draw(frame, theme, &host, overlay);
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
            .folder
            .as_ref()
            .map_or(String::new(), |f| protocol_state(&f.state)),
    }
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

fn draw_stop_question(
    frame: &mut Frame,
    area: Rect,
    dir: &std::path::Path,
    then_quit: bool,
    theme: Theme,
) {
    let rect = centered(frame, area, 64, 7);
    let dir = dir.display();
    // What finishes it is what works after this answer: R only while the screen stays.
    let (yes, later) = if then_quit {
        (
            "y stops it and quits",
            format!("(`sapnet --resume --out {dir}` finishes it later)"),
        )
    } else {
        (
            "y stops it",
            format!("(R here, or `sapnet --resume --out {dir}` later, finishes it)"),
        )
    };
    let lines = vec![
        Line::from(Span::styled(
            "protocol running: stop it? the folder stays resumable",
            theme.title(),
        )),
        Line::from(""),
        Line::from(format!("{yes} · any other key: it goes on")),
        Line::from(Span::styled(later, theme.dim())),
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
    let wanted = picker.entries.len() as u16 + 8 + error_lines;
    let rect = centered(
        frame,
        area,
        area.width.saturating_sub(4).min(110),
        wanted.min(area.height.saturating_sub(2)),
    );
    let inner_width = usize::from(rect.width.saturating_sub(2));
    // The configs' rows: a window that keeps the cursor in sight, above the row that takes
    // a typed path, which is always drawn (a list longer than the screen hid it).
    let rows = usize::from(rect.height.saturating_sub(8 + error_lines)).max(1);
    let first = picker
        .cursor
        .min(picker.entries.len().saturating_sub(1))
        .saturating_sub(rows.saturating_sub(1));
    let name_width = picker
        .entries
        .iter()
        .map(|e| file_name(&e.path).chars().count())
        .max()
        .unwrap_or(0);
    let row = |i: usize, text: String| {
        let style = if i == picker.cursor {
            theme.cursor()
        } else {
            Style::new()
        };
        let text: String = text.chars().take(inner_width).collect();
        Line::from(Span::styled(text, style))
    };
    let mut lines: Vec<Line> = Vec::new();
    for (i, entry) in picker.entries.iter().enumerate().skip(first).take(rows) {
        let text = format!(" {:<name_width$}  {}", file_name(&entry.path), entry.about);
        lines.push(row(i, text));
    }
    let hidden = picker.entries.len().saturating_sub(first + rows);
    if hidden > 0 {
        lines.push(Line::from(Span::styled(
            format!(" ▼ {hidden} more"),
            theme.dim(),
        )));
    }
    let path_row = match &picker.typing {
        Some(typed) => format!(" path: {typed}▏"),
        None => " another config: Enter here, then type its path".into(),
    };
    lines.push(row(picker.entries.len(), path_row));
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
