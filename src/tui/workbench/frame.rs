//! The frame around every view, drawn once for every screen (trippy's `render/app.rs`):
//!
//! ```text
//! ┌ header: the folder (or sweep) and where it stands ─────────────────────┐
//! │                                                                        │
//! │ body: the view shown                                                   │
//! │                                                                        │
//! └ status bar: the tabs · the keys offered now │ ? keys  q quit ──────────┘
//! ```
//!
//! The Run view's dashboard has a status line of its own and needs the whole height on
//! the smallest terminal: its frame is one line over the top (which run, where the
//! protocol is, the tabs and the keys), taking the panels' top border at 24 rows. Over
//! either: `?`'s keys, the screen's own overlay (the stop question, the picker), the last
//! key's notice. Below [`screen::MIN_WIDTH`]×[`screen::MIN_HEIGHT`] a note instead.

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Clear, Paragraph};
use ratatui::Frame;

use std::path::Path;

use super::compare_folder::CompareFolder;
use super::folder::{Compared, Folder};
use crate::results::folder_state::FolderState;
use crate::results::Status;
use crate::tui::keys::{HELP_BAR, QUIT_BAR};
use crate::tui::screen;
use crate::tui::theme::Theme;

/// A tab of the status bar: its key, its name, whether it is the one shown.
pub type Tab = (String, &'static str, bool);

/// What a screen puts around its view.
pub struct Chrome<'a> {
    /// The line above the view: which folder or run, and where it stands.
    pub header: Line<'static>,
    pub tabs: Vec<Tab>,
    /// The keys the bar offers now, most needed first (a narrow terminal drops the last).
    pub commands: Vec<(&'static str, &'static str)>,
    /// The Run view's frame: one line over the top of its full-height dashboard.
    pub over_the_top: bool,
    /// `?`'s lines, while its overlay is up.
    pub help: Option<Vec<(&'static str, &'static str)>>,
    /// What the last key did or why it did nothing.
    pub notice: Option<&'a str>,
}

/// Draws `chrome` with the view (`body`, given its area) inside and the screen's own
/// overlay (given the whole area) over both, then `?` and the notice.
pub fn draw(
    frame: &mut Frame,
    chrome: &Chrome,
    theme: Theme,
    body: impl FnOnce(&mut Frame, Rect),
    overlay: impl FnOnce(&mut Frame, Rect),
) {
    let area = frame.area();
    if screen::too_small(frame, area) {
        return;
    }
    if chrome.over_the_top {
        body(frame, body_area(area, true));
        let top = Rect::new(area.x, area.y, area.width, 1);
        frame.render_widget(Clear, top);
        frame.render_widget(
            Paragraph::new(top_line(chrome, theme, usize::from(top.width))),
            top,
        );
    } else {
        let [header, inside, status] = Layout::vertical([
            Constraint::Length(1),
            Constraint::Fill(1),
            Constraint::Length(1),
        ])
        .areas(area);
        frame.render_widget(Paragraph::new(chrome.header.clone()), header);
        body(frame, inside);
        frame.render_widget(
            Paragraph::new(status_line(chrome, theme, usize::from(status.width))),
            status,
        );
    }
    if let Some(lines) = &chrome.help {
        screen::draw_help(frame, area, lines, theme);
    }
    overlay(frame, area);
    if let Some(notice) = chrome.notice {
        draw_notice(frame, area, notice, theme);
    }
}

/// The view's area on a screen of `area`: between the header and the status bar, or for
/// the Run view all but the top line — on the smallest terminal the dashboard needs, all
/// of it (the line then takes the panels' top border).
pub fn body_area(area: Rect, over_the_top: bool) -> Rect {
    if over_the_top {
        if area.height <= screen::MIN_HEIGHT {
            return area;
        }
        return Rect::new(area.x, area.y + 1, area.width, area.height - 1);
    }
    Rect::new(
        area.x,
        area.y + 1,
        area.width,
        area.height.saturating_sub(2),
    )
}

