//! The Comparison view: each method's aggregate over its finished runs (IQM, mean, median
//! or optimality gap, `a` to change) of the training return and the test score, each with
//! its 95% interval as a number and as a whisker on a shared axis; below, P(X > Y) of the
//! picked method over every other by the separation rule. The numbers are the report's
//! that `comparison.csv` and `improvement.csv` are written from, printed as the stdout
//! table prints them, and the view says over how many finished runs of how many.

use crossterm::event::{KeyCode, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Wrap};
use ratatui::Frame;

use super::Intent;
use crate::report::comparison::interval;
use crate::report::improvement::p_value;
use crate::report::{Aggregates, MethodComparison, Report};
use crate::stats::separation::{Verdict, BOOTSTRAP_SEEDS};
use crate::stats::Estimate;
use crate::tui::keys::{ch, code, Binding};
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};
use crate::tui::workbench::cells::{fit, inner, method_styles};
use crate::tui::workbench::folder::Folder;

/// Which aggregate over runs the Comparison view shows, as `comparison.csv` names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Aggregate {
    Iqm,
    Mean,
    Median,
    OptimalityGap,
}

impl Aggregate {
    const ORDER: [Aggregate; 4] = [
        Aggregate::Iqm,
        Aggregate::Mean,
        Aggregate::Median,
        Aggregate::OptimalityGap,
    ];

    /// As the table's header says it (`IQM`, as the stdout table does).
    pub fn name(self) -> &'static str {
        match self {
            Aggregate::Iqm => "IQM",
            Aggregate::Mean => "mean",
            Aggregate::Median => "median",
            Aggregate::OptimalityGap => "optimality gap",
        }
    }

    fn next(self) -> Self {
        let i = Self::ORDER.iter().position(|&a| a == self).unwrap_or(0);
        Self::ORDER[(i + 1) % Self::ORDER.len()]
    }
}

/// A score of the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Score {
    /// The training return: the headline, which pairs are ranked by.
    Return,
    /// The greedy test score of what a run hands over.
    Test,
}

impl Score {
    /// As `improvement.csv`'s `score` column says it.
    pub fn column(self) -> &'static str {
        match self {
            Score::Return => "return",
            Score::Test => "test",
        }
    }
}

/// What the Comparison view's keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ComparisonCommand {
    /// The cursor by this many methods.
    Move(isize),
    NextAggregate,
    OtherScore,
}

/// The Comparison view's keys.
const KEYS: &[Binding<ComparisonCommand>] = &[
    Binding {
        keys: &[
            (code(KeyCode::Up), ComparisonCommand::Move(-1)),
            (ch('k'), ComparisonCommand::Move(-1)),
            (code(KeyCode::Down), ComparisonCommand::Move(1)),
            (ch('j'), ComparisonCommand::Move(1)),
            (code(KeyCode::PageUp), ComparisonCommand::Move(-10)),
            (code(KeyCode::PageDown), ComparisonCommand::Move(10)),
        ],
        help: (
            "↑ ↓ j k, PgUp PgDn",
            "pick a method: its P(X > Y) over every other below",
        ),
        bar: Some(("↑↓", "method")),
    },
    Binding {
        keys: &[(ch('a'), ComparisonCommand::NextAggregate)],
        help: (
            "a",
            "the next aggregate (IQM, mean, median, optimality gap)",
        ),
        bar: Some(("a", "aggregate")),
    },
    Binding {
        keys: &[(ch('s'), ComparisonCommand::OtherScore)],
        help: (
            "s",
            "the pairs of the other score (training return or test score); below 100 \
             columns, the table's too",
        ),
        bar: Some(("s", "score")),
    },
];

/// The methods side by side: aggregates with intervals, whiskers, pairs.
#[derive(Debug)]
pub struct ComparisonView {
    pub aggregate: Aggregate,
    /// The score whose pairs the view lists (and the only one it shows on a terminal too
    /// narrow for both).
    pub score: Score,
    /// The picked method.
    pub cursor: usize,
}

impl Default for ComparisonView {
    fn default() -> Self {
        Self {
            aggregate: Aggregate::Iqm,
            score: Score::Return,
            cursor: 0,
        }
    }
}

