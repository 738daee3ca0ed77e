//! The SAP-Net graph on a ratatui `Canvas`: policies around a circle, grouped by category
//! with a gap between groups; edges dotted by weight (denser is closer, as M is a
//! distance), solid where activation just travelled; nodes coloured (or, without colour,
//! shaped) by their share of the highest activation.

use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Context, Line as Segment, Points};
use ratatui::widgets::Block;
use ratatui::Frame;

use super::graph_layout::{positions, X_BOUNDS, Y_BOUNDS};
use super::theme::{heat_symbol, Theme};
use crate::sapnet::SapNet;
use crate::teach::labels::labels;

/// What to draw of a graph.
#[derive(Debug, Clone, Copy)]
pub struct Scene<'a> {
    pub net: &'a SapNet,
    pub names: &'a [String],
    /// Category of each policy, for grouping; `None` keeps index order in one group.
    pub groups: Option<&'a [usize]>,
    /// A name per category, written outside its group (the source tasks of a library over
    /// several tasks); empty for none.
    pub group_names: &'a [String],
    pub cursor: Option<usize>,
    /// The policy acting now (dashboard) or the activated one (teach).
    pub active: Option<usize>,
    /// Edges activation just travelled along.
    pub lit: &'a [(usize, usize)],
    /// The edge of the call about to be made (teach).
    pub walking: Option<(usize, usize)>,
    /// Per policy, whether its category is out of eq. 6's candidates (drawn `×`, dim);
    /// empty for none.
    pub excluded: &'a [bool],
}

/// Draws `scene` in `block` over `area`, the edges' weights written where the graph has
/// six policies or fewer.
pub fn draw(frame: &mut Frame, area: Rect, block: Block, scene: Scene, theme: Theme) {
    let weights = scene.net.len() <= 6;
    draw_with_weights(frame, area, block, scene, theme, weights);
}

/// Draws `scene`, writing each edge's weight (`weights`) where it finds room for it: off
/// the edges' crossings, the nodes and the other weights (teach mode writes them on every
/// lesson; Table II's ten policies once showed none).
pub fn draw_with_weights(
    frame: &mut Frame,
    area: Rect,
    block: Block,
    scene: Scene,
    theme: Theme,
    weights: bool,
) {
    let positions = positions(scene.net.len(), scene.groups);
    let top = highest(scene.net.activations().iter().copied());
    let labels = labels(scene.names);
    let grid = CellGrid::of(area);
    // The nodes' labels first: the weights find room around them.
    let node_texts: Vec<String> = (0..positions.len())
        .map(|i| {
            let excluded = scene.excluded.get(i).copied().unwrap_or(false);
            let activation = scene.net.activations()[i];
            let level = if top > 0.0 { activation / top } else { 0.0 };
            let symbol = if excluded { "×" } else { heat_symbol(level) };
            format!("{symbol}{}", labels[i])
        })
        .collect();
    let node_spans = node_label_spans(&grid, &positions, &node_texts);
    let weight_spans = if weights {
        let edges: Vec<EdgeSegment> = scene
            .net
            .graph()
            .edges()
            .map(|(i, j, _)| (positions[i], positions[j]))
            .collect();
        weight_label_spans(&grid, &edges, &node_spans, WEIGHT_LABEL_WIDTH)
    } else {
        Vec::new()
    };
    let canvas = Canvas::default()
        .block(block)
        .x_bounds(X_BOUNDS)
        .y_bounds(Y_BOUNDS)
        .paint(|ctx| {
            for (k, (i, j, w)) in scene.net.graph().edges().enumerate() {
                let (a, b) = (positions[i], positions[j]);
                let lit = scene.lit.iter().any(|&e| e == (i, j) || e == (j, i));
                let walking = scene.walking.is_some_and(|e| e == (i, j) || e == (j, i));
                if walking {
                    solid(ctx, a, b, color(theme, Color::Green));
                } else if lit {
                    solid(ctx, a, b, color(theme, Color::Yellow));
                } else {
                    dotted(ctx, a, b, w, color(theme, Color::DarkGray));
                }
                if let Some(Some(span)) = weight_spans.get(k) {
                    let (x, y) = grid.point(span.column, span.row);
                    ctx.print(x, y, Span::styled(format!("{w:.2}"), theme.dim()));
                }
            }
            ctx.layer();
            if let Some(groups) = scene.groups {
                for (group, name) in scene.group_names.iter().enumerate() {
                    let members: Vec<(f64, f64)> = (0..positions.len())
                        .filter(|&i| groups[i] == group)
                        .map(|i| positions[i])
                        .collect();
                    if members.is_empty() {
                        continue;
                    }
                    let k = members.len() as f64;
                    let (x, y) = members
                        .iter()
                        .fold((0.0, 0.0), |(sx, sy), (x, y)| (sx + x / k, sy + y / k));
                    // Outside the circle, beyond the group's middle, inside the panel.
                    let scale = 1.22 / (x * x + y * y).sqrt().max(1e-9);
                    let width = grid.cell.0 * name.chars().count() as f64;
                    ctx.print(
                        (x * scale - width / 2.0).clamp(-1.35, 1.35 - width),
                        y * scale,
                        Span::styled(name.clone(), theme.dim()),
                    );
                }
            }
            for (i, text) in node_texts.iter().enumerate() {
                let activation = scene.net.activations()[i];
                let level = if top > 0.0 { activation / top } else { 0.0 };
                let mut style = theme.heat(level);
                if scene.active == Some(i) {
                    style = theme.active();
                }
                if scene.excluded.get(i).copied().unwrap_or(false) {
                    style = theme.dim();
                }
                if scene.cursor == Some(i) {
                    style = style.patch(theme.cursor());
                }
                let span = node_spans[i];
                let (x, y) = grid.point(span.column, span.row);
                ctx.print(x, y, Line::styled(text.clone(), style));
            }
        });
    frame.render_widget(canvas, area);
}

