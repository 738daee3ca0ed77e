//! Drawing the dashboard and teach mode: pure functions of the state, so the snapshot
//! tests draw exactly what a user sees.

use ratatui::layout::{Constraint, Layout, Position, Rect};
use ratatui::style::Modifier;
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Cell, Chart, Dataset, GraphType, Paragraph, Row, Table, Wrap};
use ratatui::Frame;

use super::dashboard::{Clicked, Dashboard, Focus, Mode, RunView, SapNetView, HISTORY, SPEEDS};
use super::graph_layout;
use super::graph_view::{self, node_style, Scene};
use super::reference::Band;
use super::row_window::RowWindow;
use super::screen::{draw_help, probability_bar, too_small};
use super::step_line::step_line;
use super::theme::Theme;
use crate::teach::labels;

/// Draws the whole dashboard (or teach mode on the live graph, or the help overlay).
pub fn draw_dashboard(frame: &mut Frame, dashboard: &Dashboard, theme: Theme) {
    let area = frame.area();
    if too_small(frame, area) {
        return;
    }
    let [main, status] = Layout::vertical([Constraint::Min(0), Constraint::Length(1)]).areas(area);
    match (&dashboard.teach, dashboard.mode) {
        (Some(teach), Mode::Teach) => super::teach_view::draw_body(frame, main, teach, theme),
        _ => draw_training(frame, dashboard, theme),
    }
    draw_status(frame, status, dashboard, theme);
    if dashboard.help {
        if let (Some(teach), Mode::Teach) = (&dashboard.teach, dashboard.mode) {
            draw_help(
                frame,
                area,
                &super::teach_view::teach_help(teach, true),
                theme,
            );
        } else {
            draw_help(frame, area, HELP, theme);
        }
    }
}

/// Where the dashboard's panels are on a screen of `area`: drawing and mouse clicks use
/// the same rectangles. A panel that is not shown (another is zoomed) has an empty one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TrainingLayout {
    pub graph: Rect,
    pub table: Rect,
    pub rewards: Rect,
    pub loss: Rect,
    pub step: Rect,
}

/// What a left click at `(column, row)` of a screen of `area` showing `dashboard` lands
/// on, found in the rectangles the screen was drawn in.
pub fn clicked(dashboard: &Dashboard, area: Rect, column: u16, row: u16) -> Option<Clicked> {
    if dashboard.mode == Mode::Teach {
        let teach = dashboard.teach.as_ref()?;
        return super::teach_view::clicked(teach, area, column, row).map(Clicked::Teach);
    }
    let view = dashboard.sapnet.as_ref()?;
    let layout = training_layout(area, dashboard.zoomed());
    let inside = |r: Rect| r.contains(Position::new(column, row));
    if inside(layout.table) {
        // The rows as drawn, below the border and the header row.
        let window = policy_rows(layout.table, dashboard);
        let policy = row
            .checked_sub(layout.table.y + 2)
            .and_then(|line| window.row_at(usize::from(line)));
        return Some(Clicked::Table(policy));
    }
    if inside(layout.graph) {
        let positions = graph_layout::positions(view.policies.len(), Some(&view.categories()));
        let node = graph_layout::canvas_point(layout.graph, column, row)
            .and_then(|point| graph_layout::node_at(&positions, point, graph_layout::CLICK_REACH));
        return Some(Clicked::Graph(node));
    }
    None
}

/// The panels of the training view on a terminal of `area` (the status bar included).
pub fn training_layout(area: Rect, zoom: Option<Focus>) -> TrainingLayout {
    let [main, _status] = Layout::vertical([Constraint::Min(0), Constraint::Length(1)]).areas(area);
    let [panels, step] = Layout::vertical([Constraint::Min(0), Constraint::Length(1)]).areas(main);
    match zoom {
        Some(Focus::Graph) => TrainingLayout {
            graph: panels,
            step,
            ..TrainingLayout::default()
        },
        Some(Focus::Table) => TrainingLayout {
            table: panels,
            step,
            ..TrainingLayout::default()
        },
        None => {
            let [top, bottom] =
                Layout::vertical([Constraint::Percentage(55), Constraint::Percentage(45)])
                    .areas(panels);
            let [graph, table] =
                Layout::horizontal([Constraint::Percentage(40), Constraint::Percentage(60)])
                    .areas(top);
            let [rewards, loss] =
                Layout::horizontal([Constraint::Percentage(68), Constraint::Percentage(32)])
                    .areas(bottom);
            TrainingLayout {
                graph,
                table,
                rewards,
                loss,
                step,
            }
        }
    }
}

