//! Drawing teach mode: one activation's spreading (Algorithms 1 and 2), every quantity
//! beside its equation, and the live edits' effect on the walk. This file lays the panels
//! out, hands each to its file, and tells what a click lands on in the same rectangles.

mod call;
mod chart;
mod edits;
mod figures;
mod graph_panel;
mod help;
mod stack;
mod status_bar;
mod time_table;
mod trace;
mod tree;
mod values;

use ratatui::layout::{Constraint, Layout, Position, Rect};
use ratatui::widgets::Paragraph;
use ratatui::Frame;

use crate::teach::session::WalkPanel;
use crate::teach::Teach;
use crate::tui::screen::{draw_help, too_small, MIN_HEIGHT, MIN_WIDTH};
use crate::tui::theme::Theme;
use crate::tui::{graph_layout, graph_view};
pub(crate) use help::teach_help;

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
    let edits = edits::paragraph(teach, theme, compact(area));
    let panels = layout(area, teach, &edits);
    let call = call::paragraph(teach, theme, panels.call.width);
    graph_panel::draw(frame, panels.graph, teach, theme);
    frame.render_widget(call, panels.call);
    frame.render_widget(edits, panels.edits);
    values::draw(frame, panels.values, teach, theme);
    stack::draw(frame, panels.stack, teach, theme);
    draw_walk_panel(frame, panels.trace, teach, theme);
}

/// The panel under the edits: the trace, the tree, the chart or A and P through time
/// (`v` cycles), its title naming the next.
fn draw_walk_panel(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let panel = teach.panel();
    match panel {
        WalkPanel::Trace => trace::draw(frame, area, teach, theme),
        WalkPanel::Tree => tree::draw(frame, area, teach, theme, &walk_title(panel)),
        WalkPanel::Chart => chart::draw(frame, area, teach, theme, &walk_title(panel)),
        WalkPanel::ThroughTime => time_table::draw(frame, area, teach, theme, &walk_title(panel)),
    }
}

/// `tree (v: chart)`: what the panel shows and what `v` shows next.
fn walk_title(panel: WalkPanel) -> String {
    format!("{} (v: {})", panel.name(), panel.following().name())
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
    let edits = edits::paragraph(teach, Theme::plain(), compact(area));
    layout(area, teach, &edits)
}

/// Teach mode's panels in `area`: the call's panel as tall as the tallest text a call of
/// this lesson can give at its width (so the graph above keeps its height from step to
/// step), the edit panel as tall as its wrapped text, the trace at least
/// [`TRACE_MIN_ROWS`] and the graph taking what is left.
fn layout(area: Rect, teach: &Teach, edits: &Paragraph) -> Panels {
    let n = teach.net().len();
    let [left, right] =
        Layout::horizontal([Constraint::Percentage(45), Constraint::Percentage(55)]).areas(area);
    let rows = |paragraph: &Paragraph, width: u16| {
        u16::try_from(paragraph.line_count(width.saturating_sub(2))).unwrap_or(u16::MAX)
    };
    let call_rows =
        call::tallest_rows(teach, left.width).min(left.height.saturating_sub(GRAPH_MIN_ROWS));
    let [graph, call] = Layout::vertical([
        Constraint::Min(GRAPH_MIN_ROWS),
        Constraint::Length(call_rows),
    ])
    .areas(left);
    let short = compact(area);
    let values_rows = (n as u16 + 3).min(right.height / 3);
    let stack_rows = if short { 4 } else { 7 };
    let edit_rows = rows(edits, right.width).clamp(
        EDIT_MIN_ROWS,
        right
            .height
            .saturating_sub(values_rows + stack_rows + TRACE_MIN_ROWS)
            .max(EDIT_MIN_ROWS),
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

/// A screen too short for every panel's every line: the stack and the edit panel say less.
fn compact(area: Rect) -> bool {
    area.height < 30
}

/// Rows the graph keeps however long the call's text.
const GRAPH_MIN_ROWS: u16 = 8;
/// The trace's rows at the least: four calls under its header, inside its border (at
/// 80×24 it once showed two).
const TRACE_MIN_ROWS: u16 = 7;
/// The edit panel's rows at the least: the knobs' line, wrapped, and a line of what the
/// last edit did.
const EDIT_MIN_ROWS: u16 = 5;

/// The policy under the cell `(column, row)` of teach mode's panels drawn in `area`: a node
/// of the graph, or a row of the activations table.
pub fn policy_at(area: Rect, teach: &Teach, column: u16, row: u16) -> Option<usize> {
    let n = teach.net().len();
    let panels = panels(area, teach);
    let at = Position::new(column, row);
    if panels.graph.contains(at) {
        let label =
            graph_view::node_label_at(panels.graph, teach.names(), teach.groups(), column, row);
        if label.is_some() {
            return label;
        }
        let positions = graph_layout::positions(n, teach.groups());
        return graph_layout::canvas_point(panels.graph, column, row)
            .and_then(|point| graph_layout::node_at(&positions, point, graph_layout::CLICK_REACH));
    }
    if panels.values.contains(at) {
        return values::policy_at(panels.values, teach, column, row);
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
