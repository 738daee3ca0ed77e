//! The activations table: each policy's A (eq. 8), what the walk has deposited (eq. 11),
//! P (eq. 6), and after an edit how the walk's end moved.

use ratatui::layout::{Constraint, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Cell, Row, Table};
use ratatui::Frame;

use super::figures::{fit, name_width, name_width_of, signed};
use crate::teach::Teach;
use crate::tui::graph_view::{self, node_style};
use crate::tui::row_window::RowWindow;
use crate::tui::screen::probability_bar;
use crate::tui::theme::Theme;

/// The rows of the activations table that a panel of `area` shows, in the policies'
/// order. Where they do not all fit, the rows that matter come first: the picked policy,
/// the activated one, the one the next call reaches and the one the last call reached,
/// then those the walk has deposited most on (eq. 11); the room left goes to the rows
/// around the picked one. So on a live graph of ten policies in four rows the policies
/// receiving ΔA stay in view, not only the picked one's neighbours by index.
pub(super) fn values_rows(area: Rect, teach: &Teach) -> ShownRows {
    let room = usize::from(area.height.saturating_sub(3));
    let n = teach.net().len();
    let walk = teach.walk();
    let mut receivers: Vec<usize> = Vec::new();
    if let Some(w) = &walk {
        receivers.extend(w.pending.last().map(|c| c.to));
        receivers.extend(w.trace.last().map(|s| s.to));
        let mut by_deposit: Vec<usize> = (0..w.deposited.len())
            .filter(|&i| w.deposited[i] != 0.0)
            .collect();
        by_deposit.sort_by(|&a, &b| w.deposited[b].abs().total_cmp(&w.deposited[a].abs()));
        receivers.extend(by_deposit);
    }
    let activated = walk.as_ref().map(|w| w.policy);
    let around = RowWindow::new(n, room, std::iter::once(teach.cursor()).chain(activated));
    let priority = std::iter::once(teach.cursor())
        .chain(activated)
        .chain(receivers)
        .chain(around.rows());
    let mut rows: Vec<usize> = Vec::with_capacity(room.min(n));
    for row in priority {
        if rows.len() == room.min(n) {
            break;
        }
        if row < n && !rows.contains(&row) {
            rows.push(row);
        }
    }
    rows.sort_unstable();
    ShownRows { rows, total: n }
}

/// The activations table's rows on screen: not always consecutive (see [`values_rows`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct ShownRows {
    rows: Vec<usize>,
    total: usize,
}

impl ShownRows {
    /// The policy shown on the `line`-th line of the table (from 0), if any.
    pub(super) fn row_at(&self, line: usize) -> Option<usize> {
        self.rows.get(line).copied()
    }

    /// `6 of 10 not shown`, for the panel's bottom border, or nothing when all are.
    fn marker(&self) -> Option<String> {
        let hidden = self.total - self.rows.len();
        (hidden > 0).then(|| format!(" {hidden} of {} not shown ", self.total))
    }
}

/// A and P of every policy, with what the walk has deposited (eq. 11) and, after an edit,
/// how the walk's end moved.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let names = teach.names();
    let net = teach.net();
    let probabilities = net.probabilities();
    let top = graph_view::highest(net.activations().iter().copied());
    let deposited = teach.walk().map(|w| w.deposited);
    // The edit's columns where the panel has room; the edit panel sums them up anyway.
    let edit = teach
        .last_edit()
        .filter(|_| area.width >= 60)
        .map(|r| (r.activation_change(), r.probability_change()));
    // The figures' columns, then the names in the room left (the names are cut only
    // where there is none), then the lesson's descriptions where they fit whole; where
    // they do not, the title gives the picked policy's.
    let mut widths = vec![
        Constraint::Length(VALUE_WIDTH as u16),
        Constraint::Length(VALUE_WIDTH as u16),
        Constraint::Length(11),
    ];
    let mut header = vec!["A (eq. 8)", "ΣΔA eq.11", "P (eq. 6)"];
    if edit.is_some() {
        widths.extend([Constraint::Length(9), Constraint::Min(6)]);
        header.extend(["edit: ΔA", "ΔP"]);
    }
    let figures: u16 = widths.iter().map(|w| constraint_width(*w) + 1).sum();
    let room = area.width.saturating_sub(2 + figures);
    let name_width = name_width(names, 6, usize::from(room));
    let descriptions = teach.descriptions();
    let description_width = descriptions.map_or(0, name_width_of);
    let beside = descriptions.filter(|_| description_width < room.saturating_sub(name_width));
    if beside.is_some() {
        widths.insert(0, Constraint::Length(description_width));
        header.insert(0, "name");
    }
    widths.insert(0, Constraint::Length(name_width));
    header.insert(0, "policy");
    let mut title = " activations ".to_string();
    if let (Some(descriptions), None) = (descriptions, beside) {
        let i = teach.cursor();
        title = format!(" activations · {} = {} ", names[i], descriptions[i]);
    }
    let window = values_rows(area, teach);
    let rows = window.rows.iter().map(|&i| {
        let name = &names[i];
        let a = net.activations()[i];
        let mut cells = vec![Cell::from(Span::styled(
            name.clone(),
            node_style(theme, a, top),
        ))];
        if let Some(descriptions) = beside {
            cells.push(Cell::from(descriptions[i].clone()));
        }
        cells.extend([
            Cell::from(fit(a, VALUE_WIDTH)),
            Cell::from(deposited.map_or(String::new(), |d| fit(d[i], VALUE_WIDTH))),
            Cell::from(probability_bar(probabilities[i], 6)),
        ]);
        if let Some((da, dp)) = &edit {
            cells.push(Cell::from(signed(da[i], 4)));
            cells.push(Cell::from(signed(dp[i], 3)));
        }
        let row = Row::new(cells);
        if i == teach.cursor() {
            row.style(theme.cursor())
        } else {
            row
        }
    });
    frame.render_widget(
        Table::new(rows, widths)
            .header(Row::new(header).style(theme.title()))
            .block(
                Block::bordered()
                    .title(Span::styled(title, theme.title()))
                    .title_bottom(
                        Line::styled(window.marker().unwrap_or_default(), theme.title())
                            .right_aligned(),
                    ),
            ),
        area,
    );
}

/// The cells a fixed column takes (a `Min` column its minimum).
fn constraint_width(constraint: Constraint) -> u16 {
    match constraint {
        Constraint::Length(n) | Constraint::Min(n) => n,
        _ => 0,
    }
}

/// Characters of an activation in the table.
const VALUE_WIDTH: usize = 10;
