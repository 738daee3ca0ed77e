//! The Runs view: every planned run of the protocol, methods × runs, one line each — its
//! status, episodes done of those planned, a sparkline of its moving average (MA10) on
//! one scale for all (so lines compare at a glance), the latest MA10, the time
//! left at its pace, and the source it handed over or used most.

use crossterm::event::{KeyCode, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph};
use ratatui::Frame;

use super::Intent;
use crate::report::sample_efficiency::average_at;
use crate::results::folder_state::{FolderState, RunProgress, RunStatus};
use crate::tui::keys::{ch, code, Binding};
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};
use crate::tui::workbench::cells::{fit, inner, method_kinds, method_styles};
use crate::tui::workbench::folder::Folder;

/// The sparkline's levels, lowest first.
const LEVELS: [char; 8] = ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];

/// What the Runs view's keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunsCommand {
    /// The cursor by this many runs.
    Move(isize),
    Show,
}

/// The Runs view's keys.
const KEYS: &[Binding<RunsCommand>] = &[
    Binding {
        keys: &[
            (code(KeyCode::Up), RunsCommand::Move(-1)),
            (ch('k'), RunsCommand::Move(-1)),
            (code(KeyCode::Down), RunsCommand::Move(1)),
            (ch('j'), RunsCommand::Move(1)),
            (code(KeyCode::PageUp), RunsCommand::Move(-10)),
            (code(KeyCode::PageDown), RunsCommand::Move(10)),
        ],
        help: ("↑ ↓ j k, PgUp PgDn", "pick a run"),
        bar: Some(("↑↓", "run")),
    },
    Binding {
        keys: &[(code(KeyCode::Enter), RunsCommand::Show)],
        help: (
            "Enter",
            "the picked run's dashboard in the Run view: followed live if it trains in this \
             session, else made from its files once it finished",
        ),
        bar: Some(("⏎", "dashboard")),
    },
];

/// Every planned run of the protocol, one a line; the picked one is what Enter shows.
#[derive(Debug, Default)]
pub struct RunsView {
    pub cursor: usize,
}

impl RunsView {
    /// Keeps the cursor on a run of a folder read again.
    pub fn refreshed(&mut self, folder: &Folder) {
        self.cursor = self.cursor.min(folder.state.runs.len().saturating_sub(1));
    }
}

impl View for RunsView {
    type Model = Folder;
    type Command = RunsCommand;
    type Intent = Intent;

    fn keys(&self) -> &'static [Binding<RunsCommand>] {
        KEYS
    }

    fn apply(&mut self, folder: &Folder, command: RunsCommand) -> Outcome<Intent> {
        match command {
            RunsCommand::Move(by) => {
                let last = folder.state.runs.len().saturating_sub(1) as isize;
                self.cursor = (self.cursor as isize + by).clamp(0, last) as usize;
                Outcome::Done
            }
            RunsCommand::Show => Outcome::Intent(Intent::ShowRun(self.cursor)),
        }
    }

    fn draw(&self, folder: &Folder, frame: &mut Frame, area: Rect, theme: Theme) {
        draw(frame, area, &folder.state, self.cursor, theme);
    }

    fn legend(&self, _: &Folder) -> Vec<(&'static str, &'static str)> {
        vec![(
            "click",
            "a run's line picks it; a view's name below shows it",
        )]
    }

    fn on_mouse(&mut self, folder: &Folder, mouse: MouseEvent, area: Rect) -> Outcome<Intent> {
        if mouse.kind != MouseEventKind::Down(MouseButton::Left) {
            return Outcome::Ignored;
        }
        match run_at(area, &folder.state, self.cursor, mouse.column, mouse.row) {
            Some(run) => {
                self.cursor = run;
                Outcome::Done
            }
            None => Outcome::Ignored,
        }
    }
}

