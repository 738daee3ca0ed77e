//! Where the SAP-Net graph's nodes sit on its canvas, and which node a key or a click
//! lands on: geometry shared by the views that draw the graph and the state that moves the
//! cursor over it.

use std::f64::consts::{FRAC_PI_2, TAU};

use ratatui::layout::Rect;

/// The canvas's extent: the unit circle of nodes with room for their labels.
pub const X_BOUNDS: [f64; 2] = [-1.35, 1.35];
pub const Y_BOUNDS: [f64; 2] = [-1.3, 1.3];

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
}
