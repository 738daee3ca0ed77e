//! The Sweep view: a line saying what sweep this is and how far it is; its cells, one a
//! line (axis values, status, a running cell's process and progress, a failed one's
//! error); per axis value, how many cells finished, and the picked value's comparison —
//! each method's IQM of the training return and of the test score with their 95%
//! intervals, printed as the stdout table prints them; the status bar of its keys.

use std::convert::Infallible;

use crossterm::event::KeyCode;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph};
use ratatui::Frame;

use crate::report::comparison::interval;
use crate::tui::keys::{ch, code, Binding};
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};
use crate::tui::workbench::cells::{fit, inner};
use crate::tui::workbench::sweep_folder::{CellStatus, SweepState, ValueComparison};

/// Which of the Sweep view's lists the arrows move in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Focus {
    Cells,
    Values,
}

/// What the Sweep view's keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SweepCommand {
    /// The other list.
    Focus,
    /// The focused list's cursor by this many rows.
    Move(isize),
}

/// The Sweep view's keys.
const KEYS: &[Binding<SweepCommand>] = &[
    Binding {
        keys: &[
            (code(KeyCode::Tab), SweepCommand::Focus),
            (code(KeyCode::BackTab), SweepCommand::Focus),
        ],
        help: (
            "Tab",
            "move between the cells and the axis values (the comparison shown is the \
             picked value's)",
        ),
        bar: Some(("Tab", "cells")),
    },
    Binding {
        keys: &[
            (code(KeyCode::Up), SweepCommand::Move(-1)),
            (ch('k'), SweepCommand::Move(-1)),
            (code(KeyCode::Down), SweepCommand::Move(1)),
            (ch('j'), SweepCommand::Move(1)),
            (code(KeyCode::PageUp), SweepCommand::Move(-10)),
            (code(KeyCode::PageDown), SweepCommand::Move(10)),
        ],
        help: ("↑ ↓ j k, PgUp PgDn", "pick a cell or an axis value"),
        bar: Some(("↑↓", "value")),
    },
];

/// The Sweep view's state: the folder as last read, its comparisons, what is picked.
pub struct SweepView {
    pub sweep: SweepState,
    pub values: Vec<ValueComparison>,
    /// The comparisons of newly done cells are being made.
    pub computing: bool,
    pub focus: Focus,
    pub cell_cursor: usize,
    pub value_cursor: usize,
    /// The last refresh's failure, shown until a read succeeds again.
    pub read_error: Option<String>,
}

impl SweepView {
    pub fn new(sweep: SweepState, values: Vec<ValueComparison>) -> Self {
        Self {
            sweep,
            values,
            computing: false,
            focus: Focus::Values,
            cell_cursor: 0,
            value_cursor: 0,
            read_error: None,
        }
    }

    pub fn refreshed(&mut self, sweep: SweepState, values: Option<Vec<ValueComparison>>) {
        self.sweep = sweep;
        if let Some(values) = values {
            self.values = values;
            self.computing = false;
        }
        self.read_error = None;
        self.cell_cursor = self
            .cell_cursor
            .min(self.sweep.cells.len().saturating_sub(1));
        self.value_cursor = self.value_cursor.min(self.values.len().saturating_sub(1));
    }
}

impl View for SweepView {
    /// The view owns the sweep as read: it is the screen's only view.
    type Model = ();
    type Command = SweepCommand;
    type Intent = Infallible;

    fn keys(&self) -> &'static [Binding<SweepCommand>] {
        KEYS
    }

    fn apply(&mut self, _: &(), command: SweepCommand) -> Outcome<Infallible> {
        match command {
            SweepCommand::Focus => {
                self.focus = match self.focus {
                    Focus::Cells => Focus::Values,
                    Focus::Values => Focus::Cells,
                };
            }
            SweepCommand::Move(by) => {
                let (cursor, rows) = match self.focus {
                    Focus::Cells => (&mut self.cell_cursor, self.sweep.cells.len()),
                    Focus::Values => (&mut self.value_cursor, self.values.len()),
                };
                let last = rows.saturating_sub(1) as isize;
                *cursor = (*cursor as isize + by).clamp(0, last) as usize;
            }
        }
        Outcome::Done
    }

    fn draw(&self, _: &(), frame: &mut Frame, body: Rect, theme: Theme) {
        // The cells take up to two fifths of the screen, their rows and borders.
        let cells_height = (self.sweep.cells.len() as u16 + 3).min(body.height * 2 / 5);
        let [cells, values] =
            Layout::vertical([Constraint::Length(cells_height), Constraint::Fill(1)]).areas(body);
        draw_cells(frame, cells, self, theme);
        let list_width = self
            .values
            .iter()
            .map(|v| v.axis.chars().count() + v.value.chars().count() + 8)
            .max()
            .unwrap_or(24)
            .clamp(24, usize::from(values.width / 3).max(24)) as u16;
        let [list, comparison] =
            Layout::horizontal([Constraint::Length(list_width), Constraint::Fill(1)]).areas(values);
        draw_values(frame, list, self, theme);
        draw_comparison(frame, comparison, self, theme);
    }

    /// Tab names the list it moves to, ↑↓ what they pick.
    fn words(&self, _: &(), command: SweepCommand) -> Option<&'static str> {
        Some(match (command, self.focus) {
            (SweepCommand::Focus, Focus::Cells) => "axis values",
            (SweepCommand::Focus, Focus::Values) => "cells",
            (SweepCommand::Move(_), Focus::Cells) => "cell",
            (SweepCommand::Move(_), Focus::Values) => "value",
        })
    }
}