fn draw_training(frame: &mut Frame, dashboard: &Dashboard, theme: Theme) {
    let TrainingLayout {
        graph,
        table,
        rewards,
        loss,
        step,
    } = training_layout(frame.area(), dashboard.zoomed());
    frame.render_widget(
        Paragraph::new(step_line(dashboard, step.width, theme)),
        step,
    );
    let focus_block = |title: &str, focused: bool| {
        let block = Block::bordered().title(Span::styled(format!(" {title} "), theme.title()));
        if focused {
            block.border_style(theme.title())
        } else {
            block.border_style(theme.dim())
        }
    };
    match &dashboard.sapnet {
        Some(view) => {
            let names: Vec<String> = view.policies.iter().map(|p| p.name.clone()).collect();
            let groups = view.categories();
            let group_names = view.task_groups();
            let lit: Vec<(usize, usize)> = view
                .spread
                .filter(|&(p, _)| view.glows(p, dashboard.step))
                .map(|(p, _)| {
                    view.net
                        .graph()
                        .neighbours(p)
                        .map(|(j, _)| (p, j))
                        .collect()
                })
                .unwrap_or_default();
            let scene = Scene {
                net: &view.net,
                names: &names,
                groups: Some(&groups),
                group_names: &group_names,
                cursor: Some(dashboard.cursor),
                active: view.acting,
                lit: &lit,
                walking: None,
                excluded: &view.excluded,
            };
            let mut graph_title = if view.score_name == "A" {
                "SAP-Net graph".to_string()
            } else {
                format!("library graph · {} ({})", view.method, view.score_name)
            };
            let out = view.excluded.iter().filter(|&&e| e).count();
            if out > 0 {
                graph_title.push_str(&format!(" · × {out} excluded"));
            }
            if !graph.is_empty() {
                graph_view::draw(
                    frame,
                    graph,
                    focus_block(&graph_title, dashboard.focus == Focus::Graph),
                    scene,
                    theme,
                );
            }
            if !table.is_empty() {
                draw_policy_table(
                    frame,
                    table,
                    focus_block(
                        &policies_title(dashboard, table.width),
                        dashboard.focus == Focus::Table,
                    ),
                    view,
                    dashboard,
                    theme,
                );
            }
        }
        None => {
            // Before a followed run's first step it is still loading its library or
            // starting its task (a Gymnasium worker takes a second or more).
            let note = match &dashboard.followed {
                Some(method) => format!("{method}: loading the library and starting the task…"),
                None => "This config runs no SAP-Net: only its baselines train.".to_string(),
            };
            let note = Paragraph::new(note)
                .block(focus_block("SAP-Net graph", false))
                .wrap(Wrap { trim: true });
            let top = match (graph.is_empty(), table.is_empty()) {
                (true, _) => table,
                (_, true) => graph,
                _ => graph.union(table),
            };
            frame.render_widget(note, top);
        }
    }
    if !rewards.is_empty() {
        draw_rewards(frame, rewards, &dashboard.runs, &dashboard.reference, theme);
        draw_loss(frame, loss, dashboard.main_run(), theme);
    }
}

/// "policies", and once the followed run has ended, the source it chose (SAP-Net: the
/// highest activation) and that policy's greedy test returns (their mean, if the list does
/// not fit in `width`).
fn policies_title(dashboard: &Dashboard, width: u16) -> String {
    let ended = dashboard.main_run().and_then(|r| r.ended.as_ref());
    match ended.and_then(|record| Some((record, record.chosen.as_ref()?))) {
        Some((record, chosen)) if record.test_returns.is_empty() => format!(
            "policies · chosen {} ({})",
            chosen.name,
            if record.stopped {
                "stopped, not tested"
            } else {
                "not tested"
            }
        ),
        Some((record, chosen)) => {
            let tests: Vec<String> = record
                .test_returns
                .iter()
                .map(|r| format!("{r:.0}"))
                .collect();
            let all = format!(
                "policies · chosen {} · greedy tests {}",
                chosen.name,
                tests.join(" ")
            );
            if all.chars().count() + 4 <= usize::from(width) {
                return all;
            }
            let mean = record.test_returns.iter().sum::<f64>() / record.test_returns.len() as f64;
            format!("policies · chosen {} · test mean {mean:.1}", chosen.name)
        }
        None => match dashboard.sapnet.as_ref().and_then(|v| Some((v, v.locked?))) {
            // The softmax has collapsed: say so, and since when if it fits.
            Some((view, (i, since))) => {
                let name = &view.policies[i].name;
                let full = format!(
                    "policies · P({name}) > {} since step {}",
                    crate::trainer::LOCK_IN,
                    thousands(since)
                );
                if full.chars().count() + 4 <= usize::from(width) {
                    full
                } else {
                    format!("policies · P({name}) > {}", crate::trainer::LOCK_IN)
                }
            }
            None => "policies".to_string(),
        },
    }
}