/// What the last key did or why it did nothing, over the status bar.
fn draw_notice(frame: &mut Frame, area: Rect, notice: &str, theme: Theme) {
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

/// Where the protocol stands, in words: who writes it now, or how it ended.
pub fn protocol_state(folder: &FolderState) -> String {
    if let Some(writer) = &folder.writer {
        return format!("written by {}", writer.describe());
    }
    match folder.status {
        None | Some(Status::Complete) => "complete".into(),
        // Every screen this is drawn on takes `R` (`sapnet open`, a session).
        Some(Status::Stopped) => "stopped: R resumes it".into(),
        Some(Status::Failed) => "failed: R resumes it".into(),
        // `running` with no process holding the lock: the process was killed.
        Some(Status::Running | Status::Interrupted) => {
            "interrupted: no process writes it; R resumes it".into()
        }
    }
}

/// The folder, its task, who writes it and how far it is; on a narrow terminal the task
/// goes first, then the folder's path is cut from its start, so that who writes it and
/// the runs finished always show.
pub fn folder_line(model: &Folder, theme: Theme, width: usize) -> Line<'static> {
    let folder = &model.state;
    let state = protocol_state(folder);
    let progress = format!(
        " · {}",
        super::cells::runs_finished(folder.finished_runs(), folder.runs.len())
    );
    let state_style = if folder.writer.is_some() {
        theme.active()
    } else {
        Style::new()
    };
    let mut spans = heading(
        (&folder.dir, &folder.task()),
        ((state, state_style), progress),
        theme,
        width,
    );
    if let Some(error) = &model.read_error {
        spans.push(Span::styled(
            format!(" · re-reading failed, showing the last read: {error}"),
            theme.stopped(),
        ));
    } else if let Some(error) = &folder.error {
        spans.push(Span::styled(format!(" · {error}"), theme.stopped()));
    }
    Line::from(spans)
}

/// A compare folder, its task, how its runs were set side by side and how many there
/// are, fitted as [`folder_line`] is.
pub fn compare_line(compare: &CompareFolder, theme: Theme, width: usize) -> Line<'static> {
    let methods = compare.methods().len();
    let runs = compare.runs().len();
    let progress = format!(
        " · {} of {}",
        super::cells::counted(runs, "run"),
        super::cells::counted(methods, "method")
    );
    // The task is compare's `--task`, any text: shown as data.
    let task = crate::shown_text::cut(&compare.scoring.task, 40);
    Line::from(heading(
        (&compare.dir, &task),
        ((compare.alignment_text(), Style::new()), progress),
        theme,
        width,
    ))
}

/// The header's spans: the folder, its task, where it stands, how far. On a narrow
/// terminal the task goes first, then the folder's path is cut from its start, so that
/// where it stands and how far always show.
fn heading(
    (dir, task): (&Path, &str),
    ((state, state_style), progress): ((String, Style), String),
    theme: Theme,
    width: usize,
) -> Vec<Span<'static>> {
    let mut dir = dir.display().to_string();
    let mut task = format!("· {task} · ");
    let used = |dir: &str, task: &str| {
        dir.chars().count()
            + 2
            + task.chars().count()
            + state.chars().count()
            + progress.chars().count()
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
    vec![
        Span::styled(format!(" {dir} "), theme.title()),
        Span::raw(task),
        Span::styled(state, state_style),
        Span::raw(progress),
    ]
}

/// Below this width the bar names the shown tab only, the others by their keys, so
/// that the view's keys keep room.
const COMPACT_TABS_BELOW: usize = 100;

/// Whether the tabs are drawn by their keys on a bar of `width`, and the text of `tab`.
fn tab_text((key, name, shown): &Tab, width: usize) -> (String, String) {
    if width < COMPACT_TABS_BELOW && !shown {
        (key.clone(), String::new())
    } else {
        (key.clone(), format!(" {name}"))
    }
}

/// The space after each tab on a bar of `width`.
fn tab_gap(width: usize) -> &'static str {
    if width < COMPACT_TABS_BELOW {
        " "
    } else {
        "  "
    }
}

/// The tabs, the one shown marked, on a bar of `width`.
fn tab_spans(tabs: &[Tab], theme: Theme, width: usize) -> Vec<Span<'static>> {
    let mut spans = Vec::new();
    for tab in tabs {
        let style = if tab.2 { theme.cursor() } else { Style::new() };
        let (key, name) = tab_text(tab, width);
        spans.push(Span::styled(key, theme.title()));
        spans.push(Span::styled(name, style));
        spans.push(Span::raw(tab_gap(width)));
    }
    spans
}

fn command_spans((key, what): (&'static str, &'static str), theme: Theme) -> [Span<'static>; 2] {
    [
        Span::styled(key, theme.title()),
        Span::raw(format!(" {what}  ")),
    ]
}