/// What sweep this is and how far it is, for the screen's top line.
pub fn header_line(bench: &SweepView, theme: Theme) -> Line<'static> {
    let sweep = &bench.sweep;
    let counts: Vec<String> = ["done", "running", "queued", "stopped", "failed", "not run"]
        .iter()
        .filter_map(|name| {
            let n = sweep.count(name);
            (n > 0).then(|| format!("{name} {n}"))
        })
        .collect();
    let mut spans = vec![
        Span::styled(format!(" {} ", sweep.dir.display()), theme.title()),
        Span::raw(format!(
            "· sweep of {} cells over {} · {}",
            sweep.cells.len(),
            sweep.axes.join(", "),
            counts.join(" · ")
        )),
    ];
    if let Some(error) = &bench.read_error {
        spans.push(Span::styled(
            format!(" · re-reading failed, showing the last read: {error}"),
            theme.stopped(),
        ));
    }
    Line::from(spans)
}

fn status_style(status: &CellStatus, theme: Theme) -> Style {
    match status {
        CellStatus::Running(_) => theme.active(),
        CellStatus::Failed(_) | CellStatus::Stopped => theme.stopped(),
        CellStatus::Queued | CellStatus::NotRun => theme.dim(),
        CellStatus::Done => Style::new(),
    }
}

/// What a cell's line says beside its status.
fn detail(status: &CellStatus, progress: Option<(usize, usize)>) -> String {
    match status {
        CellStatus::Running(holder) => {
            let mut text = format!("written by {}", holder.describe());
            if let Some((finished, all)) = progress {
                text.push_str(&format!(
                    " · {}",
                    crate::tui::workbench::cells::runs_finished(finished, all)
                ));
            }
            text
        }
        CellStatus::Failed(line) => line.clone(),
        CellStatus::Stopped => "no process writes it: `sweep run` runs it again".into(),
        CellStatus::Done | CellStatus::Queued | CellStatus::NotRun => String::new(),
    }
}

fn draw_cells(frame: &mut Frame, area: Rect, bench: &SweepView, theme: Theme) {
    let focused = bench.focus == Focus::Cells;
    let title = Line::from(vec![Span::styled(
        " Cells ",
        if focused {
            theme.title().patch(theme.cursor())
        } else {
            theme.title()
        },
    )]);
    let cells = &bench.sweep.cells;
    let inside = inner(area);
    let window = RowWindow::new(
        cells.len(),
        usize::from(inside.height.saturating_sub(1)),
        [bench.cell_cursor],
    );
    // The cells the panel hides, on its bottom border (Tab, then ↑↓ reach them).
    let block = Block::bordered().title(title).title_bottom(
        Line::styled(window.marker().unwrap_or_default(), theme.title()).right_aligned(),
    );
    frame.render_widget(block, area);
    if inside.height < 2 {
        return;
    }
    let axes_width = cells
        .iter()
        .map(|c| c.axes.chars().count())
        .max()
        .unwrap_or(4)
        .clamp(4, usize::from(inside.width) / 2);
    let width = usize::from(inside.width);
    let mut lines = vec![Line::styled(
        fit(
            &format!("cell {} status   ", fit("axes", axes_width)),
            width,
        ),
        theme.dim(),
    )];
    for i in window.rows() {
        let cell = &cells[i];
        let picked = focused && i == bench.cell_cursor;
        let row = |s: Style| if picked { s.patch(theme.cursor()) } else { s };
        let lead = format!("{:04} {} ", cell.id, fit(&cell.axes, axes_width));
        let rest = width.saturating_sub(lead.chars().count() + 9);
        lines.push(Line::from(vec![
            Span::styled(lead, row(Style::new())),
            Span::styled(
                format!("{} ", fit(cell.status.name(), 8)),
                row(status_style(&cell.status, theme)),
            ),
            Span::styled(
                fit(&detail(&cell.status, cell.progress), rest),
                row(Style::new()),
            ),
        ]));
    }
    frame.render_widget(Paragraph::new(lines), inside);
}

