//! Drawing the Curves view: every method's curve of the metric picked across its runs —
//! the IQM or mean over runs of each run's moving average (MA10), with its 95% bootstrap
//! band — in the plots' colour of each method (without colour: a marker of its own along
//! its line), beside a legend that switches methods on and off and gives each one's value
//! where the view ends. The points are `sample_efficiency.csv`'s for the returns on the
//! budget's axis ([`super`]). `Enter` shows the picked method's runs one by one, each over
//! its method's band. While the curves are made, the view says so.

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Context, Line as Segment, Points};
use ratatui::widgets::{Block, Paragraph};
use ratatui::Frame;

use super::{runs_of, CurvesView as Curves};
use crate::report::metric::{CurvePoint, Metric, XAxis};
use crate::report::plots::palette::method_colours;
use crate::stats::Estimate;
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;
use crate::tui::workbench::cells::{fit, inner};
use crate::tui::workbench::folder::Compared;

/// Without colour, each method's line carries its own marker (the legend's too).
pub const MARKERS: [&str; 10] = ["●", "▲", "■", "◆", "✚", "○", "△", "□", "◇", "×"];

/// The y axis's labels' width.
const Y_LABELS: u16 = 7;

/// A method on screen: its place in the protocol, label, colour and curve.
struct Shown {
    index: usize,
    label: String,
    colour: Color,
    points: Vec<CurvePoint>,
}

/// A spinner's frame, turning ten times a second since `since`.
fn spinner(since: std::time::Instant) -> char {
    const FRAMES: [char; 10] = ['⠋', '⠙', '⠹', '⠸', '⠼', '⠴', '⠦', '⠧', '⠇', '⠏'];
    FRAMES[(since.elapsed().as_millis() / 100) as usize % FRAMES.len()]
}

pub(super) fn draw(
    frame: &mut Frame,
    area: Rect,
    curves: &Curves,
    folder: &dyn Compared,
    theme: Theme,
) {
    let (made, making) = curves.curves(folder);
    let Some(made) = made.filter(|m| m.error.is_none() || making.is_some()) else {
        draw_waiting(frame, area, curves, folder, making, theme);
        return;
    };
    let ids = folder.methods();
    let kinds: Vec<_> = ids.iter().map(|m| m.kind).collect();
    let colours = method_colours(&kinds);
    let methods: Vec<Shown> = ids
        .iter()
        .enumerate()
        .map(|(index, method)| {
            let (r, g, b) = colours[index];
            Shown {
                index,
                label: method.label().to_string(),
                colour: Color::Rgb(r, g, b),
                points: made.methods.get(index).cloned().unwrap_or_default(),
            }
        })
        .collect();
    let range = curves.range(folder);
    let block = Block::bordered().title(title(folder, curves, (range, making), theme));
    frame.render_widget(block, area);
    let inside = inner(area);
    if inside.height < 4 || inside.width < 30 {
        return;
    }
    let label_width = label_width(folder);
    let [chart, legend] = areas(inside, label_width, curves.run.is_some());
    match curves.run {
        Some(k) => {
            let Some(method) = methods.get(curves.cursor) else {
                return;
            };
            let runs = runs_of(folder, method.index);
            let k = k.min(runs.len().saturating_sub(1));
            let lines = made.runs.get(method.index).cloned().unwrap_or_default();
            let averages = lines.get(k).cloned().unwrap_or_default();
            draw_chart(
                frame,
                chart,
                (&[method], &averages),
                (curves, curves.axis(folder)),
                range,
                theme,
            );
            draw_runs_legend(
                frame,
                legend,
                (folder, curves),
                (method, &lines, range),
                k,
                theme,
            );
        }
        None => {
            let shown: Vec<&Shown> = methods
                .iter()
                .filter(|m| !curves.hidden.contains(&m.index))
                .collect();
            // The picked method drawn last, over the others.
            let ordered: Vec<&Shown> = shown
                .iter()
                .filter(|m| m.index != curves.cursor)
                .chain(shown.iter().filter(|m| m.index == curves.cursor))
                .copied()
                .collect();
            draw_chart(
                frame,
                chart,
                (&ordered, &[]),
                (curves, curves.axis(folder)),
                range,
                theme,
            );
            draw_legend(
                frame,
                legend,
                (&methods, curves.axis(folder)),
                curves,
                range,
                label_width,
                theme,
            );
        }
    }
}

