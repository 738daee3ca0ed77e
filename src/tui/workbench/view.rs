//! The workbench's screen: a line saying what folder this is and who writes it, the view
//! shown, and the status bar of the views' keys; `?` lays every key over it. Pure
//! functions of [`Workbench`].

use ratatui::layout::{Constraint, Layout};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;
use ratatui::Frame;

use super::state::{View, Workbench};
use super::{comparison_view, curves_view, runs_view};
use crate::results::folder_state::FolderState;
use crate::results::Status;
use crate::tui::screen;
use crate::tui::theme::Theme;

pub fn draw(frame: &mut Frame, workbench: &Workbench, theme: Theme) {
    let area = frame.area();
    if screen::too_small(frame, area) {
        return;
    }
    let [header, body, status] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Fill(1),
        Constraint::Length(1),
    ])
    .areas(area);
    frame.render_widget(
        Paragraph::new(header_line(workbench, theme, usize::from(header.width))),
        header,
    );
    match workbench.view {
        View::Runs => runs_view::draw(frame, body, workbench, theme),
        View::Comparison => comparison_view::draw(frame, body, workbench, theme),
        View::Curves => curves_view::draw(frame, body, workbench, theme),
    }
    frame.render_widget(
        Paragraph::new(status_line(workbench, theme, usize::from(status.width))),
        status,
    );
    if workbench.help {
        screen::draw_help(frame, area, &workbench.keys(), theme);
    }
}

/// Where the protocol stands, in words: who writes it now, or how it ended.
pub fn protocol_state(folder: &FolderState) -> String {
    if let Some(writer) = &folder.writer {
        return format!("written by {}", writer.describe());
    }
    match folder.status {
        None | Some(Status::Complete) => "complete".into(),
        Some(Status::Stopped) => "stopped (--resume finishes it)".into(),
        Some(Status::Failed) => "failed".into(),
        // `running` with no process holding the lock: the process was killed.
        Some(Status::Running | Status::Interrupted) => {
            "interrupted: no process writes it (--resume finishes it)".into()
        }
    }
}

/// The folder, its task, who writes it and how far it is; on a narrow terminal the task
/// goes first, then the folder's path is cut from its start, so that who writes it and
/// the runs finished always show.
fn header_line(workbench: &Workbench, theme: Theme, width: usize) -> Line<'static> {
    let folder = &workbench.folder;
    let state = protocol_state(folder);
    let progress = format!(
        " · {} of {} runs finished",
        folder.finished_runs(),
        folder.runs.len()
    );
    let mut dir = folder.dir.display().to_string();
    let mut task = format!("· {} · ", folder.task());
    let used = |dir: &str, task: &str| {
        dir.chars().count() + 2 + task.chars().count() + state.chars().count() + progress.len()
    };
    if used(&dir, &task) > width {
        task = "· ".into();
    }
    let over = used(&dir, &task).saturating_sub(width);
    if over > 0 {
        let keep = dir.chars().count().saturating_sub(over + 1).max(1);
        let tail: String = dir.chars().skip(dir.chars().count() - keep).collect();
        dir = format!("…{tail}");
    }
    let mut spans = vec![
        Span::styled(format!(" {dir} "), theme.title()),
        Span::raw(task),
        Span::styled(
            state,
            if folder.writer.is_some() {
                theme.active()
            } else {
                Style::new()
            },
        ),
        Span::raw(progress),
    ];
    if let Some(error) = &workbench.read_error {
        spans.push(Span::styled(
            format!(" · re-reading failed, showing the last read: {error}"),
            theme.stopped(),
        ));
    } else if let Some(error) = &folder.error {
        spans.push(Span::styled(format!(" · {error}"), theme.stopped()));
    }
    Line::from(spans)
}

/// The views' keys, the one shown marked, then the shown view's own keys (left out when
/// the line would not fit `width`: `?` lists them); the keys for help and quitting stay
/// at the end.
fn status_line(workbench: &Workbench, theme: Theme, width: usize) -> Line<'static> {
    let mut spans = vec![Span::raw(" ")];
    for view in View::ALL {
        let (key, name) = view.key();
        let style = if view == workbench.view {
            theme.cursor()
        } else {
            Style::new()
        };
        spans.push(Span::styled(format!("{key}"), theme.title()));
        spans.push(Span::styled(format!(" {name}"), style));
        spans.push(Span::raw("  "));
    }
    spans.push(Span::styled("│ ", theme.dim()));
    // As many of the view's own keys as fit before the keys for help and quitting.
    let end = "│ ? keys  q quit".chars().count();
    let mut used: usize = spans.iter().map(Span::width).sum();
    for (key, what) in workbench.view_commands() {
        let command = [
            Span::styled(key.to_string(), theme.title()),
            Span::raw(format!(" {what}  ")),
        ];
        let wide: usize = command.iter().map(Span::width).sum();
        if used + wide + end > width {
            break;
        }
        used += wide;
        spans.extend(command);
    }
    spans.push(Span::styled("│ ", theme.dim()));
    spans.push(Span::styled("?", theme.title()));
    spans.push(Span::raw(" keys  "));
    spans.push(Span::styled("q", theme.title()));
    spans.push(Span::raw(" quit"));
    Line::from(spans)
}