/// The node whose label covers the cell `(column, row)` of a graph panel drawn over
/// `area` (the screen's cells), labels placed as [`draw`] places them: a label moved a
/// row off its node is picked where it is seen.
pub fn node_label_at(
    area: Rect,
    names: &[String],
    groups: Option<&[usize]>,
    column: u16,
    row: u16,
) -> Option<usize> {
    let grid = CellGrid::of(area);
    let positions = positions(names.len(), groups);
    // Every node's symbol is one character wide: which one does not move its label.
    let texts: Vec<String> = labels(names).iter().map(|l| format!("○{l}")).collect();
    let (column, row) = (
        column.checked_sub(area.x + 1)?,
        row.checked_sub(area.y + 1)?,
    );
    node_label_spans(&grid, &positions, &texts)
        .iter()
        .position(|s| s.row == row && (s.column..s.column + s.width).contains(&column))
}

/// An edge on the canvas, from one node's point to the other's.
pub type EdgeSegment = ((f64, f64), (f64, f64));

/// Characters of an edge's weight as written (`0.40`).
const WEIGHT_LABEL_WIDTH: u16 = 4;

/// The terminal cells of a graph panel's canvas, as ratatui's `Canvas` maps its points
/// to them (a label's point falls in the cell `⌊(x − left)·(W − 1)/width⌋`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellGrid {
    /// Columns and rows inside the border.
    pub columns: u16,
    pub rows: u16,
    /// A cell's size in canvas units (x, y).
    pub cell: (f64, f64),
}

impl CellGrid {
    /// The grid of a panel drawn over `area`, its border included.
    pub fn of(area: Rect) -> Self {
        let columns = area.width.saturating_sub(2).max(2);
        let rows = area.height.saturating_sub(2).max(2);
        let cell = (
            (X_BOUNDS[1] - X_BOUNDS[0]) / f64::from(columns - 1),
            (Y_BOUNDS[1] - Y_BOUNDS[0]) / f64::from(rows - 1),
        );
        Self {
            columns,
            rows,
            cell,
        }
    }

    /// The cell a canvas point falls in, `(column, row)`, clamped to the grid.
    pub fn cell_of(&self, (x, y): (f64, f64)) -> (i32, i32) {
        let column = ((x - X_BOUNDS[0]) / self.cell.0).floor() as i32;
        let row = ((Y_BOUNDS[1] - y) / self.cell.1).floor() as i32;
        (
            column.clamp(0, i32::from(self.columns) - 1),
            row.clamp(0, i32::from(self.rows) - 1),
        )
    }