impl ComparisonView {
    /// Keeps the cursor on a method of a folder read again.
    pub fn refreshed(&mut self, folder: &Folder) {
        self.cursor = self.cursor.min(folder.methods().saturating_sub(1));
    }
}

impl View for ComparisonView {
    type Model = Folder;
    type Command = ComparisonCommand;
    type Intent = Intent;

    fn keys(&self) -> &'static [Binding<ComparisonCommand>] {
        KEYS
    }

    fn apply(&mut self, folder: &Folder, command: ComparisonCommand) -> Outcome<Intent> {
        match command {
            ComparisonCommand::Move(by) => {
                let last = folder.methods().saturating_sub(1) as isize;
                self.cursor = (self.cursor as isize + by).clamp(0, last) as usize;
            }
            ComparisonCommand::NextAggregate => self.aggregate = self.aggregate.next(),
            ComparisonCommand::OtherScore => {
                self.score = match self.score {
                    Score::Return => Score::Test,
                    Score::Test => Score::Return,
                };
            }
        }
        Outcome::Done
    }

    fn draw(&self, folder: &Folder, frame: &mut Frame, area: Rect, theme: Theme) {
        draw(frame, area, self, folder, theme);
    }

    fn legend(&self, _: &Folder) -> Vec<(&'static str, &'static str)> {
        vec![(
            "click",
            "a method's row picks it; a view's name below shows it",
        )]
    }

    fn on_mouse(&mut self, folder: &Folder, mouse: MouseEvent, area: Rect) -> Outcome<Intent> {
        if mouse.kind != MouseEventKind::Down(MouseButton::Left) {
            return Outcome::Ignored;
        }
        match method_at(area, self, folder, mouse.column, mouse.row) {
            Some(method) => {
                self.cursor = method;
                Outcome::Done
            }
            None => Outcome::Ignored,
        }
    }
}

/// Below this width the table shows one score (`s` switches), with room for its whisker.
const BOTH_SCORES_WIDTH: u16 = 100;

/// The fewest lines the pairs' panel keeps (its borders and three pairs).
const PAIRS_LINES: u16 = 5;

fn draw(frame: &mut Frame, area: Rect, view: &ComparisonView, model: &Folder, theme: Theme) {
    let Some(report) = &model.report else {
        frame.render_widget(
            Paragraph::new(vec![
                Line::from(coverage(model)),
                Line::from(""),
                Line::styled(
                    if model.computing {
                        "Making the comparison of the finished runs (the bootstrap takes a \
                         moment)…"
                    } else {
                        "No run has finished yet: the comparison is made of finished runs, \
                         and appears when the first one ends."
                    },
                    theme.dim(),
                ),
            ])
            .block(Block::bordered().title(Span::styled(" Comparison ", theme.title()))),
            area,
        );
        return;
    };
    let [said, table, pairs] = areas(area, model);
    frame.render_widget(Paragraph::new(coverage(model)), said);
    draw_table(frame, table, (view, model), report, theme);
    draw_pairs(frame, pairs, view, model, report, theme);
}

/// The line saying over how many runs, the table, the pairs.
fn areas(area: Rect, model: &Folder) -> [Rect; 3] {
    let methods = model.methods() as u16;
    let table_height = (methods + 5).min(area.height.saturating_sub(1 + PAIRS_LINES));
    Layout::vertical([
        Constraint::Length(1),
        Constraint::Length(table_height),
        Constraint::Fill(1),
    ])
    .areas(area)
}

/// The methods the table's inside `inside` shows, below its header line and above its
/// axis line.
fn window(inside: Rect, view: &ComparisonView, model: &Folder) -> RowWindow {
    let room = usize::from(inside.height).saturating_sub(2);
    RowWindow::new(model.methods(), room, [view.cursor])
}

/// The method whose row of the table is at (`column`, `row`) of the screen, the view
/// drawn in `area`: what a click picks.
fn method_at(
    area: Rect,
    view: &ComparisonView,
    model: &Folder,
    column: u16,
    row: u16,
) -> Option<usize> {
    model.report.as_ref()?;
    let [_, table, _] = areas(area, model);
    let inside = inner(table);
    let first = inside.y + 1;
    if !(inside.x..inside.x + inside.width).contains(&column) || row < first {
        return None;
    }
    window(inside, view, model).row_at(usize::from(row - first))
}