/// `1234567` → `1,234,567`.
fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The rows of the policy table that a panel of `area` shows: the cursor's row always,
/// and while paused the acting policy's too. Running, the acting policy changes from frame
/// to frame: a window that followed it would jitter, and a click could land on another row
/// than the one seen, so the bottom border names it when it is hidden instead.
pub fn policy_rows(area: Rect, dashboard: &Dashboard) -> RowWindow {
    let (total, acting) = dashboard
        .sapnet
        .as_ref()
        .map_or((0, None), |v| (v.policies.len(), v.acting));
    // Below the top border and the header, above the bottom border.
    let room = usize::from(area.height.saturating_sub(3));
    let acting = acting.filter(|_| dashboard.mode == Mode::Paused);
    RowWindow::new(total, room, std::iter::once(dashboard.cursor).chain(acting))
}

/// The policy table's width with every column but the history, borders and spacing
/// included, and with the fewest; the narrowest history worth drawing.
const FULL_TABLE_WIDTH: u16 = 72;
const COMPACT_TABLE_WIDTH: u16 = 43;
const MIN_HISTORY_WIDTH: u16 = 10;

fn draw_policy_table(
    frame: &mut Frame,
    area: Rect,
    block: Block,
    view: &SapNetView,
    dashboard: &Dashboard,
    theme: Theme,
) {
    let (cursor, relative) = (dashboard.cursor, dashboard.relative);
    let window = policy_rows(area, dashboard);
    // `v`: each score less the highest, so that saturated activations (2.360e5 beside
    // 2.359e5) still read apart.
    let highest = view
        .net
        .activations()
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let score_header = if relative {
        format!("{}−max", view.score_name)
    } else {
        view.score_name.to_string()
    };
    let top = graph_view::highest(view.net.activations().iter().copied());
    // Columns give way from the right of the wish list as the panel narrows: the graph
    // already shows categories, the counts matter least. Zoomed (`z`), the scores over
    // time come before them: at 80 columns the table keeps the sparkline (as README
    // says `z` does) and gives up the hidden layers and the +/− counts.
    let full = area.width >= FULL_TABLE_WIDTH
        && !(dashboard.zoom && area.width < FULL_TABLE_WIDTH + 1 + MIN_HISTORY_WIDTH);
    // A library over several tasks shows each source's task where one task shows the
    // number of hidden layers.
    let tasks = view
        .policies
        .iter()
        .any(|p| p.description.source_task != view.policies[0].description.source_task);
    let bar_width = 8;
    // Each policy's score over the last episodes, on one scale for all (the highest in the
    // window), zoomed (`z`) or on a wide terminal, as many of the last episodes as fit.
    let used = if full {
        FULL_TABLE_WIDTH
    } else {
        COMPACT_TABLE_WIDTH
    };
    let history_width = usize::from(area.width.saturating_sub(used + 1)).min(HISTORY);
    let history = (area.width >= 90 || dashboard.zoom) && history_width >= MIN_HISTORY_WIDTH.into();
    let skipped = view.history.len().saturating_sub(history_width);
    let history_top = graph_view::highest(view.history.iter().flatten().copied());
    let rows = view.policies[window.rows()]
        .iter()
        .zip(window.rows())
        .map(|(p, i)| {
            let a = view.net.activations()[i];
            let probability = view.probabilities.get(i).copied().unwrap_or(0.0);
            let mut name = Span::styled(p.name.clone(), node_style(theme, a, top));
            if view.acting == Some(i) {
                name = name.patch_style(theme.active());
            }
            let mut cells = vec![Cell::from(name)];
            if full {
                cells.push(Cell::from(format!("{:?}", p.description.hidden)));
                cells.push(Cell::from(if tasks {
                    labels::short_task(&p.description.source_task).to_string()
                } else {
                    p.description.hidden.len().to_string()
                }));
            }
            cells.push(Cell::from(format_activation(if relative {
                a - highest
            } else {
                a
            })));
            cells.push(Cell::from(probability_bar(probability, bar_width)));
            cells.push(Cell::from(count(view.selections[i])));
            if full {
                cells.push(Cell::from(format!(
                    "{}/{}",
                    count(view.positive[i]),
                    count(view.negative[i])
                )));
            }
            if history {
                cells.push(Cell::from(sparkline(
                    view.history.iter().skip(skipped).map(|scores| scores[i]),
                    history_top,
                )));
            }
            let row = Row::new(cells);
            if i == cursor {
                row.style(theme.cursor())
            } else {
                row
            }
        });
    let (mut header, mut widths) = if full {
        (
            vec![
                "policy",
                "hidden",
                if tasks { "task" } else { "cat" },
                &score_header,
                "P(π)",
                "acted",
                "+/−",
            ],
            vec![
                Constraint::Length(9),
                Constraint::Length(14),
                Constraint::Length(if tasks { 14 } else { 3 }),
                Constraint::Length(9),
                Constraint::Length(bar_width as u16 + 5),
                Constraint::Length(6),
                Constraint::Min(9),
            ],
        )
    } else {
        (
            vec!["policy", &score_header, "P(π)", "acted"],
            vec![
                Constraint::Length(9),
                Constraint::Length(9),
                Constraint::Length(bar_width as u16 + 5),
                Constraint::Min(6),
            ],
        )
    };
    if history {
        header.push("A per episode");
        widths.push(Constraint::Length(history_width as u16));
    }
    let mut marker = window.marker().unwrap_or_default();
    if let Some(acting) = view.acting.filter(|i| !window.rows().contains(i)) {
        marker.push_str(&format!("· {} acts ", view.policies[acting].name));
    }
    let block = block.title_bottom(Line::styled(marker, theme.title()).right_aligned());
    let table = Table::new(rows, widths)
        .header(Row::new(header).style(theme.title()))
        .block(block);
    frame.render_widget(table, area);
}

