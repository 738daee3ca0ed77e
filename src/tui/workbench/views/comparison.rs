//! The Comparison view: each method's aggregate over its finished runs (IQM, mean, median
//! or optimality gap, `a` to change) of the training return and the test score, each with
//! its 95% interval as a number and as a whisker on a shared axis; below, P(X > Y) of the
//! picked method over every other by the separation rule. The numbers are the report's
//! that `comparison.csv` and `improvement.csv` are written from, printed as the stdout
//! table prints them, and the view says over how many finished runs of how many. The
//! table sorts by any of its columns (`o` the column, `O` the direction); a method of one
//! run shows its value without an interval; each pair's verdict names the better method.

use crossterm::event::{KeyCode, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Wrap};
use ratatui::Frame;

use super::Intent;
use crate::report::comparison::interval_of_runs;
use crate::report::improvement::p_value;
use crate::report::{Aggregates, MethodComparison, Report};
use crate::stats::separation::{Verdict, BOOTSTRAP_SEEDS};
use crate::stats::Estimate;
use crate::tui::keys::{ch, code, Binding};
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};
use crate::tui::workbench::cells::{counted, fit, inner, method_styles, runs_finished};
use crate::tui::workbench::folder::Compared;

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

/// A column of the table its methods are sorted by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SortColumn {
    /// The protocol's order of its methods.
    Protocol,
    Method,
    Runs,
    /// The aggregate shown of a score.
    Score(Score),
}

impl SortColumn {
    const ORDER: [SortColumn; 5] = [
        SortColumn::Protocol,
        SortColumn::Method,
        SortColumn::Runs,
        SortColumn::Score(Score::Return),
        SortColumn::Score(Score::Test),
    ];

    fn next(self) -> Self {
        let i = Self::ORDER.iter().position(|&c| c == self).unwrap_or(0);
        Self::ORDER[(i + 1) % Self::ORDER.len()]
    }

    /// Names ascend and numbers descend when first picked: the best first.
    fn descending_first(self) -> bool {
        matches!(self, SortColumn::Runs | SortColumn::Score(_))
    }
}

/// What the Comparison view's keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ComparisonCommand {
    /// The cursor by this many methods.
    Move(isize),
    NextAggregate,
    OtherScore,
    /// Sorts by the next column.
    NextSort,
    /// Sorts the other way.
    FlipSort,
}

/// The Comparison view's keys: the status bar drops the last first on a narrow terminal,
/// and the arrows need no saying.
const KEYS: &[Binding<ComparisonCommand>] = &[
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
    Binding {
        keys: &[(ch('o'), ComparisonCommand::NextSort)],
        help: (
            "o",
            "sort by the next column (protocol order, method, runs, return, test); the \
             header marks it",
        ),
        bar: Some(("o", "sort")),
    },
    Binding {
        keys: &[(ch('O'), ComparisonCommand::FlipSort)],
        help: ("O", "sort the other way"),
        bar: Some(("O", "flip")),
    },
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
];

/// The methods side by side: aggregates with intervals, whiskers, pairs.
#[derive(Debug)]
pub struct ComparisonView {
    pub aggregate: Aggregate,
    /// The score whose pairs the view lists (and the only one it shows on a terminal too
    /// narrow for both).
    pub score: Score,
    /// The picked method, by its place in the protocol.
    pub cursor: usize,
    /// The column the table is sorted by, and whether the largest come first.
    pub sort: SortColumn,
    pub descending: bool,
}

impl Default for ComparisonView {
    fn default() -> Self {
        Self {
            aggregate: Aggregate::Iqm,
            score: Score::Return,
            cursor: 0,
            sort: SortColumn::Protocol,
            descending: false,
        }
    }
}

impl ComparisonView {
    /// Keeps the cursor on a method of a folder read again.
    pub fn refreshed(&mut self, folder: &dyn Compared) {
        self.cursor = self.cursor.min(folder.methods().len().saturating_sub(1));
    }

    /// The methods, by their place in the protocol, in the order the table lists them:
    /// sorted by the view's column and direction, a method without a value last either
    /// way, ties in the protocol's order.
    pub fn order(&self, model: &dyn Compared) -> Vec<usize> {
        let labels = labels(model);
        let mut order: Vec<usize> = (0..labels.len()).collect();
        let row = |i: usize| {
            model
                .report()
                .and_then(|r| r.comparison.iter().find(|c| c.method == labels[i]))
        };
        let value = |i: usize| -> Option<f64> {
            match self.sort {
                SortColumn::Protocol => Some(i as f64),
                SortColumn::Method => None,
                SortColumn::Runs => Some(row(i).map_or(0.0, |r| r.runs as f64)),
                SortColumn::Score(score) => row(i)
                    .and_then(|r| aggregates_of(r, score))
                    .map(|a| estimate(a, self.aggregate).point)
                    .filter(|v| v.is_finite()),
            }
        };
        let direction = |o: std::cmp::Ordering| if self.descending { o.reverse() } else { o };
        order.sort_by(|&a, &b| match self.sort {
            SortColumn::Method => direction(labels[a].cmp(&labels[b])),
            _ => match (value(a), value(b)) {
                (Some(x), Some(y)) => direction(x.total_cmp(&y)),
                (Some(_), None) => std::cmp::Ordering::Less,
                (None, Some(_)) => std::cmp::Ordering::Greater,
                (None, None) => std::cmp::Ordering::Equal,
            },
        });
        order
    }