/// Over how many runs: every planned one, or (partial) the finished ones so far.
fn coverage(model: &Folder) -> String {
    let folder = &model.state;
    let (finished, planned) = (folder.finished_runs(), folder.runs.len());
    if model.report.is_none() {
        format!(" {finished} of {planned} runs finished")
    } else if finished == planned {
        format!(" over all {planned} runs (as comparison.csv and improvement.csv)")
    } else {
        format!(
            " partial: over the {finished} finished runs of {planned} ({} not finished); \
             made again as runs end",
            planned - finished
        )
    }
}

/// The scores the table shows at this width.
fn shown_scores(width: u16, picked: Score) -> Vec<Score> {
    if width >= BOTH_SCORES_WIDTH {
        vec![Score::Return, Score::Test]
    } else {
        vec![picked]
    }
}

fn aggregates_of(row: &MethodComparison, score: Score) -> Option<&Aggregates> {
    match score {
        Score::Return => row.training.as_ref(),
        Score::Test => row.test.as_ref(),
    }
}

fn estimate(aggregates: &Aggregates, aggregate: Aggregate) -> Estimate {
    match aggregate {
        Aggregate::Iqm => aggregates.iqm,
        Aggregate::Mean => aggregates.mean,
        Aggregate::Median => aggregates.median,
        Aggregate::OptimalityGap => aggregates.optimality_gap,
    }
}

/// Decimals as the stdout table prints the aggregate: the optimality gap is of normalised
/// scores, the others in the report's units.
fn digits(report: &Report, aggregate: Aggregate) -> usize {
    match aggregate {
        Aggregate::OptimalityGap => crate::report::Units::Normalised.digits(),
        _ => report.units.digits(),
    }
}

fn score_name(report: &Report, score: Score) -> String {
    match score {
        Score::Return => "return".into(),
        Score::Test => report.test_score.short().into(),
    }
}

/// The whiskers' axis: its ends under each score's whiskers; under the methods, whether
/// the table hides some.
fn axis_line(
    columns: &[ScoreColumn],
    (method_width, runs_width, whisker_width): (usize, usize, usize),
    more: bool,
    digits: usize,
) -> Vec<Span<'static>> {
    let mut axis_line = vec![Span::raw(format!(
        "{} {}",
        fit(if more { "▲▼ more (↑↓)" } else { "" }, method_width),
        fit("", runs_width)
    ))];
    for column in columns {
        let (low, high) = column.axis;
        axis_line.push(Span::raw(format!(" {} ", fit("", column.width))));
        let (low, high) = (format!("{low:.digits$}"), format!("{high:.digits$}"));
        let gap = whisker_width.saturating_sub(low.chars().count() + high.chars().count());
        axis_line.push(Span::raw(fit(
            &format!("{low}{}{high} ", " ".repeat(gap)),
            whisker_width + 1,
        )));
    }
    axis_line
}

/// Each score's column: the intervals as text, and the whiskers' shared axis.
fn score_columns(
    rows: &[Option<&MethodComparison>],
    scores: &[Score],
    aggregate: Aggregate,
    report: &Report,
) -> Vec<ScoreColumn> {
    let digits = digits(report, aggregate);
    scores
        .iter()
        .map(|&score| {
            let estimates: Vec<Option<Estimate>> = rows
                .iter()
                .map(|r| {
                    r.and_then(|r| aggregates_of(r, score))
                        .map(|a| estimate(a, aggregate))
                })
                .collect();
            let header = format!(
                "{} {} [95% CI]",
                score_name(report, score),
                aggregate.name()
            );
            let width = estimates
                .iter()
                .flatten()
                .map(|e| interval(e, digits).chars().count())
                .chain([header.chars().count()])
                .max()
                .unwrap_or(1);
            let axis = axis(&estimates);
            ScoreColumn {
                score,
                estimates,
                width,
                axis,
            }
        })
        .collect()
}