/// The tabs, then as many of the keys offered as fit before the keys for help and
/// quitting, which stay at the end (`?` lists the others).
fn status_line(chrome: &Chrome, theme: Theme, width: usize) -> Line<'static> {
    let mut spans = vec![Span::raw(" ")];
    if !chrome.tabs.is_empty() {
        spans.extend(tab_spans(&chrome.tabs, theme, width));
        spans.push(Span::styled("│ ", theme.dim()));
    }
    let end = [
        Span::styled("│ ", theme.dim()),
        Span::styled(HELP_BAR.0, theme.title()),
        Span::raw(format!(" {}  ", HELP_BAR.1)),
        Span::styled(QUIT_BAR.0, theme.title()),
        Span::raw(format!(" {}", QUIT_BAR.1)),
    ];
    let end_width: usize = end.iter().map(Span::width).sum();
    let mut used: usize = spans.iter().map(Span::width).sum();
    for &command in &chrome.commands {
        let command = command_spans(command, theme);
        let wide: usize = command.iter().map(Span::width).sum();
        if used + wide + end_width > width {
            break;
        }
        used += wide;
        spans.extend(command);
    }
    spans.extend(end);
    Line::from(spans)
}

/// The Run view's line: which run and where the protocol is, then the tabs and as many
/// of the keys offered as fit whole in `width` (`?` and quitting are on the dashboard's
/// own line).
fn top_line(chrome: &Chrome, theme: Theme, width: usize) -> Line<'static> {
    let mut spans = chrome.header.spans.clone();
    if !chrome.tabs.is_empty() || !chrome.commands.is_empty() {
        spans.push(Span::styled("  │ ", theme.dim()));
    }
    let mut used: usize = spans.iter().map(Span::width).sum();
    // Each tab whole or not at all, then the keys likewise.
    for tab in tab_spans(&chrome.tabs, theme, width).chunks(3) {
        let wide: usize = tab.iter().map(Span::width).sum();
        if used + wide > width {
            break;
        }
        used += wide;
        spans.extend(tab.iter().cloned());
    }
    for &command in &chrome.commands {
        let command = command_spans(command, theme);
        let wide: usize = command.iter().map(Span::width).sum();
        if used + wide > width {
            break;
        }
        used += wide;
        spans.extend(command);
    }
    Line::from(spans)
}

/// The tab whose name in the status bar of `width` is at `column`: the bar starts with
/// a space, then each tab's key, a space and its name (below [`COMPACT_TABS_BELOW`], the
/// shown tab's only), and the gap.
pub fn tab_at(tabs: &[Tab], column: u16, width: u16) -> Option<usize> {
    let width = usize::from(width);
    let mut start = 1u16;
    for (i, tab) in tabs.iter().enumerate() {
        let (key, name) = tab_text(tab, width);
        let end = start + (key.chars().count() + name.chars().count()) as u16;
        if (start..end).contains(&column) {
            return Some(i);
        }
        start = end + tab_gap(width).len() as u16;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_status_bar_names_each_tab_where_it_is_drawn() {
        let tabs = [
            ("r", "runs", false),
            ("c", "comparison", true),
            ("v", "curves", false),
            ("f", "run", false),
        ]
        .map(|(key, name, shown)| (key.to_string(), name, shown));
        // " r runs  c comparison  v curves  f run  │ …"
        let tab_at = |tabs: &[Tab], column| tab_at(tabs, column, 120);
        assert_eq!(tab_at(&tabs, 0), None);
        assert_eq!(tab_at(&tabs, 1), Some(0));
        assert_eq!(tab_at(&tabs, 6), Some(0));
        assert_eq!(tab_at(&tabs, 7), None);
        assert_eq!(tab_at(&tabs, 9), Some(1));
        assert_eq!(tab_at(&tabs, 20), Some(1));
        assert_eq!(tab_at(&tabs, 23), Some(2));
        assert_eq!(tab_at(&tabs, 30), Some(2));
        assert_eq!(tab_at(&tabs, 31), None);
        assert_eq!(tab_at(&tabs, 33), Some(3));
        assert_eq!(tab_at(&tabs, 37), Some(3));
        assert_eq!(tab_at(&tabs, 38), None);
        // At 80 columns: " r c comparison v f │ …"
        let narrow = |column| super::tab_at(&tabs, column, 80);
        assert_eq!(narrow(1), Some(0));
        assert_eq!(narrow(2), None);
        assert_eq!((narrow(3), narrow(14)), (Some(1), Some(1)));
        assert_eq!(
            (narrow(15), narrow(16), narrow(18)),
            (None, Some(2), Some(3))
        );
    }
}
