//! Drawing teach mode: one activation's spreading (Algorithms 1 and 2), every quantity
//! beside its equation, and the live edits' effect on the walk. This file lays the panels
//! out, hands each to its file, and tells what a click lands on in the same rectangles.

mod call;
mod edits;
mod figures;
mod graph_panel;
mod help;
mod stack;
mod status_bar;
mod trace;
mod values;

use ratatui::layout::{Constraint, Layout, Position, Rect};
use ratatui::widgets::Paragraph;
use ratatui::Frame;

use crate::teach::Teach;
use crate::tui::graph_layout;
use crate::tui::screen::{draw_help, too_small, MIN_HEIGHT, MIN_WIDTH};
use crate::tui::theme::Theme;
pub(crate) use help::teach_help;
use values::values_rows;

/// Draws stand-alone teach mode (`sapnet teach`).
pub fn draw(frame: &mut Frame, teach: &Teach, help: bool, theme: Theme) {
    let area = frame.area();
    if too_small(frame, area) {
        return;
    }
    let [main, status] = Layout::vertical([Constraint::Min(0), Constraint::Length(1)]).areas(area);
    draw_body(frame, main, teach, theme);
    status_bar::draw(frame, status, teach, theme);
    if help {
        draw_help(frame, area, &teach_help(teach, false), theme);
    }
}

/// Teach mode's panels, in the dashboard or on their own.
pub fn draw_body(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let call = call::paragraph(teach, theme);
    let edits = edits::paragraph(teach, theme);
    let panels = layout(area, teach.net().len(), &call, &edits);
    graph_panel::draw(frame, panels.graph, teach, theme);
    frame.render_widget(call, panels.call);
    frame.render_widget(edits, panels.edits);
    values::draw(frame, panels.values, teach, theme);
    stack::draw(frame, panels.stack, teach, theme);
    trace::draw(frame, panels.trace, teach, theme);
}

/// Where teach mode's panels go.
struct Panels {
    graph: Rect,
    call: Rect,
    values: Rect,
    stack: Rect,
    edits: Rect,
    trace: Rect,
}

/// Teach mode's panels in `area`, for hit-testing a click (drawing lays them out from the
/// paragraphs it draws, [`layout`]).
fn panels(area: Rect, teach: &Teach) -> Panels {
    let call = call::paragraph(teach, Theme::plain());
    let edits = edits::paragraph(teach, Theme::plain());
    layout(area, teach.net().len(), &call, &edits)
}

/// Teach mode's panels in `area` for a net of `n` policies: the call's and the edit's
/// panels as tall as their wrapped text (at 80 columns both wrap to more lines than fixed
/// heights held), the graph and the trace taking what is left.
fn layout(area: Rect, n: usize, call: &Paragraph, edits: &Paragraph) -> Panels {
    let [left, right] =
        Layout::horizontal([Constraint::Percentage(45), Constraint::Percentage(55)]).areas(area);
    let rows = |paragraph: &Paragraph, width: u16| {
        u16::try_from(paragraph.line_count(width.saturating_sub(2))).unwrap_or(u16::MAX)
    };
    let call_rows = rows(call, left.width).clamp(9, left.height.saturating_sub(GRAPH_MIN_ROWS));
    let [graph, call] = Layout::vertical([
        Constraint::Min(GRAPH_MIN_ROWS),
        Constraint::Length(call_rows),
    ])
    .areas(left);
    let short = area.height < 30;
    let values_rows = (n as u16 + 3).min(right.height / 3);
    let stack_rows = if short { 5 } else { 7 };
    let edit_rows = rows(edits, right.width).clamp(
        6,
        right
            .height
            .saturating_sub(values_rows + stack_rows + TRACE_MIN_ROWS),
    );
    let [values, stack, edits, trace] = Layout::vertical([
        Constraint::Length(values_rows),
        Constraint::Length(stack_rows),
        Constraint::Length(edit_rows),
        Constraint::Min(TRACE_MIN_ROWS),
    ])
    .areas(right);
    Panels {
        graph,
        call,
        values,
        stack,
        edits,
        trace,
    }
}

/// Rows the graph keeps however long the call's text, and the trace however long the edit's.
const GRAPH_MIN_ROWS: u16 = 8;
const TRACE_MIN_ROWS: u16 = 3;

/// The policy under the cell `(column, row)` of teach mode's panels drawn in `area`: a node
/// of the graph, or a row of the activations table.
pub fn policy_at(area: Rect, teach: &Teach, column: u16, row: u16) -> Option<usize> {
    let n = teach.net().len();
    let panels = panels(area, teach);
    let at = Position::new(column, row);
    if panels.graph.contains(at) {
        let positions = graph_layout::positions(n, teach.groups());
        return graph_layout::canvas_point(panels.graph, column, row)
            .and_then(|point| graph_layout::node_at(&positions, point, graph_layout::CLICK_REACH));
    }
    if panels.values.contains(at) && row < panels.values.bottom() - 1 {
        // The rows as drawn, below the border and the header row.
        let line = usize::from(row.checked_sub(panels.values.y + 2)?);
        return values_rows(panels.values, teach).row_at(line);
    }
    None
}

/// The policy a left click at `(column, row)` of a `screen` showing teach mode (its panels
/// above the status line, in the dashboard or on their own) lands on, if any.
pub fn clicked(teach: &Teach, screen: Rect, column: u16, row: u16) -> Option<usize> {
    if screen.width < MIN_WIDTH || screen.height < MIN_HEIGHT {
        return None;
    }
    let [main, _status] =
        Layout::vertical([Constraint::Min(0), Constraint::Length(1)]).areas(screen);
    policy_at(main, teach, column, row)
}