fn draw_table(
    frame: &mut Frame,
    area: Rect,
    (view, model): (&ComparisonView, &Folder),
    report: &Report,
    theme: Theme,
) {
    let aggregate = view.aggregate;
    let title = Line::from(vec![
        Span::styled(format!(" {} ", aggregate.name()), theme.title()),
        Span::raw("of each method's finished runs, 95% stratified bootstrap intervals "),
    ]);
    frame.render_widget(Block::bordered().title(title), area);
    let inside = inner(area);
    if inside.height < 3 {
        return;
    }
    let folder = &model.state;
    let labels: Vec<String> = folder
        .config
        .protocol
        .methods
        .iter()
        .map(|m| m.label())
        .collect();
    let rows: Vec<Option<&MethodComparison>> = labels
        .iter()
        .map(|l| report.comparison.iter().find(|c| &c.method == l))
        .collect();
    let scores = shown_scores(area.width, view.score);
    let digits = digits(report, aggregate);
    let columns = score_columns(&rows, &scores, aggregate, report);
    let method_width = labels
        .iter()
        .map(|l| l.chars().count())
        .max()
        .unwrap_or(6)
        .clamp(6, 22);
    let runs_width = 5;
    let texts: usize = columns.iter().map(|c| c.width + 2).sum();
    let spare = usize::from(inside.width).saturating_sub(method_width + 1 + runs_width + texts);
    let whisker_width = (spare / columns.len()).saturating_sub(1).max(3);

    let mut header = vec![Span::raw(format!(
        "{} {}",
        fit("method", method_width),
        fit("runs", runs_width)
    ))];
    for column in &columns {
        header.push(Span::raw(format!(
            " {} ",
            fit(
                &format!(
                    "{} {} [95% CI]",
                    score_name(report, column.score),
                    aggregate.name()
                ),
                column.width
            )
        )));
        header.push(Span::raw(format!("{} ", fit("", whisker_width))));
    }
    let mut lines = vec![Line::from(header).style(theme.dim())];
    let window = window(inside, view, model);
    let styles = method_styles(folder, theme);
    for i in window.rows() {
        let picked = i == view.cursor;
        let style = |s: Style| if picked { s.patch(theme.cursor()) } else { s };
        let runs = format!(
            "{}/{}",
            rows[i].map_or(0, |r| r.runs),
            folder.config.protocol.runs
        );
        let mut spans = vec![
            Span::styled(
                fit(&labels[i], method_width),
                style(styles.get(i).copied().unwrap_or_default()),
            ),
            Span::styled(format!(" {}", fit(&runs, runs_width)), style(Style::new())),
        ];
        for column in &columns {
            let (text, whisker) = match column.estimates[i] {
                Some(e) => (
                    interval(&e, digits),
                    whisker(&e, column.axis, whisker_width),
                ),
                None => ("-".to_string(), String::new()),
            };
            spans.push(Span::styled(
                format!(" {} ", fit(&text, column.width)),
                style(Style::new()),
            ));
            spans.push(Span::styled(
                format!("{} ", fit(&whisker, whisker_width)),
                styles.get(i).copied().unwrap_or_default(),
            ));
        }
        lines.push(Line::from(spans));
    }
    let more = window.shown < window.total;
    let axis_line = axis_line(
        &columns,
        (method_width, runs_width, whisker_width),
        more,
        digits,
    );
    lines.push(Line::from(axis_line).style(theme.dim()));
    frame.render_widget(Paragraph::new(lines), inside);
}

/// A score's columns in the table: its intervals as text, and its whiskers.
struct ScoreColumn {
    score: Score,
    /// Each method's aggregate, in the protocol's order (`None`: no finished run).
    estimates: Vec<Option<Estimate>>,
    /// The text column's width.
    width: usize,
    /// The axis its whiskers share.
    axis: (f64, f64),
}

/// The axis the whiskers of a column share: from the lowest interval's end to the
/// highest's.
fn axis(estimates: &[Option<Estimate>]) -> (f64, f64) {
    let low = estimates
        .iter()
        .flatten()
        .map(|e| e.lo)
        .fold(f64::INFINITY, f64::min);
    let high = estimates
        .iter()
        .flatten()
        .map(|e| e.hi)
        .fold(f64::NEG_INFINITY, f64::max);
    if low.is_finite() && high.is_finite() {
        (low, high)
    } else {
        (0.0, 0.0)
    }
}

