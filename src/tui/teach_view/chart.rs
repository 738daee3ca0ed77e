//! A and P of every policy over the calls made so far: two small charts side by side,
//! a curve per policy, so that a student sees where each call's ΔA went and how eq. 6's
//! softmax follows.

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::Span;
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

fn chart(
    frame: &mut Frame,
    area: Rect,
    calls: &[f64],
    values: &[Vec<f64>],
    names: &[String],
    what: &str,
    theme: Theme,
) {
    let points: Vec<Vec<(f64, f64)>> = values
        .iter()
        .map(|v| calls.iter().copied().zip(v.iter().copied()).collect())
        .collect();
    let top = values
        .iter()
        .flatten()
        .fold(0.0f64, |m, &x| m.max(x))
        .max(1e-9);
    let bottom = values.iter().flatten().fold(0.0f64, |m, &x| m.min(x));
    let last = calls.last().copied().unwrap_or(0.0).max(1.0);
    let datasets: Vec<Dataset> = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (marker, _) = theme.series_marker(i);
            Dataset::default()
                .name(names[i].clone())
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
        .legend_position(Some(ratatui::widgets::LegendPosition::TopLeft))
        .hidden_legend_constraints((Constraint::Percentage(60), Constraint::Percentage(60)));
    frame.render_widget(chart, area);
}
