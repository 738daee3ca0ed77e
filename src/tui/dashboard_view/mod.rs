//! Drawing the dashboard: pure functions of its state, so the snapshot tests draw exactly
//! what a user sees. This file lays the screen out, hands each panel to its file, and
//! tells what a click lands on in the same rectangles; teach mode on the live graph is
//! drawn by [`teach_view`]. The `?` overlay is its screen's (the Run view's keys with
//! [`legend`] after them).

mod figures;
mod graph_panel;
mod help;
mod loss_chart;
mod policy_table;
mod reward_chart;
mod status_bar;
mod step_line;

use ratatui::layout::{Constraint, Layout, Position, Rect};
use ratatui::text::Span;
use ratatui::widgets::{Block, Paragraph, Wrap};
use ratatui::Frame;

use crate::tui::dashboard::{Clicked, Dashboard, Focus, Mode};
use crate::tui::graph_layout;
use crate::tui::screen::too_small;
use crate::tui::teach_view;
use crate::tui::theme::Theme;
pub use help::legend;
use policy_table::policy_rows;
use step_line::step_line;

/// Draws the whole dashboard (or teach mode on the live graph).
pub fn draw_dashboard(frame: &mut Frame, dashboard: &Dashboard, theme: Theme) {
    let area = frame.area();
    if too_small(frame, area) {
        return;
    }
    let [main, status] = Layout::vertical([Constraint::Min(0), Constraint::Length(1)]).areas(area);
    match (&dashboard.teach, dashboard.mode) {
        (Some(teach), Mode::Teach) => teach_view::draw_body(frame, main, teach, theme),
        _ => draw_training(frame, dashboard, theme),
    }
    status_bar::draw(frame, status, dashboard, theme);
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
        return teach_view::clicked(teach, area, column, row).map(Clicked::Teach);
    }
    let view = dashboard.library.as_ref()?;
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
    match &dashboard.library {
        Some(view) => {
            if !graph.is_empty() {
                let focused = dashboard.focus == Focus::Graph;
                let block = focus_block(&graph_panel::title(view), focused, theme);
                graph_panel::draw(frame, graph, block, view, dashboard, theme);
            }
            if !table.is_empty() {
                let focused = dashboard.focus == Focus::Table;
                let block =
                    focus_block(&policy_table::title(dashboard, table.width), focused, theme);
                policy_table::draw(frame, table, block, view, dashboard, theme);
            }
        }
        None => {
            // A followed run that started without a library reuses none (DQN from
            // scratch); before it starts it is still loading its library or starting its
            // task (a Gymnasium worker takes a second or more).
            let started =
                |method: &String| dashboard.runs.iter().any(|r| r.method.label() == method);
            let note = match &dashboard.followed {
                Some(method) if started(method) => format!(
                    "{method} reuses no library: no graph or policy table to show. Its curve \
                     and loss are below."
                ),
                Some(method) => format!("{method}: loading the library and starting the task…"),
                None => "This config runs no SAP-Net: only its baselines train.".to_string(),
            };
            let note = Paragraph::new(note)
                .block(focus_block("SAP-Net graph", false, theme))
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
        reward_chart::draw(frame, rewards, &dashboard.runs, &dashboard.reference, theme);
        // Known unless read from files that did not keep it.
        let known = dashboard.from_files.is_none_or(|f| f.learner);
        loss_chart::draw(frame, loss, (dashboard.main_run(), known), theme);
    }
}

/// A panel's border and title, bright where the arrows move (tab), dim elsewhere.
fn focus_block(title: &str, focused: bool, theme: Theme) -> Block<'static> {
    let block = Block::bordered().title(Span::styled(format!(" {title} "), theme.title()));
    if focused {
        block.border_style(theme.title())
    } else {
        block.border_style(theme.dim())
    }
}
