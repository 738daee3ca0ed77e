//! A and P of every policy over the calls made so far: two small charts side by side,
//! a curve per policy, each curve's end labelled with its policy, so that a student sees
//! where each call's ΔA went and how eq. 6's softmax follows.

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType, Paragraph};
use ratatui::Frame;

use crate::sapnet::selection::probabilities;
use crate::teach::{labels, Teach};
use crate::tui::theme::Theme;

/// The most points a curve gets: a long walk is sampled, its last call always kept.
const MAX_POINTS: usize = 200;

/// Draws the two charts in `area`.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme, title: &str) {
    let block = Block::bordered().title(Span::styled(format!(" {title} "), theme.title()));
    let Some(series) = Series::of(teach) else {
        let hint = "no walk yet: a activates the picked policy";
        frame.render_widget(Paragraph::new(hint).style(theme.dim()).block(block), area);
        return;
    };
    let inner = block.inner(area);
    frame.render_widget(block, area);
    let [left, right] =
        Layout::horizontal([Constraint::Percentage(50), Constraint::Percentage(50)]).areas(inner);
    let names = labels::labels(teach.names());
    chart(
        frame,
        left,
        &series.calls,
        &series.activations,
        &names,
        "A",
        theme,
    );
    chart(
        frame,
        right,
        &series.calls,
        &series.probabilities,
        &names,
        "P",
        theme,
    );
}

/// A and P of each policy at sampled calls of the walk (call 0: just after eq. 8).
struct Series {
    calls: Vec<f64>,
    /// Per policy, its values at `calls`.
    activations: Vec<Vec<f64>>,
    probabilities: Vec<Vec<f64>>,
}

impl Series {
    fn of(teach: &Teach) -> Option<Self> {
        let walk = teach.walk()?;
        let net = teach.net();
        let n = net.len();
        let tau = net.params().temperature;
        // The activations now, less what the calls deposited: the walk's start after
        // eq. 8; the calls' ΔA then rebuild each point.
        let mut a = net.activations().to_vec();
        for step in walk.trace {
            a[step.to] -= step.delta;
        }
        let made = walk.trace.len();
        let every = made.div_ceil(MAX_POINTS).max(1);
        let mut series = Series {
            calls: Vec::new(),
            activations: vec![Vec::new(); n],
            probabilities: vec![Vec::new(); n],
        };
        let sample = |call: usize, a: &[f64], series: &mut Series| {
            series.calls.push(call as f64);
            let p = probabilities(a, tau);
            for i in 0..n {
                series.activations[i].push(a[i]);
                series.probabilities[i].push(p[i]);
            }
        };
        sample(0, &a, &mut series);
        for (k, step) in walk.trace.iter().enumerate() {
            a[step.to] += step.delta;
            if (k + 1) % every == 0 || k + 1 == made {
                sample(k + 1, &a, &mut series);
            }
        }
        Some(series)
    }
}

/// One chart of `values` (a curve per policy) over `calls`, each curve's end labelled with
/// its policy in a column at the chart's right.
fn chart(
    frame: &mut Frame,
    area: Rect,
    calls: &[f64],
    values: &[Vec<f64>],
    names: &[String],
    what: &str,
    theme: Theme,
) {
    let top = values
        .iter()
        .flatten()
        .fold(0.0f64, |m, &x| m.max(x))
        .max(1e-9);
    let bottom = values.iter().flatten().fold(0.0f64, |m, &x| m.min(x));
    let ends = EndLabels::of(values, names, (bottom, top), area, theme);
    let [plot, labels] =
        Layout::horizontal([Constraint::Min(0), Constraint::Length(ends.width)]).areas(area);
    render_curves(frame, plot, calls, values, (bottom, top), what, theme);
    frame.render_widget(Paragraph::new(ends.lines), labels);
}

fn render_curves(
    frame: &mut Frame,
    area: Rect,
    calls: &[f64],
    values: &[Vec<f64>],
    (bottom, top): (f64, f64),
    what: &str,
    theme: Theme,
) {
    let points: Vec<Vec<(f64, f64)>> = values
        .iter()
        .map(|v| calls.iter().copied().zip(v.iter().copied()).collect())
        .collect();
    let last = calls.last().copied().unwrap_or(0.0).max(1.0);
    let datasets: Vec<Dataset> = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (marker, _) = theme.series_marker(i);
            Dataset::default()
                .marker(marker)
                .graph_type(GraphType::Line)
                .style(theme.series(i))
                .data(p)
        })
        .collect();
    let chart = Chart::new(datasets)
        .x_axis(
            Axis::default()
                .bounds([0.0, last])
                .labels([Span::raw("0"), Span::raw(format!("{last}"))]),
        )
        .y_axis(
            Axis::default()
                .title(Span::styled(what.to_string(), theme.title()))
                .bounds([bottom, top])
                .labels([
                    Span::raw(format!("{bottom:.1}")),
                    Span::raw(format!("{top:.2}")),
                ]),
        )
        .legend_position(None);
    frame.render_widget(chart, area);
}