/// `values` as a sparkline of ▁…█ scaled to `top`; blank where a value is 0 or below.
fn sparkline(values: impl Iterator<Item = f64>, top: f64) -> String {
    const BARS: [char; 8] = ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
    values
        .map(|v| {
            if v <= 0.0 || top <= 0.0 || !v.is_finite() {
                ' '
            } else {
                BARS[((v / top * 7.0).round() as usize).min(7)]
            }
        })
        .collect()
}

/// A count in at most five characters, so that a long run's tallies fit their column:
/// 9999, then 10k … 9999k, then 10M ….
fn count(n: u64) -> String {
    match n {
        0..10_000 => n.to_string(),
        // Up to where rounding to thousands would make 10000k.
        10_000..9_999_500 => format!("{}k", (n + 500) / 1000),
        _ => format!("{}M", (n + 500_000) / 1_000_000),
    }
}

fn format_activation(a: f64) -> String {
    if a.abs() >= 1e5 {
        format!("{a:.3e}")
    } else {
        format!("{a:.3}")
    }
}

/// The chart's legend is its title: one coloured name per curve, with the symbol its
/// curve is drawn with, so it names the curves in colour and without, at any width, and
/// covers no data (ratatui's legend box sat on the newest episodes at 120+ columns and was
/// hidden below). Long titles drop words before values.
fn rewards_title<'a>(runs: &[RunView], x_max: f64, width: u16, theme: Theme) -> Line<'a> {
    let entry = |i: usize, run: &RunView, value: bool| {
        let (_, symbol) = theme.series_marker(i);
        let symbol = if symbol.is_empty() { "━ " } else { symbol };
        let mut text = format!("{symbol}{}", run.method);
        if let (true, Some(ma)) = (value, run.curve.last_average()) {
            text.push_str(&format!(" {ma:.1}"));
        }
        if f64::from(run.episode) > x_max {
            text.push_str(&format!(" (ep {})", run.episode));
        }
        Span::styled(text, theme.series(i))
    };
    let fits = |line: &Line| line.width() + 2 <= usize::from(width);
    let mut line = Line::default();
    for (head, values) in [
        (" episode return, MA10 · ", true),
        (" MA10 · ", true),
        (" MA10 · ", false),
    ] {
        let mut spans = vec![Span::styled(head, theme.title())];
        for (i, run) in runs.iter().enumerate() {
            if i > 0 {
                spans.push(Span::styled(" · ", theme.title()));
            }
            spans.push(entry(i, run, values || i == 0));
        }
        spans.push(Span::raw(" "));
        line = Line::from(spans);
        if fits(&line) {
            break;
        }
    }
    line
}