/// The view while its curves are made (or could not be): what is made, over how many
/// runs, a spinner; or why not.
fn draw_waiting(
    frame: &mut Frame,
    area: Rect,
    curves: &Curves,
    folder: &dyn Compared,
    making: Option<std::time::Instant>,
    theme: Theme,
) {
    let runs = folder
        .runs()
        .iter()
        .filter(|r| !r.training.is_empty())
        .count();
    let text = match making {
        Some(since) => format!(
            "{} Making the curves of {} ({}, {} over runs) against the {} over {}: reading \
             the runs' files and bootstrapping each point…",
            spinner(since),
            metric_name(curves, folder),
            match curves.window(folder) {
                1 => "unsmoothed".to_string(),
                w => format!("MA{w}"),
            },
            curves.statistic.name(),
            curves.axis(folder).name(),
            crate::tui::workbench::cells::counted(runs, "run"),
        ),
        None => {
            let (made, _) = curves.curves(folder);
            format!(
                "The curves could not be made: {}",
                made.and_then(|m| m.error).unwrap_or_default()
            )
        }
    };
    frame.render_widget(
        Paragraph::new(Line::styled(text, theme.dim()))
            .wrap(ratatui::widgets::Wrap { trim: true })
            .block(Block::bordered().title(Span::styled(" Curves ", theme.title()))),
        area,
    );
}

/// The metric as the view names it.
fn metric_name(curves: &Curves, folder: &dyn Compared) -> String {
    curves.metric.name(&folder.sources())
}

/// A value of `metric` with its decimals.
fn value(metric: Metric, x: f64) -> String {
    format!("{x:.*}", metric.digits())
}

/// A place on `axis`: whole episodes and steps; seconds to a hundredth below ten (a tiny
/// run's episodes take milliseconds), to a tenth below a thousand, else whole.
fn place(axis: XAxis, x: f64) -> String {
    match axis {
        XAxis::Wall if x.abs() < 10.0 => format!("{x:.2}"),
        XAxis::Wall if x.abs() < 1000.0 => format!("{x:.1}"),
        XAxis::Wall | XAxis::Episode | XAxis::Step => format!("{x:.0}"),
    }
}

/// The labels' width in the legend.
fn label_width(folder: &dyn Compared) -> usize {
    folder
        .methods()
        .iter()
        .map(|m| m.label().chars().count())
        .max()
        .unwrap_or(6)
        .clamp(6, 22)
}

/// The chart and, right of it, the legend: toggle, marker, label and the value with its
/// interval where it fits.
fn areas(inside: Rect, label_width: usize, runs: bool) -> [Rect; 2] {
    // On a narrow terminal the values without their intervals leave the chart room; one
    // method's runs list their status and episodes.
    let wanted = if inside.width >= 110 { 27 } else { 13 };
    let wanted = if runs { wanted.max(30) } else { wanted };
    let legend_width = (label_width as u16 + wanted).min(inside.width / 2);
    let [chart, _, legend] = Layout::horizontal([
        Constraint::Fill(1),
        Constraint::Length(1),
        Constraint::Length(legend_width),
    ])
    .areas(inside);
    [chart, legend]
}

/// The method whose legend line is at (`column`, `row`) of the screen, the view drawn in
/// `area` with every method (not one method's runs): what a click shows or hides.
pub(super) fn legend_method_at(
    area: Rect,
    curves: &Curves,
    folder: &dyn Compared,
    column: u16,
    row: u16,
) -> Option<usize> {
    if curves.run.is_some() {
        return None;
    }
    let inside = inner(area);
    let [_, legend] = areas(inside, label_width(folder), false);
    let first = legend.y + 1;
    if !(legend.x..legend.x + legend.width).contains(&column) || row < first {
        return None;
    }
    let methods = folder.methods().len();
    legend_window(legend, methods, curves.cursor).row_at(usize::from(row - first))
}

/// The methods' lines the legend in `area` shows: as many as fit between its heading and
/// its footer, the picked one kept in view.
fn legend_window(area: Rect, methods: usize, cursor: usize) -> RowWindow {
    RowWindow::new(
        methods,
        usize::from(area.height).saturating_sub(2),
        [cursor],
    )
}