    /// A canvas point that falls in the cell `(column, row)` (just inside its left and top
    /// edges: the last cell's right edge is the canvas's, and a point past it is not drawn).
    pub fn point(&self, column: u16, row: u16) -> (f64, f64) {
        (
            X_BOUNDS[0] + (f64::from(column) + 1e-6) * self.cell.0,
            Y_BOUNDS[1] - (f64::from(row) + 1e-6) * self.cell.1,
        )
    }
}

/// A label's cells: `width` columns from `column`, on `row`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LabelSpan {
    pub column: u16,
    pub row: u16,
    pub width: u16,
}

impl LabelSpan {
    /// Whether the two share a cell or touch side by side on a row (a label written right
    /// after another would read as one word).
    fn touches(&self, other: &LabelSpan) -> bool {
        self.row == other.row
            && self.column <= other.column + other.width
            && other.column <= self.column + self.width
    }
}

/// Each node's label, centred on its node; a label that would touch one already placed
/// moves a row, then two, away from the circle's middle (then toward it), so that a
/// category's policies drawn close together on a short panel stay apart.
pub fn node_label_spans(
    grid: &CellGrid,
    positions: &[(f64, f64)],
    texts: &[String],
) -> Vec<LabelSpan> {
    let mut placed: Vec<LabelSpan> = Vec::with_capacity(positions.len());
    for (&(x, y), text) in positions.iter().zip(texts) {
        let width = u16::try_from(text.chars().count())
            .unwrap_or(u16::MAX)
            .min(grid.columns);
        let (centre, row) = grid.cell_of((x, y));
        let column = (centre - i32::from(width) / 2).clamp(0, i32::from(grid.columns - width));
        let outward = if y >= 0.0 { -1 } else { 1 };
        let span_at = |row: i32| LabelSpan {
            column: column as u16,
            row: row as u16,
            width,
        };
        let on_grid = |row: &i32| (0..i32::from(grid.rows)).contains(row);
        let span = [0, outward, 2 * outward, -outward, -2 * outward]
            .into_iter()
            .map(|shift| row + shift)
            .filter(on_grid)
            .map(span_at)
            .find(|span| !placed.iter().any(|p| p.touches(span)))
            .unwrap_or_else(|| span_at(row));
        placed.push(span);
    }
    placed
}

/// Where each edge's weight is written, if anywhere: on the edge, as near its middle as
/// leaves the label off every crossing of two edges, off the nodes' labels and off the
/// weights already placed; `None` where no point of the edge has room.
pub fn weight_label_spans(
    grid: &CellGrid,
    edges: &[EdgeSegment],
    nodes: &[LabelSpan],
    width: u16,
) -> Vec<Option<LabelSpan>> {
    let crossings: Vec<(i32, i32)> = crossings(edges)
        .into_iter()
        .map(|p| grid.cell_of(p))
        .collect();
    let mut placed: Vec<LabelSpan> = Vec::new();
    let mut spans = Vec::with_capacity(edges.len());
    for &(a, b) in edges {
        let along = |t: f64| (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
        let free = |span: &LabelSpan| {
            let on_crossing = crossings.iter().any(|&(column, row)| {
                // A column clear on either side: the canvas rounds a point to its cell.
                row == i32::from(span.row)
                    && column >= i32::from(span.column) - 2
                    && column <= i32::from(span.column + span.width) + 1
            });
            !on_crossing
                && !nodes.iter().any(|n| n.touches(span))
                && !placed.iter().any(|p| p.touches(span))
        };
        let span = [0.5, 0.4, 0.6, 0.3, 0.7, 0.25, 0.75, 0.2, 0.8]
            .into_iter()
            .filter_map(|t| {
                let (centre, row) = grid.cell_of(along(t));
                let column = centre - i32::from(width) / 2;
                (column >= 0 && column + i32::from(width) <= i32::from(grid.columns)).then_some(
                    LabelSpan {
                        column: column as u16,
                        row: row as u16,
                        width,
                    },
                )
            })
            .find(free);
        placed.extend(span);
        spans.push(span);
    }
    spans
}

/// The points where two edges cross (edges sharing a node meet there, which is no
/// crossing).
fn crossings(edges: &[EdgeSegment]) -> Vec<(f64, f64)> {
    let mut points = Vec::new();
    for (k, &(a, b)) in edges.iter().enumerate() {
        for &(c, d) in &edges[k + 1..] {
            let shared = [c, d]
                .iter()
                .any(|p| [a, b].iter().any(|q| (p.0 - q.0).hypot(p.1 - q.1) < 1e-9));
            if shared {
                continue;
            }
            // a + t·(b − a) = c + u·(d − c), both t and u within the segments.
            let r = (b.0 - a.0, b.1 - a.1);
            let s = (d.0 - c.0, d.1 - c.1);
            let cross = r.0 * s.1 - r.1 * s.0;
            if cross.abs() < 1e-12 {
                continue;
            }
            let t = ((c.0 - a.0) * s.1 - (c.1 - a.1) * s.0) / cross;
            let u = ((c.0 - a.0) * r.1 - (c.1 - a.1) * r.0) / cross;
            if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
                points.push((a.0 + t * r.0, a.1 + t * r.1));
            }
        }
    }
    points
}