/// What the dim curves are, under the chart: a finished protocol's mean and the ends of
/// its 95% interval, per method, over its runs.
fn bands_caption<'a>(bands: &[&Band], theme: Theme) -> Option<Line<'a>> {
    if bands.is_empty() {
        return None;
    }
    let per_method: Vec<String> = bands
        .iter()
        .map(|b| format!("{} {} runs", b.label, b.runs))
        .collect();
    Some(Line::styled(
        format!(
            " dim: --compare's mean and 95% CI · {} ",
            per_method.join(" · ")
        ),
        theme.dim(),
    ))
}

/// The episode axis follows the first (leading) run, so that its curve fills the chart
/// however far ahead a baseline of short episodes has raced; the others are drawn over the
/// same episodes, and the title says where they are.
fn draw_rewards(frame: &mut Frame, area: Rect, runs: &[RunView], reference: &[Band], theme: Theme) {
    let x_max = runs
        .first()
        .map_or(10.0, |r| f64::from(r.episode).max(10.0));
    // A finished protocol's band for each method on screen, over the episodes shown.
    let bands: Vec<&Band> = reference
        .iter()
        .filter(|b| runs.iter().any(|r| r.method.label() == b.label))
        .collect();
    let shown = |points: &[(f64, f64)]| -> Vec<(f64, f64)> {
        points
            .iter()
            .copied()
            .filter(|&(x, _)| x <= x_max)
            .collect()
    };
    let band_points: Vec<[Vec<(f64, f64)>; 3]> = bands
        .iter()
        .map(|b| [shown(&b.low), shown(&b.mean), shown(&b.high)])
        .collect();
    let (y_min, y_max) = runs
        .iter()
        .flat_map(|r| r.curve.returns.iter().map(|&(_, y)| y))
        .chain(band_points.iter().flatten().flatten().map(|&(_, y)| y))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
            (lo.min(y), hi.max(y))
        });
    let (y_min, y_max) = if y_min.is_finite() {
        (y_min.min(0.0), y_max.max(y_min + 1.0))
    } else {
        (0.0, 1.0)
    };
    let mut datasets = Vec::new();
    // The bands first, so the live curves draw over them: the mean a dim line, its 95%
    // interval's ends as dim dots.
    for (band, [low, mean, high]) in bands.iter().zip(&band_points) {
        let i = runs
            .iter()
            .position(|r| r.method.label() == band.label)
            .unwrap_or(0);
        for edge in [low, high] {
            datasets.push(
                Dataset::default()
                    .marker(Marker::Braille)
                    .graph_type(GraphType::Scatter)
                    .style(theme.dim())
                    .data(edge),
            );
        }
        datasets.push(
            Dataset::default()
                .marker(Marker::Braille)
                .graph_type(GraphType::Line)
                .style(theme.series(i).add_modifier(Modifier::DIM))
                .data(mean),
        );
    }
    for (i, run) in runs.iter().enumerate() {
        if i == 0 {
            // The leading run's returns themselves, dim dots under its moving average.
            datasets.push(
                Dataset::default()
                    .marker(Marker::Braille)
                    .graph_type(GraphType::Scatter)
                    .style(theme.dim())
                    .data(&run.curve.returns),
            );
        }
        datasets.push(
            Dataset::default()
                .marker(theme.series_marker(i).0)
                .graph_type(GraphType::Line)
                .style(theme.series(i))
                .data(&run.curve.average),
        );
    }
    let mut block = Block::bordered().title(rewards_title(runs, x_max, area.width, theme));
    if let Some(caption) = bands_caption(&bands, theme) {
        block = block.title_bottom(caption);
    }
    let chart = Chart::new(datasets)
        .block(block)
        .x_axis(
            Axis::default()
                .bounds([0.0, x_max])
                .labels([Line::from("0"), Line::from(format!("{x_max:.0}"))])
                .style(theme.dim()),
        )
        .y_axis(
            Axis::default()
                .bounds([y_min, y_max])
                .labels([
                    Line::from(format!("{y_min:.0}")),
                    Line::from(format!("{y_max:.0}")),
                ])
                .style(theme.dim()),
        );
    frame.render_widget(chart, area);
}