/// What the view shows, over how many runs, and where on the axis; a spinner while the
/// curves are made again.
fn title(
    folder: &dyn Compared,
    curves: &Curves,
    ((from, to), making): ((f64, f64), Option<std::time::Instant>),
    theme: Theme,
) -> Line<'static> {
    let window = curves.window(folder);
    let axis = curves.axis(folder);
    let (finished, planned_runs) = (folder.finished_runs(), folder.runs().len());
    let over = if finished == planned_runs && planned_runs == 1 {
        "its one run".to_string()
    } else if finished == planned_runs {
        format!("all {planned_runs} runs")
    } else {
        format!(
            "partial: {}, running ones so far",
            crate::tui::workbench::cells::runs_finished(finished, planned_runs)
        )
    };
    let zoom = if curves.zoom.is_some() {
        let (_, all) = curves.extent(folder);
        format!(
            " · {} {}–{} of {}",
            axis.short(),
            place(axis, from),
            place(axis, to),
            place(axis, all)
        )
    } else {
        String::new()
    };
    let smoothed = if window > 1 {
        format!(" MA{window}")
    } else {
        " unsmoothed".to_string()
    };
    let what = match curves.run {
        Some(_) => format!("one run's{smoothed} over its method's"),
        None => format!("{smoothed} {} over runs,", curves.statistic.name())
            .trim_start()
            .to_string(),
    };
    let mut spans = vec![
        Span::styled(" Curves ", theme.title()),
        Span::styled(format!("{} ", metric_name(curves, folder)), theme.title()),
        Span::raw(format!("{what} 95% band · {over}{zoom} ")),
    ];
    if let Some(since) = making {
        spans.push(Span::styled(format!("{} ", spinner(since)), theme.active()));
    }
    Line::from(spans)
}

/// The points of a curve inside the range shown.
fn in_range(points: &[CurvePoint], (from, to): (f64, f64)) -> impl Iterator<Item = &CurvePoint> {
    points.iter().filter(move |p| (from..=to).contains(&p.at))
}

/// The curves (each method's line and band; without colour the picked method's band
/// only, and markers along every line), and one run's MA when its runs are read one by one.
fn draw_chart(
    frame: &mut Frame,
    area: Rect,
    (methods, run): (&[&Shown], &[(f64, f64)]),
    (curves, axis): (&Curves, XAxis),
    range: (f64, f64),
    theme: Theme,
) {
    let (from, to) = range;
    let statistic = curves.statistic;
    let run: Vec<(f64, f64)> = run
        .iter()
        .copied()
        .filter(|&(x, _)| (from..=to).contains(&x))
        .collect();
    let values = methods
        .iter()
        .flat_map(|m| in_range(&m.points, range).map(|p| statistic.of(p)))
        .flat_map(|e| [e.lo, e.hi])
        .chain(run.iter().map(|&(_, y)| y));
    let (low, high) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
        (lo.min(y), hi.max(y))
    });
    if !low.is_finite() {
        frame.render_widget(
            Paragraph::new(Line::styled(
                "No curve to draw: no shown method has a run with episodes here.",
                theme.dim(),
            )),
            area,
        );
        return;
    }
    let (low, high) = if high > low {
        (low, high)
    } else {
        (low - 1.0, high + 1.0)
    };
    let plot = draw_axes(
        frame,
        area,
        (range, axis),
        (low, high),
        (curves.metric, theme),
    );
    let picked = curves.cursor;
    let colour = |m: &Shown| if theme.color { m.colour } else { Color::Reset };
    // Without colour a marker every few columns along each line tells the lines apart.
    let every = (to - from) / f64::from(plot.width.max(1)) * 8.0;
    let canvas = Canvas::default()
        .x_bounds([from, to])
        .y_bounds([low, high])
        .marker(ratatui::symbols::Marker::Braille)
        .paint(|ctx: &mut Context| {
            for m in methods {
                let estimates: Vec<(f64, Estimate)> = in_range(&m.points, range)
                    .map(|p| (p.at, statistic.of(p)))
                    .collect();
                if theme.color || m.index == picked {
                    // The band's edges, dotted.
                    let edges: Vec<(f64, f64)> = estimates
                        .iter()
                        .step_by(2)
                        .flat_map(|&(x, e)| [(x, e.lo), (x, e.hi)])
                        .collect();
                    ctx.draw(&Points {
                        coords: &edges,
                        color: colour(m),
                    });
                }
                // One run shown alone: its method's band under it, not its method's line.
                let pairs = if run.is_empty() {
                    estimates.windows(2)
                } else {
                    [].windows(2)
                };
                for pair in pairs {
                    ctx.draw(&Segment {
                        x1: pair[0].0,
                        y1: pair[0].1.point,
                        x2: pair[1].0,
                        y2: pair[1].1.point,
                        color: colour(m),
                    });
                }
                if estimates.len() == 1 {
                    let (x, e) = estimates[0];
                    ctx.draw(&Points {
                        coords: &[(x, e.point)],
                        color: colour(m),
                    });
                }
            }
            for pair in run.windows(2) {
                ctx.draw(&Segment {
                    x1: pair[0].0,
                    y1: pair[0].1,
                    x2: pair[1].0,
                    y2: pair[1].1,
                    color: if theme.color {
                        Color::White
                    } else {
                        Color::Reset
                    },
                });
            }
            if !theme.color && run.is_empty() {
                ctx.layer();
                for m in methods {
                    let mut next = f64::NEG_INFINITY;
                    for p in in_range(&m.points, range) {
                        let x = p.at;
                        if x >= next {
                            ctx.print(x, statistic.of(p).point, MARKERS[m.index % MARKERS.len()]);
                            next = x + every;
                        }
                    }
                }
            }
        });
    frame.render_widget(canvas, plot);
}