/// An interval as a whisker `├──●──┤` of `width` columns on `axis`: its ends and its
/// point where they fall.
pub fn whisker(e: &Estimate, (low, high): (f64, f64), width: usize) -> String {
    if width == 0 {
        return String::new();
    }
    let at = |x: f64| -> usize {
        if high > low {
            (((x - low) / (high - low)).clamp(0.0, 1.0) * (width - 1) as f64).round() as usize
        } else {
            (width - 1) / 2
        }
    };
    let (from, point, to) = (at(e.lo), at(e.point), at(e.hi));
    (0..width)
        .map(|i| match i {
            _ if i == point => '●',
            _ if i == from => '├',
            _ if i == to => '┤',
            _ if i > from && i < to => '─',
            _ => ' ',
        })
        .collect()
}

fn draw_pairs(
    frame: &mut Frame,
    area: Rect,
    view: &ComparisonView,
    model: &Folder,
    report: &Report,
    theme: Theme,
) {
    let folder = &model.state;
    let Some(method) = folder
        .config
        .protocol
        .methods
        .get(view.cursor)
        .map(|m| m.label())
    else {
        return;
    };
    let score = view.score;
    let title = Line::from(vec![
        Span::styled(format!(" P({method} > Y) "), theme.title()),
        Span::raw(format!(
            "on the {} ",
            match score {
                Score::Return => "training return".to_string(),
                Score::Test => report.test_score.long(),
            }
        )),
    ]);
    let rows: Vec<_> = report
        .improvement
        .iter()
        .filter(|r| r.score == score.column() && r.method == method)
        .collect();
    let over_width = rows
        .iter()
        .map(|r| r.over.chars().count())
        .max()
        .unwrap_or(4)
        .min(22);
    let rule = Line::styled(
        format!(
            "separated: {BOOTSTRAP_SEEDS} seeds' intervals exclude ½, Holm p < 0.05 · s: other \
             score"
        ),
        theme.dim(),
    );
    let mut lines: Vec<Line> = std::iter::once(rule)
        .chain(rows.iter().map(|r| {
            let verdict_style = match r.verdict {
                Verdict::Separated => theme.active(),
                Verdict::Fragile => theme.spreading(),
                Verdict::NotSeparated => theme.dim(),
            };
            let mut spans = vec![
                Span::raw(format!(
                    "over {}  P = {:.2} [{:.2}, {:.2}]  ",
                    fit(&r.over, over_width),
                    r.p.point,
                    r.p.lo,
                    r.p.hi
                )),
                Span::styled(fit(r.verdict.name(), 13), verdict_style),
                Span::raw(format!(
                    "  Holm p = {}, {}/{BOOTSTRAP_SEEDS} seeds",
                    p_value(r.holm_p),
                    r.seeds_excluding
                )),
            ];
            if let Some(n) = r.runs_needed {
                spans.push(Span::styled(format!(", {n} runs to detect"), theme.dim()));
            }
            Line::from(spans)
        }))
        .collect();
    if rows.is_empty() {
        lines.push(Line::styled(
            format!("{method} has no pair yet: a pair needs finished runs of both methods"),
            theme.dim(),
        ));
    }
    frame.render_widget(
        // A pair's line wraps on a narrow terminal rather than lose its end.
        Paragraph::new(lines)
            .wrap(Wrap { trim: false })
            .block(Block::bordered().title(title)),
        area,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whisker_marks_its_ends_and_point_on_the_shared_axis() {
        let e = Estimate {
            point: 5.0,
            lo: 2.0,
            hi: 8.0,
        };
        assert_eq!(whisker(&e, (0.0, 10.0), 11), "  ├──●──┤  ");
        // One run: no spread, the point alone, in the middle of a flat axis.
        let one = Estimate {
            point: 3.0,
            lo: 3.0,
            hi: 3.0,
        };
        assert_eq!(whisker(&one, (3.0, 3.0), 5), "  ●  ");
        assert_eq!(axis(&[Some(e), None, Some(one)]), (2.0, 8.0));
    }
}