fn draw_loss(frame: &mut Frame, area: Rect, run: Option<&RunView>, theme: Theme) {
    let points: Vec<(f64, f64)> = run
        .map(|r| {
            let first = r.episode as usize + 1 - r.statistic_loss.len().min(r.episode as usize + 1);
            r.statistic_loss
                .iter()
                .enumerate()
                .map(|(k, &e)| ((first + k) as f64, e))
                .collect()
        })
        .unwrap_or_default();
    let (x_min, x_max) = match (points.first(), points.last()) {
        (Some(a), Some(b)) => (a.0, b.0.max(a.0 + 1.0)),
        _ => (0.0, 1.0),
    };
    let y_max = points.iter().map(|p| p.1).fold(1e-9, f64::max);
    let title = match points.last() {
        Some(&(_, e)) => format!(" statistic loss E {e:.4} "),
        None => " statistic loss E ".to_string(),
    };
    let data = [Dataset::default()
        .marker(Marker::Braille)
        .graph_type(GraphType::Line)
        .style(theme.series(0))
        .data(&points)];
    let chart = Chart::new(data.to_vec())
        .block(Block::bordered().title(Span::styled(title, theme.title())))
        .x_axis(Axis::default().bounds([x_min, x_max]).style(theme.dim()))
        .y_axis(
            Axis::default()
                .bounds([0.0, y_max])
                .labels([Line::from("0"), Line::from(format!("{y_max:.3}"))])
                .style(theme.dim()),
        );
    frame.render_widget(chart, area);
}