fn draw(frame: &mut Frame, area: Rect, folder: &FolderState, cursor: usize, theme: Theme) {
    let title = Line::from(vec![
        Span::styled(" Runs ", theme.title()),
        Span::raw(format!("{} ", counts(&folder.runs))),
    ]);
    frame.render_widget(Block::bordered().title(title), area);
    let inside = inner(area);
    if inside.height < 2 {
        return;
    }
    let window = folder.config.protocol.moving_average;
    // Each run's moving average read where it is shown, never kept whole: a folder of
    // millions of episodes costs no copy of them a frame.
    let averages: Vec<Averages> = folder
        .runs
        .iter()
        .map(|r| Averages::of(&r.training.returns, window))
        .collect();
    // One scale for every line, the lowest MA10 of the folder to its highest, so that
    // lines compare and a curve's shape shows even far below the task's best return.
    let range = averages
        .iter()
        .map(Averages::extent)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (a, b)| {
            (lo.min(a), hi.max(b))
        });
    let Widths {
        method: method_width,
        source: source_width,
        episodes: episodes_width,
        spark: spark_width,
    } = widths(folder, inside.width);
    let header = format!(
        "{} {} {} {} {} {} {} {}",
        fit("method", method_width),
        fit("run", 4),
        fit("status", 8),
        fit("episodes", episodes_width),
        fit(
            &if range.0 <= range.1 {
                format!("MA{window}, {:.1} to {:.1}", range.0, range.1)
            } else {
                format!("MA{window}")
            },
            spark_width
        ),
        fit(&format!("MA{window}"), 8),
        fit("ETA", 7),
        fit("source", source_width),
    );
    let mut lines = vec![Line::styled(header, theme.dim())];
    let rows = run_window(inside, folder, cursor);
    let styles = method_styles(&method_kinds(folder), theme);
    for i in rows.rows() {
        let run = &folder.runs[i];
        let first_of_method = i == 0 || folder.runs[i - 1].method != run.method;
        let method = if first_of_method {
            run.method.label()
        } else {
            ""
        };
        let averages = &averages[i];
        let latest = averages
            .last()
            .map_or_else(|| "-".to_string(), |a| format!("{a:.1}"));
        let eta = run.eta_s().map_or_else(|| "-".to_string(), duration);
        let picked = i == cursor;
        let row_style = |style: Style| {
            if picked {
                style.patch(theme.cursor())
            } else {
                style
            }
        };
        let method_style = styles.get(run.method.index).copied().unwrap_or_default();
        lines.push(Line::from(vec![
            Span::styled(fit(method, method_width), row_style(method_style)),
            Span::styled(
                format!(" {} ", fit(&run.run.to_string(), 4)),
                row_style(Style::new()),
            ),
            Span::styled(
                fit(run.status.name(), 8),
                row_style(status_style(run.status, theme)),
            ),
            Span::styled(
                format!(
                    " {} {} {} {} {}",
                    fit(&run.progress_text(), episodes_width),
                    fit(
                        &sparkline_of(averages.len, |i| averages.at(i), range, spark_width),
                        spark_width
                    ),
                    fit(&latest, 8),
                    fit(&eta, 7),
                    fit(run.source.as_deref().unwrap_or("-"), source_width),
                ),
                row_style(Style::new()),
            ),
        ]));
    }
    if let Some(more) = rows.marker() {
        lines.push(Line::styled(
            format!("{} (↑↓ to move)", more.trim()),
            theme.dim(),
        ));
    }
    frame.render_widget(Paragraph::new(lines), inside);
}

/// The columns' widths: each as wide as its longest cell, the sparkline what is left.
struct Widths {
    method: usize,
    source: usize,
    episodes: usize,
    spark: usize,
}

fn widths(folder: &FolderState, inside_width: u16) -> Widths {
    let method = folder
        .runs
        .iter()
        .map(|r| r.method.label().chars().count())
        .max()
        .unwrap_or(6)
        .clamp(6, 22);
    let source = folder
        .runs
        .iter()
        .filter_map(|r| r.source.as_ref().map(|s| s.chars().count()))
        .max()
        .unwrap_or(1)
        .clamp(6, 12);
    let episodes = folder
        .runs
        .iter()
        .map(|r| r.full_text().len().max(r.progress_text().len()))
        .max()
        .unwrap_or(8)
        .max(8);
    // method, run, status, episodes, [sparkline], MA10, ETA, source, with a space between.
    let fixed = method + 4 + 8 + episodes + 8 + 7 + source + 7;
    let spark = usize::from(inside_width).saturating_sub(fixed).max(4);
    Widths {
        method,
        source,
        episodes,
        spark,
    }
}

/// The runs shown in the panel's inside `inside`, below its header line; a line under them
/// says what they hide, when they do not all fit.
fn run_window(inside: Rect, folder: &FolderState, cursor: usize) -> RowWindow {
    let runs = folder.runs.len();
    let mut room = usize::from(inside.height).saturating_sub(1);
    if runs > room {
        room = room.saturating_sub(1);
    }
    RowWindow::new(runs, room, [cursor])
}

