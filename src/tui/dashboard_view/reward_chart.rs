//! The episode returns' chart: each run's moving average (MA10), the leading run's returns
//! as dots under it, and with `--compare` a finished protocol's bands beneath.

use ratatui::layout::Rect;
use ratatui::style::Modifier;
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType};
use ratatui::Frame;

use crate::tui::dashboard::RunView;
use crate::tui::reference::Band;
use crate::tui::theme::Theme;

/// The episode axis follows the first (leading) run, so that its curve fills the chart
/// however far ahead a baseline of short episodes has raced; the others are drawn over the
/// same episodes, and the title says where they are.
pub(super) fn draw(
    frame: &mut Frame,
    area: Rect,
    runs: &[RunView],
    reference: &[Band],
    theme: Theme,
) {
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
    // interval's ends as dim dots, each method's in its family's hue (as the plots draw
    // it), so that two methods' bands read apart.
    for (band, [low, mean, high]) in bands.iter().zip(&band_points) {
        let kind = runs
            .iter()
            .find(|r| r.method.label() == band.label)
            .map(|r| r.method.kind);
        let style = match kind {
            Some(kind) => theme.method(kind, 0).add_modifier(Modifier::DIM),
            None => theme.dim(),
        };
        for edge in [low, high] {
            datasets.push(
                Dataset::default()
                    .marker(Marker::Braille)
                    .graph_type(GraphType::Scatter)
                    .style(style)
                    .data(edge),
            );
        }
        datasets.push(
            Dataset::default()
                .marker(Marker::Braille)
                .graph_type(GraphType::Line)
                .style(style)
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
