//! The SAP-Net graph on a ratatui `Canvas`: policies around a circle, grouped by category
//! with a gap between groups; edges dotted by weight (denser is closer, as M is a
//! distance), solid where activation just travelled; nodes coloured (or, without colour,
//! shaped) by their share of the highest activation.

use std::f64::consts::{FRAC_PI_2, TAU};

use ratatui::layout::Rect;
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Context, Line as Segment, Points};
use ratatui::widgets::Block;
use ratatui::Frame;

use super::theme::{heat_symbol, Theme};
use crate::sapnet::SapNet;

/// The canvas's extent: the unit circle of nodes with room for their labels.
const X_BOUNDS: [f64; 2] = [-1.35, 1.35];
const Y_BOUNDS: [f64; 2] = [-1.3, 1.3];

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
                if scene.cursor == Some(i) {
                    style = style.patch(theme.cursor());
                }
                let text = format!("{}{}", heat_symbol(level), labels[i]);
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

/// Node positions on the unit circle, clockwise from the top, in group order with one
/// empty slot between groups.
pub fn positions(n: usize, groups: Option<&[usize]>) -> Vec<(f64, f64)> {
    let mut order: Vec<usize> = (0..n).collect();
    if let Some(groups) = groups {
        order.sort_by_key(|&i| (groups[i], i));
    }
    let gaps = groups.map_or(0, |g| {
        let mut keys: Vec<usize> = g.to_vec();
        keys.sort_unstable();
        keys.dedup();
        if keys.len() > 1 {
            keys.len()
        } else {
            0
        }
    });
    let slots = (n + gaps).max(1) as f64;
    let mut positions = vec![(0.0, 0.0); n];
    let mut slot = 0;
    for (k, &i) in order.iter().enumerate() {
        if k > 0 && groups.is_some_and(|g| g[order[k - 1]] != g[i]) && gaps > 0 {
            slot += 1;
        }
        let angle = FRAC_PI_2 - TAU * slot as f64 / slots;
        positions[i] = (angle.cos(), angle.sin());
        slot += 1;
    }
    positions
}