/// The names of the policies whose curves end on each row of a chart, for a column beside
/// it: a legend would not fit ten policies in a few rows (Table II's at 80×24 had none),
/// while a curve's end is where a reader looks for its name. Curves ending on the same row
/// share it (`π4 π5 π6`, cut to `π4 +2` where the column is narrow).
struct EndLabels {
    width: u16,
    lines: Vec<Line<'static>>,
}

impl EndLabels {
    /// `area` is the chart's with the column: the column takes at most a third of it.
    fn of(
        values: &[Vec<f64>],
        names: &[String],
        (bottom, top): (f64, f64),
        area: Rect,
        theme: Theme,
    ) -> Self {
        // The chart's curves are drawn above its x axis and its labels, two rows.
        let rows = usize::from(area.height.saturating_sub(2));
        let mut ending: Vec<Vec<usize>> = vec![Vec::new(); rows];
        for (i, curve) in values.iter().enumerate() {
            if let (Some(&end), true) = (curve.last(), rows > 0) {
                let (marker, _) = theme.series_marker(i);
                ending[end_row(end, (bottom, top), rows, marker)].push(i);
            }
        }
        let widest = ending
            .iter()
            .map(|on| joined(on, names).chars().count())
            .max();
        let width = widest.unwrap_or(0).min(usize::from(area.width / 3));
        let lines = ending
            .iter()
            .map(|on| match on[..] {
                [i] => Line::styled(format!(" {}", names[i]), theme.series(i)),
                _ => Line::from(format!(" {}", cut(on, names, width))),
            })
            .collect();
        Self {
            // A space between the curves and the names.
            width: u16::try_from(width + 1).unwrap_or(u16::MAX),
            lines,
        }
    }
}

/// The row (from the top, of `rows`) where a curve ending at `value` ends, as the chart's
/// canvas places it: `marker` decides how many dots a row holds (braille's four).
fn end_row(value: f64, (bottom, top): (f64, f64), rows: usize, marker: Marker) -> usize {
    let dots = if marker == Marker::Braille { 4 } else { 1 };
    let resolution = (rows * dots) as f64;
    let dot = ((top - value) * (resolution - 1.0) / (top - bottom).max(1e-12)).round();
    (dot.max(0.0) as usize / dots).min(rows - 1)
}

/// The names of `policies`, a space between two.
fn joined(policies: &[usize], names: &[String]) -> String {
    let named: Vec<&str> = policies.iter().map(|&i| names[i].as_str()).collect();
    named.join(" ")
}

/// [`joined`] in at most `width` characters: as many names as fit, then `+k` for the rest.
fn cut(policies: &[usize], names: &[String], width: usize) -> String {
    let whole = joined(policies, names);
    if whole.chars().count() <= width {
        return whole;
    }
    for kept in (1..policies.len()).rev() {
        let text = format!(
            "{} +{}",
            joined(&policies[..kept], names),
            policies.len() - kept
        );
        if text.chars().count() <= width {
            return text;
        }
    }
    format!("+{}", policies.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_sharing_a_row_are_cut_with_a_count() {
        let names: Vec<String> = (0..10).map(|i| format!("π{i}")).collect();
        assert_eq!(cut(&[4, 5, 6], &names, 8), "π4 π5 π6");
        assert_eq!(cut(&[4, 5, 6], &names, 6), "π4 +2");
        assert_eq!(cut(&[0, 1, 2, 7, 8, 9], &names, 3), "+6");
    }

    /// Three rows from 0 to 1, one dot a row: 1 on the top row, 0.5 and 0.7 in the middle,
    /// 0 at the bottom. Braille's twelve dots put 0.7 on dot 3 (0.3 × 11 rounded), the top
    /// row's last.
    #[test]
    fn a_curve_ends_on_the_row_its_value_is_drawn_on() {
        let bounds = (0.0, 1.0);
        assert_eq!(end_row(1.0, bounds, 3, Marker::Dot), 0);
        assert_eq!(end_row(0.5, bounds, 3, Marker::Dot), 1);
        assert_eq!(end_row(0.0, bounds, 3, Marker::Dot), 2);
        assert_eq!(end_row(0.7, bounds, 3, Marker::Dot), 1);
        assert_eq!(end_row(0.7, bounds, 3, Marker::Braille), 0);
    }
}