/// The bottom line: mode and figures on the left, the keys of the mode on the right
/// (the figures give way first on a narrow terminal).
fn draw_status(frame: &mut Frame, area: Rect, dashboard: &Dashboard, theme: Theme) {
    let (mode, hints) = match dashboard.mode {
        Mode::Running => ("RUNNING", "space pause · t teach · ? keys · q quit"),
        Mode::Paused => ("PAUSED", "space resume · n step · t teach · ? keys"),
        Mode::Teach => (
            "TEACH",
            "a · s · r · u · c · 1–5 +/− edit · t back · ? keys",
        ),
    };
    let run = dashboard.main_run();
    let finished = run.is_some_and(|r| r.ended.is_some());
    // The followed run failing is the one thing worth the whole line: its training went no
    // further. A baseline's failure is a note beside the figures; the rest goes on.
    let failure = run.and_then(|r| Some((&r.method, r.failed.as_ref()?)));
    let other_failures: Vec<&str> = dashboard
        .runs
        .iter()
        .skip(1)
        .filter(|r| r.failed.is_some())
        .map(|r| r.method.label())
        .collect();
    let hints = if failure.is_some() {
        "q quit"
    } else if let Some(notice) = dashboard.notice {
        notice
    } else if area.width < 100 {
        "? keys · q quit"
    } else if finished && dashboard.mode != Mode::Teach {
        // Nothing left to pause or step; the graph can still be taught on.
        "t teach · ? keys · q quit"
    } else {
        hints
    };
    let episode = run.map_or("-".to_string(), |r| {
        // Run 0 goes without saying; another (`--follow-run`) is named, from 0 as in the
        // results' files.
        let which = match r.run {
            0 => String::new(),
            run => format!(" run {run}"),
        };
        // The episode being played, as the step line counts it: the next one once its
        // first step came (the run counts the episodes that ended).
        let playing = dashboard.last_step.as_ref().map_or(0, |s| s.episode);
        format!(
            "{}{which} ep {}/{}",
            r.method,
            r.episode.max(playing),
            r.planned_episodes
        )
    });
    // Paused, training makes no steps: the last rate measured would be stale.
    let speed = match (dashboard.mode, dashboard.steps_per_second) {
        (Mode::Teach, _) => Some("paused".to_string()),
        _ if finished || dashboard.mode == Mode::Paused => None,
        (_, Some(s)) => Some(format!("{s:.0} steps/s")),
        (_, None) => Some("- steps/s".to_string()),
    };
    let throttle = match SPEEDS[dashboard.speed] {
        d if d.is_zero() => "full speed".to_string(),
        d => format!("{} ms/step", d.as_millis()),
    };
    let epsilon = run.map_or(0.0, |r| r.epsilon);
    let figures = match failure {
        Some((method, error)) => Line::from(vec![
            Span::styled(" FAILED ", theme.stopped().add_modifier(Modifier::REVERSED)),
            Span::raw(if error.contains(method.label()) {
                format!(" {error}")
            } else {
                format!(" {method}: {error}")
            }),
        ]),
        None => {
            let mut spans = vec![Span::styled(
                format!(" {} ", if finished { "DONE" } else { mode }),
                theme.title().add_modifier(Modifier::REVERSED),
            )];
            // First, where a narrow terminal cannot cut it off; the error itself is
            // printed when the dashboard closes.
            for method in other_failures {
                spans.push(Span::styled(format!(" {method} FAILED ·"), theme.stopped()));
            }
            // The state first: how fast training is let run, where the run is. What does
            // not fit before the keys is dropped from the end, never cut mid-word; two
            // spaces at least keep the last figure from reading into the keys.
            let room = usize::from(area.width)
                .saturating_sub(hints.chars().count() + 2)
                .saturating_sub(spans.iter().map(|s| s.content.chars().count()).sum());
            let figures = [
                Some(throttle),
                Some(episode),
                Some(format!("step {}", thousands(dashboard.step))),
                speed,
                Some(format!("ε {epsilon:.2}")),
                Some(dashboard.task.clone()),
            ];
            let mut text = String::new();
            for figure in figures.into_iter().flatten() {
                let next = if text.is_empty() {
                    format!(" {figure}")
                } else {
                    format!(" · {figure}")
                };
                if text.chars().count() + next.chars().count() > room {
                    break;
                }
                text.push_str(&next);
            }
            spans.push(Span::raw(text));
            Line::from(spans)
        }
    };
    let [left, right] = Layout::horizontal([
        Constraint::Min(0),
        Constraint::Length(hints.chars().count() as u16 + 1),
    ])
    .areas(area);
    frame.render_widget(Paragraph::new(figures), left);
    frame.render_widget(
        Paragraph::new(Span::styled(hints, theme.dim())).right_aligned(),
        right,
    );
}

const HELP: &[(&str, &str)] = &[
    ("space", "pause / resume training"),
    ("n", "one training step while paused"),
    (
        "+ / -",
        "faster / slower (delays training, never the screen)",
    ),
    ("tab / click", "focus the graph or the table"),
    (
        "↑↓←→ hjkl",
        "pick a policy (graph: the nearest node that way)",
    ),
    ("click", "pick the policy of a node or a row"),
    ("z", "enlarge the focused panel, or back"),
    ("m", "follow the next reusing method's run"),
    ("v", "scores as A − max(A), readable when A saturates"),
    ("t", "teach mode on the live graph (pauses training)"),
    ("?", "this help (any key closes it)"),
    ("q / Esc / Ctrl-C", "quit"),
    ("", ""),
    ("○ ◐ ●", "a node's A: < ¼, < ¾, ≥ ¾ of the highest A"),
    ("cat", "category: number of hidden layers (the prototype)"),
    ("+/−", "its positive / negative transitions so far (eq. 7)"),
];

#[cfg(test)]
mod tests {
    use super::{count, sparkline};

    #[test]
    fn sparklines_share_one_scale() {
        assert_eq!(sparkline([0.0, 1.0, 4.0, 8.0].into_iter(), 8.0), " ▂▅█");
        assert_eq!(sparkline([3.0].into_iter(), 0.0), " ");
    }

    #[test]
    fn counts_fit_five_characters() {
        assert_eq!(count(0), "0");
        assert_eq!(count(9_999), "9999");
        assert_eq!(count(10_000), "10k");
        assert_eq!(count(143_250), "143k");
        assert_eq!(count(37_813), "38k");
        assert_eq!(count(9_999_499), "9999k");
        assert_eq!(count(9_999_500), "10M");
        assert_eq!(count(12_600_000), "13M");
    }
}