/// The node a move from `from` in direction `(dx, dy)` (canvas axes, y up) lands on: of
/// the nodes ahead, the one nearest along the direction, sideways distance counting
/// double (as hjkl move in gitui's and k9s's panes). `None` when no node is ahead.
pub fn nearest_ahead(positions: &[(f64, f64)], from: usize, (dx, dy): (f64, f64)) -> Option<usize> {
    let (x0, y0) = *positions.get(from)?;
    positions
        .iter()
        .enumerate()
        .filter(|&(j, _)| j != from)
        .filter_map(|(j, &(x, y))| {
            let along = (x - x0) * dx + (y - y0) * dy;
            let across = ((x - x0) * dy - (y - y0) * dx).abs();
            (along > 1e-9).then_some((j, along + 2.0 * across))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(j, _)| j)
}

/// How near a click must land to a node, in canvas units (the circle's radius is 1).
pub const CLICK_REACH: f64 = 0.25;

/// The node nearest to `point` (canvas units), if one lies within `reach`.
pub fn node_at(positions: &[(f64, f64)], (x, y): (f64, f64), reach: f64) -> Option<usize> {
    positions
        .iter()
        .enumerate()
        .map(|(i, &(px, py))| (i, (px - x).hypot(py - y)))
        .filter(|&(_, d)| d <= reach)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// The canvas point under the terminal cell `(column, row)` of a graph panel drawn in
/// `area` (its border included), as [`draw`] maps the canvas; `None` outside the canvas.
pub fn canvas_point(area: Rect, column: u16, row: u16) -> Option<(f64, f64)> {
    let inner = Rect::new(
        area.x + 1,
        area.y + 1,
        area.width.saturating_sub(2),
        area.height.saturating_sub(2),
    );
    let inside = (inner.x..inner.x + inner.width).contains(&column)
        && (inner.y..inner.y + inner.height).contains(&row);
    inside.then(|| {
        let fx = (f64::from(column - inner.x) + 0.5) / f64::from(inner.width);
        let fy = (f64::from(row - inner.y) + 0.5) / f64::from(inner.height);
        (
            X_BOUNDS[0] + fx * (X_BOUNDS[1] - X_BOUNDS[0]),
            Y_BOUNDS[1] - fy * (Y_BOUNDS[1] - Y_BOUNDS[0]),
        )
    })
}

/// `cartpole(length=1.0)` → `length=1.0`: a source task's label without its family, for a
/// library whose tasks are variants of one; other labels stay as they are.
pub fn short_task(label: &str) -> &str {
    match label.split_once('(') {
        Some((_, rest)) if rest.ends_with(')') => &rest[..rest.len() - 1],
        _ => label,
    }
}

/// The nodes' labels: [`short_label`]s where they tell every policy apart, else the index
/// in the paper's notation, π0…πN−1 (the tables give the names).
pub fn labels(names: &[String]) -> Vec<String> {
    distinct_labels(names).unwrap_or_else(|| (0..names.len()).map(|i| format!("π{i}")).collect())
}

/// The [`short_label`] of each name, if no two are the same: `source-3`, `source-12` →
/// `3`, `12`; not `1×100`, `2×100` (both `100`).
pub fn distinct_labels(names: &[String]) -> Option<Vec<String>> {
    let labels: Vec<String> = names.iter().map(|n| short_label(n)).collect();
    let mut sorted: Vec<&String> = labels.iter().collect();
    sorted.sort_unstable();
    sorted.dedup();
    (sorted.len() == labels.len()).then_some(labels)
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

/// `source-12` → `12`; short names stay as they are.
pub fn short_label(name: &str) -> String {
    let digits = name.len() - name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    if digits > 0 && name.len() - digits > 2 {
        name[name.len() - digits..].to_string()
    } else {
        name.to_string()
    }
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
    fn groups_sit_together_with_a_gap_between() {
        let p = positions(4, Some(&[1, 0, 1, 0]));
        // Order 1, 3 (group 0), gap, 0, 2 (group 1), gap: six slots, 1 at the top.
        assert!((p[1].0).abs() < 1e-12 && (p[1].1 - 1.0).abs() < 1e-12);
        let angle = |(x, y): (f64, f64)| y.atan2(x);
        let step = TAU / 6.0;
        assert!((angle(p[3]) - (FRAC_PI_2 - step)).abs() < 1e-12);
        assert!((angle(p[0]) - (FRAC_PI_2 - 3.0 * step)).abs() < 1e-9);
    }

    #[test]
    fn moves_land_on_the_nearest_node_ahead() {
        // Four nodes at 12, 3, 6 and 9 o'clock.
        let p = positions(4, None);
        assert_eq!(
            nearest_ahead(&p, 0, (0.0, -1.0)),
            Some(2),
            "down from the top"
        );
        assert_eq!(
            nearest_ahead(&p, 0, (1.0, 0.0)),
            Some(1),
            "right from the top"
        );
        assert_eq!(
            nearest_ahead(&p, 1, (1.0, 0.0)),
            None,
            "nothing right of 3 o'clock"
        );
        assert_eq!(
            nearest_ahead(&p, 3, (1.0, 0.0)),
            Some(1),
            "straight across, not aside"
        );
    }

    #[test]
    fn a_click_finds_the_node_under_it() {
        let p = positions(4, None);
        let area = Rect::new(0, 0, 29, 15);
        // The top node (0, 1) sits in the middle column, a little below the top border.
        let top = canvas_point(area, 14, 2).unwrap();
        assert_eq!(node_at(&p, top, 0.3), Some(0));
        assert_eq!(canvas_point(area, 0, 5), None, "the border");
        let middle = canvas_point(area, 14, 7).unwrap();
        assert_eq!(node_at(&p, middle, 0.3), None, "the empty middle");
    }

    #[test]
    fn labels_keep_the_number_of_long_names() {
        assert_eq!(short_label("source-12"), "12");
        assert_eq!(short_label("π3"), "π3");
        assert_eq!(short_label("cartpole"), "cartpole");
    }

    #[test]
    fn crossing_edges_print_their_weights_apart() {
        let (n, e, s, w) = ((0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0));
        let cell = (0.1, 0.2);
        let points = weight_label_points([(n, e), (n, s), (e, w)], cell, 4);
        assert_eq!(points[0], (0.5, 0.5));
        assert_eq!(points[1], (0.0, 0.0), "the first diagonal at its middle");
        assert_eq!(points[2], (0.0, 0.2), "the second a row above it");
    }

    #[test]
    fn names_whose_numbers_repeat_are_labelled_by_index() {
        let names = |list: &[&str]| list.iter().map(ToString::to_string).collect::<Vec<_>>();
        assert_eq!(labels(&names(&["source-0", "source-12"])), ["0", "12"]);
        // Table II's lesson: three names end in 100.
        assert_eq!(
            labels(&names(&["1×100", "2×100", "2×64-128", "3×50-150-100"])),
            ["π0", "π1", "π2", "π3"]
        );
    }
}
