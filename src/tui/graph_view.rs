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

/// Draws `scene` in `block` over `area`.
pub fn draw(frame: &mut Frame, area: Rect, block: Block, scene: Scene, theme: Theme) {
    let positions = positions(scene.net.len(), scene.groups);
    let top = highest(scene.net.activations().iter().copied());
    let labels = labels(scene.names);
    let show_weights = scene.net.len() <= 6;
    // The canvas's x units per terminal cell.
    let cell = 2.7 / f64::from(area.width.saturating_sub(2).max(1));
    let weight_labels = if show_weights {
        let row = (Y_BOUNDS[1] - Y_BOUNDS[0]) / f64::from(area.height.saturating_sub(2).max(1));
        weight_label_points(
            scene
                .net
                .graph()
                .edges()
                .map(|(i, j, _)| (positions[i], positions[j])),
            (cell, row),
            4,
        )
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
                if let Some(&(x, y)) = weight_labels.get(k) {
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
                    let width = cell * name.chars().count() as f64;
                    ctx.print(
                        (x * scale - width / 2.0).clamp(-1.35, 1.35 - width),
                        y * scale,
                        Span::styled(name.clone(), theme.dim()),
                    );
                }
            }
            for (i, &(x, y)) in positions.iter().enumerate() {
                let activation = scene.net.activations()[i];
                let level = if top > 0.0 { activation / top } else { 0.0 };
                let mut style = theme.heat(level);
                if scene.active == Some(i) {
                    style = theme.active();
                }
                let excluded = scene.excluded.get(i).copied().unwrap_or(false);
                if excluded {
                    style = theme.dim();
                }
                if scene.cursor == Some(i) {
                    style = style.patch(theme.cursor());
                }
                let symbol = if excluded { "×" } else { heat_symbol(level) };
                let text = format!("{symbol}{}", labels[i]);
                // Roughly centre the label on the node (0.04 units is about a cell of a
                // panel 60 cells wide; exact centring would need the panel's width).
                ctx.print(
                    x - 0.04 * text.chars().count() as f64 / 2.0,
                    y,
                    Line::styled(text, style),
                );
            }
        });
    frame.render_widget(canvas, area);
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

/// Where each edge's weight is printed: its middle, unless an earlier label is already
/// there (the two diagonals of a square cross at their middles); then a row above or below
/// it, or a third of the way along the edge. `cell` is a terminal cell's size in canvas
/// units (x, y), `width` a label's characters.
pub fn weight_label_points(
    edges: impl IntoIterator<Item = ((f64, f64), (f64, f64))>,
    cell: (f64, f64),
    width: usize,
) -> Vec<(f64, f64)> {
    let mut points: Vec<(f64, f64)> = Vec::new();
    for (a, b) in edges {
        let along = |t: f64| (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
        let middle = along(0.5);
        let taken = |p: (f64, f64)| {
            points.iter().any(|q| {
                (p.0 - q.0).abs() < (width + 1) as f64 * cell.0 && (p.1 - q.1).abs() < cell.1
            })
        };
        let candidates = [
            middle,
            (middle.0, middle.1 + cell.1),
            (middle.0, middle.1 - cell.1),
            along(1.0 / 3.0),
            along(2.0 / 3.0),
        ];
        let point = candidates
            .into_iter()
            .find(|&p| !taken(p))
            .unwrap_or(middle);
        points.push(point);
    }
    points
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

    #[test]
    fn crossing_edges_print_their_weights_apart() {
        let (n, e, s, w) = ((0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0));
        let cell = (0.1, 0.2);
        let points = weight_label_points([(n, e), (n, s), (e, w)], cell, 4);
        assert_eq!(points[0], (0.5, 0.5));
        assert_eq!(points[1], (0.0, 0.0), "the first diagonal at its middle");
        assert_eq!(points[2], (0.0, 0.2), "the second a row above it");
    }
}