fn color(theme: Theme, color: Color) -> Color {
    if theme.color {
        color
    } else {
        Color::Reset
    }
}

fn solid(ctx: &mut Context, a: (f64, f64), b: (f64, f64), color: Color) {
    ctx.draw(&Segment::new(a.0, a.1, b.0, b.1, color));
}

/// A dotted edge whose dots are closer the lighter (closer) the weight.
fn dotted(ctx: &mut Context, a: (f64, f64), b: (f64, f64), weight: f64, color: Color) {
    let length = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
    let gap = (0.03 + 0.05 * weight.clamp(0.0, 2.0)).max(0.02);
    let dots = (length / gap).ceil().max(1.0) as usize;
    let coords: Vec<(f64, f64)> = (1..dots)
        .map(|k| {
            let t = k as f64 / dots as f64;
            (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1))
        })
        .collect();
    ctx.draw(&Points {
        coords: &coords,
        color,
    });
}

/// The largest of `values`, or 0 if none is positive: the scale of the nodes' heat and of
/// the sparklines.
pub fn highest(values: impl IntoIterator<Item = f64>) -> f64 {
    values.into_iter().fold(0.0_f64, f64::max)
}

/// The style of a table row's name: the same heat as its node.
pub fn node_style(theme: Theme, activation: f64, top: f64) -> Style {
    theme.heat(if top > 0.0 { activation / top } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fig. 2's square with both diagonals' weights: the two diagonals cross at the
    /// middle, where both labels once sat.
    #[test]
    fn weights_are_written_off_the_crossing_and_off_each_other() {
        let (n, e, s, w) = ((0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0));
        let grid = CellGrid::of(Rect::new(0, 0, 36, 13));
        let edges = [(n, e), (n, s), (e, s), (e, w)];
        let spans = weight_label_spans(&grid, &edges, &[], 4);
        let middle = grid.cell_of((0.0, 0.0));
        for span in spans.iter().map(|s| s.expect("room for every weight")) {
            let covers_middle = i32::from(span.row) == middle.1
                && (i32::from(span.column) - 2..=i32::from(span.column + span.width) + 1)
                    .contains(&middle.0);
            assert!(!covers_middle, "{span:?} sits on the crossing {middle:?}");
        }
        let placed: Vec<LabelSpan> = spans.into_iter().flatten().collect();
        for (k, a) in placed.iter().enumerate() {
            for b in &placed[k + 1..] {
                assert!(!a.touches(b), "{a:?} touches {b:?}");
            }
        }
    }

    #[test]
    fn only_edges_apart_cross() {
        let (n, e, s, w) = ((0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0));
        assert_eq!(crossings(&[(n, s), (e, w)]), vec![(0.0, 0.0)]);
        assert!(crossings(&[(n, e), (e, s)]).is_empty(), "they share e");
        assert!(crossings(&[(n, e), (s, w)]).is_empty(), "parallel");
    }

    /// Two nodes a row apart whose labels would overlap: the second moves away from the
    /// middle, on a row of its own.
    #[test]
    fn labels_that_would_overlap_take_rows_of_their_own() {
        let grid = CellGrid::of(Rect::new(0, 0, 36, 12));
        let positions = [(-0.9, -0.42), (-0.88, -0.40)];
        let texts = ["○π7".to_string(), "○π8".to_string()];
        let spans = node_label_spans(&grid, &positions, &texts);
        assert!(!spans[0].touches(&spans[1]), "{spans:?}");
        assert_eq!(
            spans[1].row,
            spans[0].row + 1,
            "below: away from the middle"
        );
    }
}