    /// `▼` or `▲` after the header of the column sorted by (none in the protocol's order).
    fn mark(&self, column: SortColumn) -> &'static str {
        match (
            self.sort == column && column != SortColumn::Protocol,
            self.descending,
        ) {
            (false, _) => "",
            (true, true) => " ▼",
            (true, false) => " ▲",
        }
    }
}

/// The folder's methods' labels, in its order.
fn labels(model: &dyn Compared) -> Vec<String> {
    model
        .methods()
        .iter()
        .map(|m| m.label().to_string())
        .collect()
}

impl View for ComparisonView {
    type Model = dyn Compared;
    type Command = ComparisonCommand;
    type Intent = Intent;

    fn keys(&self) -> &'static [Binding<ComparisonCommand>] {
        KEYS
    }

    fn apply(&mut self, folder: &dyn Compared, command: ComparisonCommand) -> Outcome<Intent> {
        match command {
            ComparisonCommand::Move(by) => {
                // Along the table's order, not the protocol's.
                let order = self.order(folder);
                let at = order.iter().position(|&m| m == self.cursor).unwrap_or(0);
                let last = order.len().saturating_sub(1) as isize;
                let to = (at as isize + by).clamp(0, last) as usize;
                self.cursor = order.get(to).copied().unwrap_or(0);
            }
            ComparisonCommand::NextSort => {
                self.sort = self.sort.next();
                self.descending = self.sort.descending_first();
            }
            ComparisonCommand::FlipSort => self.descending = !self.descending,
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

    fn draw(&self, folder: &dyn Compared, frame: &mut Frame, area: Rect, theme: Theme) {
        draw(frame, area, self, folder, theme);
    }

    fn legend(&self, _: &dyn Compared) -> Vec<(&'static str, &'static str)> {
        vec![(
            "click",
            "a method's row picks it; a view's name below shows it",
        )]
    }

    fn on_mouse(
        &mut self,
        folder: &dyn Compared,
        mouse: MouseEvent,
        area: Rect,
    ) -> Outcome<Intent> {
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

fn draw(frame: &mut Frame, area: Rect, view: &ComparisonView, model: &dyn Compared, theme: Theme) {
    let Some(report) = model.report() else {
        frame.render_widget(
            Paragraph::new(vec![
                Line::from(coverage(model)),
                Line::from(""),
                Line::styled(
                    if model.computing() {
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
fn areas(area: Rect, model: &dyn Compared) -> [Rect; 3] {
    let methods = model.methods().len() as u16;
    let table_height = (methods + 5).min(area.height.saturating_sub(1 + PAIRS_LINES));
    Layout::vertical([
        Constraint::Length(1),
        Constraint::Length(table_height),
        Constraint::Fill(1),
    ])
    .areas(area)
}

/// The table's rows (places in [`ComparisonView::order`]) its inside `inside` shows,
/// below its header line and above its axis line.
fn window(inside: Rect, order: &[usize], view: &ComparisonView) -> RowWindow {
    let room = usize::from(inside.height).saturating_sub(2);
    let at = order.iter().position(|&m| m == view.cursor).unwrap_or(0);
    RowWindow::new(order.len(), room, [at])
}

/// The method whose row of the table is at (`column`, `row`) of the screen, the view
/// drawn in `area`: what a click picks.
fn method_at(
    area: Rect,
    view: &ComparisonView,
    model: &dyn Compared,
    column: u16,
    row: u16,
) -> Option<usize> {
    model.report()?;
    let [_, table, _] = areas(area, model);
    let inside = inner(table);
    let first = inside.y + 1;
    if !(inside.x..inside.x + inside.width).contains(&column) || row < first {
        return None;
    }
    let order = view.order(model);
    window(inside, &order, view)
        .row_at(usize::from(row - first))
        .and_then(|at| order.get(at).copied())
}

/// Over how many runs: every planned one, or (partial) the finished ones so far.
fn coverage(model: &dyn Compared) -> String {
    let (finished, planned) = (model.finished_runs(), model.runs().len());
    if model.report().is_none() {
        format!(" {}", runs_finished(finished, planned))
    } else if finished == planned {
        let all = if planned == 1 {
            "its one run".to_string()
        } else {
            format!("all {planned} runs")
        };
        format!(" over {all} (as comparison.csv and improvement.csv)")
    } else {
        format!(
            " partial: over the {finished} finished of {} ({} not finished); made again as \
             runs end",
            counted(planned, "run"),
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

/// A score's column's header: `return IQM [95% CI]`, marked when the table is sorted by it.
fn score_header(report: &Report, score: Score, view: &ComparisonView) -> String {
    format!(
        "{} {} [95% CI]{}",
        score_name(report, score),
        view.aggregate.name(),
        view.mark(SortColumn::Score(score))
    )
}

/// The text of a method's aggregate: its interval, or its value alone over one run.
fn value_text(row: Option<&MethodComparison>, e: &Estimate, digits: usize) -> String {
    interval_of_runs(e, row.map_or(0, |r| r.runs), digits)
}

/// Each score's column: the intervals as text, and the whiskers' shared axis.
fn score_columns(
    rows: &[Option<&MethodComparison>],
    scores: &[Score],
    view: &ComparisonView,
    report: &Report,
) -> Vec<ScoreColumn> {
    let aggregate = view.aggregate;
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
            let header = score_header(report, score, view);
            let width = estimates
                .iter()
                .zip(rows)
                .filter_map(|(e, row)| Some(value_text(*row, e.as_ref()?, digits)))
                .map(|text| text.chars().count())
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
    (view, model): (&ComparisonView, &dyn Compared),
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
    let methods = model.methods();
    let labels = labels(model);
    let rows: Vec<Option<&MethodComparison>> = labels
        .iter()
        .map(|l| report.comparison.iter().find(|c| &c.method == l))
        .collect();
    let scores = shown_scores(area.width, view.score);
    let digits = digits(report, aggregate);
    let columns = score_columns(&rows, &scores, view, report);
    let method_width = labels
        .iter()
        .map(|l| l.chars().count())
        .max()
        .unwrap_or(6)
        .clamp(6, 22);
    let runs_width = 6;
    let texts: usize = columns.iter().map(|c| c.width + 2).sum();
    let spare = usize::from(inside.width).saturating_sub(method_width + 1 + runs_width + texts);
    let whisker_width = (spare / columns.len()).saturating_sub(1).max(3);

    let mut header = vec![Span::raw(format!(
        "{} {}",
        fit(
            &format!("method{}", view.mark(SortColumn::Method)),
            method_width
        ),
        fit(&format!("runs{}", view.mark(SortColumn::Runs)), runs_width)
    ))];
    for column in &columns {
        header.push(Span::raw(format!(
            " {} ",
            fit(&score_header(report, column.score, view), column.width)
        )));
        header.push(Span::raw(format!("{} ", fit("", whisker_width))));
    }
    let mut lines = vec![Line::from(header).style(theme.dim())];
    let order = view.order(model);
    let window = window(inside, &order, view);
    let kinds: Vec<_> = methods.iter().map(|m| m.kind).collect();
    let styles = method_styles(&kinds, theme);
    for i in window.rows().map(|at| order[at]) {
        let picked = i == view.cursor;
        let style = |s: Style| if picked { s.patch(theme.cursor()) } else { s };
        let runs = format!(
            "{}/{}",
            rows[i].map_or(0, |r| r.runs),
            model.planned_runs(i)
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
                    value_text(rows[i], &e, digits),
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
    model: &dyn Compared,
    report: &Report,
    theme: Theme,
) {
    let Some(method) = labels(model).into_iter().nth(view.cursor) else {
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
    let judgements: Vec<String> = rows.iter().map(|r| r.judgement()).collect();
    // Aligned where the lines fit; on a narrow panel, not padded into a wrapped gap.
    let judgement_width = if area.width >= BOTH_SCORES_WIDTH {
        judgements
            .iter()
            .map(|j| j.chars().count())
            .max()
            .unwrap_or(0)
    } else {
        0
    };
    let rule = Line::styled(
        format!(
            "separated: {BOOTSTRAP_SEEDS} seeds' intervals exclude ½, Holm p < 0.05 · s: other \
             score"
        ),
        theme.dim(),
    );
    let mut lines: Vec<Line> = std::iter::once(rule)
        .chain(rows.iter().zip(&judgements).map(|(r, judgement)| {
            let verdict_style = match r.verdict {
                Verdict::Separated => theme.active(),
                Verdict::Fragile => theme.spreading(),
                Verdict::NotSeparated => theme.dim(),
            };
            let mut spans = vec![
                Span::raw(format!(
                    "vs {}  P = {:.2} [{:.2}, {:.2}]  ",
                    fit(&r.over, over_width),
                    r.p.point,
                    r.p.lo,
                    r.p.hi
                )),
                // The better method named first, whichever way the row reads.
                Span::styled(
                    fit(judgement, judgement_width.max(judgement.chars().count())),
                    verdict_style,
                ),
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