/// The axes' labels around the plot in `area` (the y axis: its top, middle and bottom
/// values; the x axis: its ends), and the plot's area inside them.
fn draw_axes(
    frame: &mut Frame,
    area: Rect,
    ((from, to), axis): ((f64, f64), XAxis),
    (low, high): (f64, f64),
    (metric, theme): (Metric, Theme),
) -> Rect {
    let [left, plot] =
        Layout::horizontal([Constraint::Length(Y_LABELS), Constraint::Fill(1)]).areas(area);
    let [plot, x_labels] =
        Layout::vertical([Constraint::Fill(1), Constraint::Length(1)]).areas(plot);
    let mut y_lines = vec![Line::from(""); usize::from(plot.height)];
    let last = y_lines.len().saturating_sub(1);
    // Whole numbers where the axis spans ten or more; else the metric's decimals (ε,
    // probabilities, losses), as many as fit.
    let decimals = if high - low >= 10.0 {
        0
    } else {
        metric.digits().clamp(1, 3)
    };
    for (row, value) in [(0, high), (last / 2, (low + high) / 2.0), (last, low)] {
        let text = format!("{value:>6.decimals$}");
        y_lines[row] = Line::styled(format!("{} ", fit(&text, 6)), theme.dim());
    }
    frame.render_widget(Paragraph::new(y_lines), left);
    let (first, end) = (
        place(axis, from),
        format!("{} {}", axis.name(), place(axis, to)),
    );
    let gap = usize::from(x_labels.width).saturating_sub(first.len() + end.len());
    frame.render_widget(
        Paragraph::new(Line::styled(
            format!("{first}{}{end}", " ".repeat(gap)),
            theme.dim(),
        )),
        x_labels,
    );
    plot
}

/// The value of a curve where the view ends: its last point inside the range shown.
pub fn value_at_end(points: &[CurvePoint], range: (f64, f64)) -> Option<&CurvePoint> {
    in_range(points, range).last()
}

