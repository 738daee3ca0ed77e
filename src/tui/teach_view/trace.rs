//! The trace: every `spread` call made so far, its h, Ω, η and ΔA (eq. 9–11), the latest
//! last.

use ratatui::layout::{Constraint, Rect};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Cell, Row, Table};
use ratatui::Frame;

use super::figures::name_width;
use crate::sapnet::TraceStep;
use crate::teach::labels;
use crate::teach::Teach;
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;

/// The trace: the calls made so far, the latest last.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let walk = teach.walk();
    let names = teach.names();
    let trace_steps = walk.as_ref().map_or(&[][..], |w| w.trace);
    // The latest calls; the marker counts the earlier ones.
    let window = RowWindow::new(
        trace_steps.len(),
        usize::from(area.height.saturating_sub(3)),
        trace_steps.len().checked_sub(1),
    );
    // Wide enough for the last call's number: long walks make hundreds of thousands.
    let number_width = trace_steps.len().max(1).to_string().len().max(4) as u16;
    // #, h, Ω, η, ΔA ("0.526316") and the six gaps between the seven columns.
    let fixed = number_width + 2 + 5 + 7 + 8 + 6;
    let room = area.width.saturating_sub(2 + fixed) / 2;
    // The names where both columns have room for them, else the graph's labels.
    let short: Vec<String>;
    let names = if name_width(names, 4, usize::MAX) <= room {
        names
    } else {
        short = labels::labels(names);
        short.as_slice()
    };
    let name_width = name_width(names, 4, usize::MAX);
    let rows = trace_steps[window.rows()]
        .iter()
        .zip(window.rows())
        .map(|(s, k)| trace_row(k + 1, s, names, theme));
    frame.render_widget(
        Table::new(
            rows,
            [
                Constraint::Length(number_width),
                Constraint::Length(name_width),
                Constraint::Length(name_width),
                Constraint::Length(2),
                Constraint::Length(5),
                Constraint::Length(7),
                Constraint::Min(8),
            ],
        )
        .header(Row::new(["#", "from", "to", "h", "Ω", "η", "ΔA"]).style(theme.title()))
        .block(
            Block::bordered()
                .title(Span::styled(" trace (v: tree) ", theme.title()))
                .title_bottom(
                    Line::styled(window.marker().unwrap_or_default(), theme.title())
                        .right_aligned(),
                ),
        ),
        area,
    );
}

fn trace_row(k: usize, s: &TraceStep, names: &[String], theme: Theme) -> Row<'static> {
    let delta = if s.stopped {
        Span::styled("stopped", theme.stopped())
    } else {
        Span::raw(format!("{:.6}", s.delta))
    };
    Row::new(vec![
        Cell::from(k.to_string()),
        Cell::from(names[s.from].clone()),
        Cell::from(names[s.to].clone()),
        Cell::from(s.h.to_string()),
        Cell::from(format!("{:.2}", s.omega)),
        Cell::from(format!("{:.4}", s.eta)),
        Cell::from(delta),
    ])
    .style(Style::new())
}