/// The run whose line is at (`column`, `row`) of the screen, the view drawn in `area`: what
/// a click picks.
fn run_at(area: Rect, folder: &FolderState, cursor: usize, column: u16, row: u16) -> Option<usize> {
    let inside = inner(area);
    let first = inside.y + 1;
    if !(inside.x..inside.x + inside.width).contains(&column) || row < first {
        return None;
    }
    run_window(inside, folder, cursor).row_at(usize::from(row - first))
}

/// `done 3 · running 2 · queued 6` (only the statuses some run has).
fn counts(runs: &[RunProgress]) -> String {
    let statuses = [
        RunStatus::Done,
        RunStatus::Running,
        RunStatus::Queued,
        RunStatus::Stopped,
        RunStatus::Failed,
        RunStatus::NotRun,
    ];
    let parts: Vec<String> = statuses
        .iter()
        .filter_map(|&s| {
            let n = runs.iter().filter(|r| r.status == s).count();
            (n > 0).then(|| format!("{} {n}", s.name()))
        })
        .collect();
    format!("· {} runs: {}", runs.len(), parts.join(" · "))
}

fn status_style(status: RunStatus, theme: Theme) -> Style {
    match status {
        RunStatus::Running => theme.active(),
        RunStatus::Failed | RunStatus::Stopped => theme.stopped(),
        RunStatus::Queued | RunStatus::NotRun => theme.dim(),
        RunStatus::Done => Style::new(),
    }
}

/// A run's moving average of `window` returns (as [`crate::report::moving_average`]
/// gives it), each value computed where it is read.
struct Averages<'a> {
    returns: &'a [f64],
    window: usize,
    /// How many values it has.
    len: usize,
}

impl<'a> Averages<'a> {
    fn of(returns: &'a [f64], window: usize) -> Self {
        let len = if window == 0 {
            0
        } else {
            (returns.len() + 1).saturating_sub(window)
        };
        Self {
            returns,
            window,
            len,
        }
    }

    fn at(&self, i: usize) -> f64 {
        average_at(self.returns, i, self.window).unwrap_or(f64::NAN)
    }

    fn last(&self) -> Option<f64> {
        self.len.checked_sub(1).map(|i| self.at(i))
    }

    /// Its lowest and highest value (infinities the wrong way round without one).
    fn extent(&self) -> (f64, f64) {
        (0..self.len)
            .map(|i| self.at(i))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), a| {
                (lo.min(a), hi.max(a))
            })
    }
}

/// The values as at most `width` block characters on the scale `low..high`, the last
/// value of each of `width` equal stretches of the run (a long run's latest shape).
pub fn sparkline(values: &[f64], range: (f64, f64), width: usize) -> String {
    sparkline_of(values.len(), |i| values[i], range, width)
}

/// [`sparkline`] of the `len` values `at` gives.
fn sparkline_of(
    len: usize,
    at: impl Fn(usize) -> f64,
    (low, high): (f64, f64),
    width: usize,
) -> String {
    if len == 0 || width == 0 {
        return String::new();
    }
    let shown = len.min(width);
    (1..=shown)
        .map(|k| {
            let v = at(k * len / shown - 1);
            let level = if high > low {
                ((v - low) / (high - low)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            LEVELS[(level * (LEVELS.len() - 1) as f64).round() as usize]
        })
        .collect()
}

/// `45s`, `3m05s`, `2h10m`.
fn duration(seconds: f64) -> String {
    let s = seconds.round() as u64;
    match s {
        0..60 => format!("{s}s"),
        60..3600 => format!("{}m{:02}s", s / 60, s % 60),
        _ => format!("{}h{:02}m", s / 3600, s % 3600 / 60),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sparkline_keeps_the_last_value_of_each_stretch_on_the_tasks_scale() {
        // 0..500 in eight levels: 0 → ▁, 250 → ▅ (3.5 rounds up), 500 → █.
        assert_eq!(sparkline(&[0.0, 250.0, 500.0], (0.0, 500.0), 10), "▁▅█");
        // Four values in two columns: the 2nd and the 4th.
        assert_eq!(sparkline(&[0.0, 500.0, 0.0, 0.0], (0.0, 500.0), 2), "█▁");
        assert_eq!(sparkline(&[-300.0], (-200.0, 0.0), 3), "▁", "clamped");
        assert_eq!(sparkline(&[], (0.0, 1.0), 3), "");
    }

    #[test]
    fn durations_read_at_a_glance() {
        assert_eq!(duration(44.6), "45s");
        assert_eq!(duration(185.0), "3m05s");
        assert_eq!(duration(7800.0), "2h10m");
    }
}