/// One line per method: shown or not, its colour or marker, its label, and its
/// statistic with the 95% interval at the view's last episode.
fn draw_legend(
    frame: &mut Frame,
    area: Rect,
    (methods, axis): (&[Shown], XAxis),
    curves: &Curves,
    range: (f64, f64),
    label_width: usize,
    theme: Theme,
) {
    let width = usize::from(area.width);
    let ends: Vec<Option<&CurvePoint>> = methods
        .iter()
        .map(|m| value_at_end(&m.points, range))
        .collect();
    let at = ends
        .iter()
        .flatten()
        .map(|p| p.at)
        .fold(None, |a: Option<f64>, x| Some(a.map_or(x, |a| a.max(x))))
        .map(|x| place(axis, x));
    let unit = axis.short();
    // The intervals where the legend is wide enough for them.
    let intervals = width >= label_width + 27;
    let mut lines = vec![Line::styled(
        fit(
            &match at {
                Some(at) if intervals => {
                    format!("{} [95% CI] at {unit} {at}", curves.statistic.name())
                }
                Some(at) => format!("{} at {unit} {at}", curves.statistic.name()),
                None => curves.statistic.name().to_string(),
            },
            width,
        ),
        theme.dim(),
    )];
    let window = legend_window(area, methods.len(), curves.cursor);
    for (m, end) in methods
        .iter()
        .zip(&ends)
        .skip(window.first)
        .take(window.shown)
    {
        let on = !curves.hidden.contains(&m.index);
        let style = if theme.color {
            Style::new().fg(m.colour)
        } else {
            Style::new()
        };
        let symbol = if theme.color {
            "━"
        } else {
            MARKERS[m.index % MARKERS.len()]
        };
        let digits = curves.metric.digits();
        let value = end.map_or_else(
            || "—".to_string(),
            |p| {
                let e = curves.statistic.of(p);
                // Returns to a tenth, as the tables print them; each metric its decimals;
                // the interval where it fits whole.
                let with = crate::report::comparison::interval(&e, digits);
                if intervals && with.chars().count() <= width.saturating_sub(label_width + 5) {
                    with
                } else {
                    format!("{:.digits$}", e.point)
                }
            },
        );
        let picked = m.index == curves.cursor;
        let row = |s: Style| if picked { s.patch(theme.cursor()) } else { s };
        let text_style = if on { Style::new() } else { theme.dim() };
        lines.push(Line::from(vec![
            Span::styled(if on { "■ " } else { "□ " }, row(text_style)),
            Span::styled(format!("{symbol} "), row(style)),
            Span::styled(
                format!("{} ", fit(&m.label, label_width)),
                row(text_style.patch(if on { style } else { Style::new() })),
            ),
            Span::styled(
                fit(&value, width.saturating_sub(label_width + 5)),
                row(text_style),
            ),
        ]));
    }
    let footer = match window.marker() {
        Some(more) => format!("{} ↑↓", more.trim()),
        None => "␣: on/off · ⏎: runs".to_string(),
    };
    lines.push(Line::styled(fit(&footer, width), theme.dim()));
    frame.render_widget(Paragraph::new(lines), area);
}

/// One method's runs as the legend draws them: the method, each run's line, the x range.
type ShownRuns<'a> = (&'a Shown, &'a [Vec<(f64, f64)>], (f64, f64));

/// The picked method's runs, the one shown marked, each with its status and its line's
/// last value in the range shown.
fn draw_runs_legend(
    frame: &mut Frame,
    area: Rect,
    (folder, curves): (&dyn Compared, &Curves),
    (method, run_lines, (from, to)): ShownRuns<'_>,
    shown: usize,
    theme: Theme,
) {
    let width = usize::from(area.width);
    let window = curves.window(folder);
    let runs = runs_of(folder, method.index);
    let style = if theme.color {
        Style::new().fg(method.colour)
    } else {
        Style::new()
    };
    let mut lines = vec![
        Line::styled(
            fit(&method.label, width),
            style.add_modifier(Modifier::BOLD),
        ),
        Line::styled(
            fit(
                &if window > 1 {
                    format!("run  status   episodes  MA{window}")
                } else {
                    "run  status   episodes  last".to_string()
                },
                width,
            ),
            theme.dim(),
        ),
    ];
    // Between the two heading lines and the footer, the shown run kept in view.
    let rows = RowWindow::new(
        runs.len(),
        usize::from(area.height).saturating_sub(3),
        [shown],
    );
    for (k, run) in runs.iter().enumerate().skip(rows.first).take(rows.shown) {
        let last = run_lines
            .get(k)
            .and_then(|line| line.iter().rev().find(|(x, _)| (from..=to).contains(x)))
            .map_or_else(|| "—".to_string(), |&(_, y)| value(curves.metric, y));
        let text = format!(
            "{} {} {} {}",
            fit(&run.run.to_string(), 4),
            fit(run.status.name(), 8),
            fit(&run.episodes().to_string(), 9),
            last
        );
        let line_style = if k == shown {
            theme.cursor()
        } else {
            Style::new()
        };
        lines.push(Line::styled(fit(&text, width), line_style));
    }
    if runs.is_empty() {
        lines.push(Line::styled("no run with episodes yet", theme.dim()));
    }
    let footer = match rows.marker() {
        Some(more) => format!("{} [ ]", more.trim()),
        None => "[ ]: run · ⏎: every method".to_string(),
    };
    lines.push(Line::styled(fit(&footer, width), theme.dim()));
    frame.render_widget(Paragraph::new(lines), area);
}
