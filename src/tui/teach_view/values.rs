//! The activations table: each policy's A (eq. 8), what the walk has deposited (eq. 11),
//! P (eq. 6), and after an edit how the walk's end moved. A row per policy where they fit;
//! where they do not, a grid of every policy (Table II's ten at 80×24), so that none is
//! left out where their names allow it.

use ratatui::layout::{Constraint, Position, Rect};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Cell, Paragraph, Row, Table};
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
/// how the walk's end moved: a row each where they fit, else a grid of them all.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    match Grid::fit(area, teach) {
        Some(grid) => render_grid(frame, area, teach, theme, &grid),
        None => render_table(frame, area, teach, theme),
    }
}

/// The policy drawn at `(column, row)` of the panel in `area`, if any.
pub(super) fn policy_at(area: Rect, teach: &Teach, column: u16, row: u16) -> Option<usize> {
    let inner = Block::bordered().inner(area);
    if !area.contains(Position::new(column, row)) || row >= inner.bottom() {
        return None;
    }
    let line = usize::from(row.checked_sub(inner.y)?);
    match Grid::fit(area, teach) {
        Some(grid) => grid.policy_at(line, usize::from(column.saturating_sub(inner.x))),
        // Below the header row.
        None => values_rows(area, teach).row_at(line.checked_sub(1)?),
    }
}

