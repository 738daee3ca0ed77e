//! The followed run's statistic loss E over its episodes (Algorithm 3), its latest value
//! in the title; `—` and no line where it has none (a method that spreads no activation,
//! files that did not keep it).

use ratatui::layout::Rect;
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Chart, Dataset, GraphType};
use ratatui::Frame;

use crate::tui::dashboard::RunView;
use crate::tui::theme::Theme;

pub(super) fn draw(
    frame: &mut Frame,
    area: Rect,
    (run, known): (Option<&RunView>, bool),
    theme: Theme,
) {
    let points: Vec<(f64, f64)> = run
        .filter(|r| known && r.method.kind.spreads)
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
        None => " statistic loss E — ".to_string(),
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