fn draw_values(frame: &mut Frame, area: Rect, bench: &SweepView, theme: Theme) {
    let focused = bench.focus == Focus::Values;
    let title = Span::styled(
        " Values (done cells) ",
        if focused {
            theme.title().patch(theme.cursor())
        } else {
            theme.title()
        },
    );
    frame.render_widget(Block::bordered().title(title), area);
    let inside = inner(area);
    let width = usize::from(inside.width);
    if bench.values.is_empty() {
        frame.render_widget(
            Paragraph::new(Line::styled(fit("no cell done yet", width), theme.dim())),
            inside,
        );
        return;
    }
    let window = RowWindow::new(
        bench.values.len(),
        usize::from(inside.height),
        [bench.value_cursor],
    );
    let lines: Vec<Line> = window
        .rows()
        .map(|i| {
            let v = &bench.values[i];
            let text = fit(&format!("{}={} ({})", v.axis, v.value, v.cells), width);
            if i == bench.value_cursor {
                Line::styled(text, theme.cursor())
            } else {
                Line::raw(text)
            }
        })
        .collect();
    frame.render_widget(Paragraph::new(lines), inside);
}

/// The picked value's comparison: each method's runs and IQMs with their intervals.
fn draw_comparison(frame: &mut Frame, area: Rect, bench: &SweepView, theme: Theme) {
    let Some(value) = bench.values.get(bench.value_cursor) else {
        let said = if bench.computing {
            "Making the comparison of the finished cells…"
        } else {
            "The comparison of an axis value is made of its finished cells: it appears when \
             the first one is done."
        };
        frame.render_widget(
            Paragraph::new(Line::styled(said, theme.dim()))
                .wrap(ratatui::widgets::Wrap { trim: true })
                .block(Block::bordered().title(Span::styled(" Comparison ", theme.title()))),
            area,
        );
        return;
    };
    let report = &value.report;
    let title = Line::from(vec![
        Span::styled(format!(" {} = {} ", value.axis, value.value), theme.title()),
        Span::raw(format!(
            "· {} finished cells, as sweep merge's comparison.csv ",
            value.cells
        )),
    ]);
    frame.render_widget(Block::bordered().title(title), area);
    let inside = inner(area);
    let width = usize::from(inside.width);
    let digits = report.units.digits();
    let method_width = report
        .comparison
        .iter()
        .map(|c| c.method.chars().count())
        .max()
        .unwrap_or(6)
        .clamp(6, 22);
    let cell =
        |a: Option<crate::stats::Estimate>| a.map_or("-".to_string(), |e| interval(&e, digits));
    let columns: Vec<[String; 3]> = report
        .comparison
        .iter()
        .map(|c| {
            [
                c.runs.to_string(),
                cell(c.training.map(|a| a.iqm)),
                cell(c.test.map(|a| a.iqm)),
            ]
        })
        .collect();
    let heads = [
        "runs".to_string(),
        "return IQM [95% CI]".to_string(),
        format!("{} IQM [95% CI]", report.test_score.short()),
    ];
    let widths: Vec<usize> = (0..3)
        .map(|k| {
            columns
                .iter()
                .map(|c| c[k].chars().count())
                .chain([heads[k].chars().count()])
                .max()
                .unwrap_or(4)
        })
        .collect();
    let line = |method: &str, cells: &[String; 3]| {
        fit(
            &format!(
                "{} {} {} {}",
                fit(method, method_width),
                fit(&cells[0], widths[0]),
                fit(&cells[1], widths[1]),
                fit(&cells[2], widths[2])
            ),
            width,
        )
    };
    let mut lines = vec![Line::styled(line("method", &heads), theme.dim())];
    let room = usize::from(inside.height).saturating_sub(2);
    for (row, cells) in report.comparison.iter().zip(&columns).take(room) {
        lines.push(Line::raw(line(&row.method, cells)));
    }
    if report.comparison.len() > room {
        lines.push(Line::styled(
            format!("… {} more methods", report.comparison.len() - room),
            theme.dim(),
        ));
    } else if report.units == crate::report::Units::Normalised {
        lines.push(Line::styled(
            fit(
                "normalised to [0, 1] by each task's range, stratified by task",
                width,
            ),
            theme.dim(),
        ));
    }
    frame.render_widget(Paragraph::new(lines), inside);
}