/// A row per policy (those that matter where not all fit, [`values_rows`]), its figures
/// under a header.
fn render_table(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
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
    let columns = TableColumns::fit(area, teach, edit.is_some());
    let beside = columns.descriptions;
    let window = values_rows(area, teach);
    let rows = window.rows.iter().map(|&i| {
        let a = net.activations()[i];
        let mut cells = vec![Cell::from(Span::styled(
            names[i].clone(),
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
    let block = panel_block(teach, theme, beside.is_none()).title_bottom(
        Line::styled(window.marker().unwrap_or_default(), theme.title()).right_aligned(),
    );
    frame.render_widget(
        Table::new(rows, columns.widths)
            .header(Row::new(columns.header).style(theme.title()))
            .block(block),
        area,
    );
}

/// The panel's frame: ` activations `, with the picked policy's description where the
/// descriptions have no column (`titled`).
fn panel_block(teach: &Teach, theme: Theme, titled: bool) -> Block<'static> {
    let title = match teach.descriptions().filter(|_| titled) {
        Some(descriptions) => {
            let i = teach.cursor();
            format!(" activations · {} = {} ", teach.names()[i], descriptions[i])
        }
        None => " activations ".to_string(),
    };
    Block::bordered().title(Span::styled(title, theme.title()))
}

/// The table's columns: the figures' first, then the names in the room left (the names
/// are cut only where there is none), then the lesson's descriptions where they fit whole;
/// where they do not, the title gives the picked policy's.
struct TableColumns<'a> {
    widths: Vec<Constraint>,
    header: Vec<&'static str>,
    descriptions: Option<&'a [String]>,
}

impl<'a> TableColumns<'a> {
    fn fit(area: Rect, teach: &'a Teach, edit: bool) -> Self {
        let mut widths = vec![
            Constraint::Length(VALUE_WIDTH as u16),
            Constraint::Length(VALUE_WIDTH as u16),
            Constraint::Length(11),
        ];
        let mut header = vec!["A (eq. 8)", "ΣΔA eq.11", "P (eq. 6)"];
        if edit {
            widths.extend([Constraint::Length(9), Constraint::Min(6)]);
            header.extend(["edit: ΔA", "ΔP"]);
        }
        let figures: u16 = widths.iter().map(|w| constraint_width(*w) + 1).sum();
        let room = area.width.saturating_sub(2 + figures);
        let name_width = name_width(teach.names(), 6, usize::from(room));
        let descriptions = teach.descriptions();
        let description_width = descriptions.map_or(0, name_width_of);
        let beside = descriptions.filter(|_| description_width < room.saturating_sub(name_width));
        if beside.is_some() {
            widths.insert(0, Constraint::Length(description_width));
            header.insert(0, "name");
        }
        widths.insert(0, Constraint::Length(name_width));
        header.insert(0, "policy");
        Self {
            widths,
            header,
            descriptions: beside,
        }
    }
}

/// Every policy in columns of `height`, down then across, each cell its name and figures
/// (ΣΔA where there is room), the columns named in the panel's bottom border: for a panel
/// too short for a row each, as Table II's ten policies at 80×24 (a table there once
/// showed four).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Grid {
    policies: usize,
    height: usize,
    columns: usize,
    name_width: usize,
    /// Whether the cells have room for ΣΔA (eq. 11).
    deposits: bool,
}

/// Between two of the grid's columns.
const GRID_GAP: &str = " │ ";
/// An activation's characters in the grid (`0.833333`).
const GRID_VALUE_WIDTH: usize = 8;
/// P's characters in the grid (`0.22`).
const GRID_P_WIDTH: usize = 4;

impl Grid {
    /// The grid for the panel in `area`, where a row each would leave policies out and a
    /// grid shows them all with their names whole.
    pub(super) fn fit(area: Rect, teach: &Teach) -> Option<Self> {
        let policies = teach.net().len();
        let room = usize::from(area.height.saturating_sub(2));
        if policies < room || room == 0 {
            // A header and a row each fit.
            return None;
        }
        let columns = policies.div_ceil(room);
        let inner = usize::from(area.width.saturating_sub(2));
        let name_width = usize::from(name_width_of(teach.names()));
        [true, false].into_iter().find_map(|deposits| {
            let grid = Grid {
                policies,
                height: policies.div_ceil(columns),
                columns,
                name_width,
                deposits,
            };
            (grid.width() <= inner).then_some(grid)
        })
    }

    /// A cell's characters.
    fn cell_width(&self) -> usize {
        let deposits = if self.deposits {
            GRID_VALUE_WIDTH + 1
        } else {
            0
        };
        self.name_width + 1 + GRID_VALUE_WIDTH + 1 + deposits + GRID_P_WIDTH
    }

    fn width(&self) -> usize {
        self.columns * self.cell_width() + (self.columns - 1) * GRID_GAP.chars().count()
    }

    /// The policy in the `line`-th line of the grid at `column` characters from its left,
    /// if any (none on a gap).
    fn policy_at(&self, line: usize, column: usize) -> Option<usize> {
        let stride = self.cell_width() + GRID_GAP.chars().count();
        let (k, within) = (column / stride, column % stride);
        let i = k * self.height + line;
        (line < self.height && k < self.columns && within < self.cell_width() && i < self.policies)
            .then_some(i)
    }

    /// What the cells hold, for the bottom border.
    fn legend(&self) -> &'static str {
        if self.deposits {
            " A eq. 8 · ΣΔA eq. 11 · P eq. 6 "
        } else {
            " A (eq. 8) · P (eq. 6) "
        }
    }
}

/// The policies in a [`Grid`].
fn render_grid(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme, grid: &Grid) {
    let lines: Vec<Line> = (0..grid.height)
        .map(|line| {
            let mut spans = Vec::new();
            for k in 0..grid.columns {
                let i = k * grid.height + line;
                if i >= grid.policies {
                    break;
                }
                if k > 0 {
                    spans.push(Span::styled(GRID_GAP, theme.dim()));
                }
                spans.extend(grid_cell(teach, theme, grid, i));
            }
            Line::from(spans)
        })
        .collect();
    let block = panel_block(teach, theme, true)
        .title_bottom(Line::styled(grid.legend(), theme.title()).right_aligned());
    frame.render_widget(Paragraph::new(lines).block(block), area);
}

/// Policy `i`'s cell: its name in its node's heat, A, ΣΔA where there is room, P; the
/// picked policy's reversed.
fn grid_cell(teach: &Teach, theme: Theme, grid: &Grid, i: usize) -> Vec<Span<'static>> {
    let net = teach.net();
    let a = net.activations()[i];
    let top = graph_view::highest(net.activations().iter().copied());
    let width = grid.name_width;
    let mut figures = format!(" {:<GRID_VALUE_WIDTH$}", fit(a, GRID_VALUE_WIDTH));
    if grid.deposits {
        let deposited = teach
            .walk()
            .map_or(String::new(), |w| fit(w.deposited[i], GRID_VALUE_WIDTH));
        figures.push_str(&format!(" {deposited:<GRID_VALUE_WIDTH$}"));
    }
    figures.push_str(&format!(" {:.2}", net.probabilities()[i]));
    let picked = if i == teach.cursor() {
        theme.cursor()
    } else {
        Style::new()
    };
    vec![
        Span::styled(
            format!("{:<width$}", teach.names()[i]),
            node_style(theme, a, top).patch(picked),
        ),
        Span::styled(figures, picked),
    ]
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
