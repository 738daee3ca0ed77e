//! `improvement.png`: for every pair of methods, the probability that a run of the row's
//! method X scores above a run of the column's method Y, `P(X > Y)`, as a matrix per
//! score (the greedy test score, the training return), each cell marked with what the
//! separation rule ([`crate::stats::separation`]) says of the pair.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::comparison_style::{runs, title};
use super::{Drawn, FAMILY};
use crate::report::{Improvement, Report};
use crate::stats::separation::Verdict;
use crate::stats::Estimate;

/// One score's matrix: `cells[x][y]` is `P(method x > method y)` and the pair's verdict,
/// None on the diagonal.
#[derive(Debug)]
pub(super) struct Matrix {
    pub methods: Vec<String>,
    pub cells: Vec<Vec<Option<(Estimate, Verdict)>>>,
}

/// The matrix of `score` (`test` or `return`) from `rows` (`improvement.csv`'s): the
/// methods in `order` (the comparison's) that have rows for it.
pub(super) fn matrix(order: &[String], rows: &[Improvement], score: &str) -> Matrix {
    let rows: Vec<&Improvement> = rows.iter().filter(|r| r.score == score).collect();
    let methods: Vec<String> = order
        .iter()
        .filter(|m| rows.iter().any(|r| &r.method == *m || &r.over == *m))
        .cloned()
        .collect();
    let cells = methods
        .iter()
        .map(|x| {
            methods
                .iter()
                .map(|y| {
                    rows.iter()
                        .find(|r| &r.method == x && &r.over == y)
                        .map(|r| (r.p, r.verdict))
                })
                .collect()
        })
        .collect();
    Matrix { methods, cells }
}

/// The side of a cell, in pixels.
const CELL: u32 = 64;
/// The rows' names, left of the matrix.
const ROW_NAMES: u32 = 170;
/// The columns' names, written upwards above the matrix.
const COLUMN_NAMES: u32 = 150;
/// The title's and the notes' heights.
const HEADING: u32 = 50;
const NOTES: u32 = 60;

/// The figure's size for `methods` methods: two matrices side by side.
pub(super) fn size(methods: usize) -> (u32, u32) {
    let n = methods.max(1) as u32;
    let panel = ROW_NAMES + n * CELL + 30;
    (
        (2 * panel).max(1000),
        HEADING + 30 + COLUMN_NAMES + n * CELL + NOTES,
    )
}

/// A cell's colour: white at ½, blue as X wins more often, red as it loses more often
/// (ColorBrewer's RdBu ends).
fn shade(p: f64) -> RGBColor {
    let (end, t) = if p >= 0.5 {
        ((33.0, 102.0, 172.0), (p - 0.5) * 2.0)
    } else {
        ((178.0, 24.0, 43.0), (0.5 - p) * 2.0)
    };
    let t = t.clamp(0.0, 1.0) * 0.85;
    let mix = |e: f64| (255.0 + (e - 255.0) * t).round() as u8;
    RGBColor(mix(end.0), mix(end.1), mix(end.2))
}

/// How a verdict is marked after the probability.
fn mark(verdict: Verdict) -> &'static str {
    match verdict {
        Verdict::Separated => " **",
        Verdict::Fragile => " *",
        Verdict::NotSeparated => "",
    }
}

/// Both matrices, the test score's left, the training return's right.
pub(super) fn probabilities<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    report: &Report,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let (heading, body) = root.split_vertically(HEADING);
    heading.titled(
        &title(
            report,
            &format!(
                "P(a run of the row's method X beats a run of the column's Y) over {}",
                runs(report)
            ),
        ),
        (FAMILY, 20),
    )?;
    let height = body.dim_in_pixel().1;
    let (body, notes) = body.split_vertically(height.saturating_sub(NOTES));
    let panels = body.split_evenly((1, 2));
    let order: Vec<String> = report.comparison.iter().map(|m| m.method.clone()).collect();
    let test_score = report.test_score.long();
    for (panel, (score, caption)) in panels
        .iter()
        .zip([("test", test_score.as_str()), ("return", "training return")])
    {
        draw_matrix(panel, caption, &matrix(&order, &report.improvement, score))?;
    }
    let small = (FAMILY, 14).into_font().color(&BLACK.mix(0.8));
    for (k, line) in [
        "cell: the point estimate of P(X > Y), its 95% stratified bootstrap interval below; \
         blue where X wins more often, red where it loses more often",
        "** separated: every bootstrap seed's interval excludes ½ and the rank test agrees \
         after Holm's correction;  * fragile: they disagree;  unmarked: not separated",
    ]
    .iter()
    .enumerate()
    {
        notes.draw(&Text::new(
            line.to_string(),
            (20, 8 + 22 * k as i32),
            small.clone(),
        ))?;
    }
    root.present()
}

/// One matrix in `area`: the caption, the columns' names upwards, the rows' names, cells.
fn draw_matrix<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    matrix: &Matrix,
) -> Drawn<DB> {
    let n = matrix.methods.len();
    area.draw(&Text::new(
        caption.to_string(),
        (ROW_NAMES as i32, 4),
        (FAMILY, 17).into_font(),
    ))?;
    if n == 0 {
        return Ok(());
    }
    let left = ROW_NAMES as i32;
    let top = 30 + COLUMN_NAMES as i32;
    let cell = CELL as i32;
    let names = (FAMILY, 13).into_font();
    let upwards = names
        .clone()
        .transform(FontTransform::Rotate270)
        .color(&BLACK);
    // plotters' layout sets a line's baseline 0.1 em below the anchor's centre, so that
    // digits stand 0.27 em above it: text centred in a cell is moved down by that much.
    let centred = |size: f64| (0.27 * size) as i32;
    for (i, name) in matrix.methods.iter().enumerate() {
        let middle = i as i32 * cell + cell / 2;
        area.draw(&Text::new(
            name.clone(),
            (left - 8, top + middle + centred(13.0)),
            names
                .clone()
                .color(&BLACK)
                .pos(Pos::new(HPos::Right, VPos::Center)),
        ))?;
        area.draw(&Text::new(
            name.clone(),
            (left + middle - 8, top - 8),
            upwards.clone(),
        ))?;
    }
    let number = (FAMILY, 14).into_font();
    let interval = (FAMILY, 11).into_font();
    for (x, row) in matrix.cells.iter().enumerate() {
        for (y, cell_value) in row.iter().enumerate() {
            let corner = (left + y as i32 * cell, top + x as i32 * cell);
            let far = (corner.0 + cell, corner.1 + cell);
            let Some((p, verdict)) = cell_value else {
                area.draw(&Rectangle::new([corner, far], BLACK.mix(0.08).filled()))?;
                continue;
            };
            area.draw(&Rectangle::new([corner, far], shade(p.point).filled()))?;
            let ink = if (p.point - 0.5).abs() > 0.3 {
                WHITE
            } else {
                BLACK
            };
            let centre = corner.0 + cell / 2;
            area.draw(&Text::new(
                format!("{:.2}{}", p.point, mark(*verdict)),
                (centre, corner.1 + cell / 2 - 8 + centred(14.0)),
                number
                    .clone()
                    .color(&ink)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
            ))?;
            area.draw(&Text::new(
                format!("{:.2}–{:.2}", p.lo, p.hi),
                (centre, corner.1 + cell / 2 + 12 + centred(11.0)),
                interval
                    .clone()
                    .color(&ink)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
            ))?;
            if *verdict == Verdict::Separated {
                area.draw(&Rectangle::new(
                    [(corner.0 + 1, corner.1 + 1), (far.0 - 1, far.1 - 1)],
                    BLACK.stroke_width(2),
                ))?;
            }
        }
    }
    // The grid over the cells.
    for k in 0..=n as i32 {
        let style = WHITE.stroke_width(1);
        area.draw(&PathElement::new(
            [
                (left, top + k * cell),
                (left + n as i32 * cell, top + k * cell),
            ],
            style,
        ))?;
        area.draw(&PathElement::new(
            [
                (left + k * cell, top),
                (left + k * cell, top + n as i32 * cell),
            ],
            style,
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(score: &'static str, x: &str, y: &str, p: f64, verdict: Verdict) -> Improvement {
        Improvement {
            score,
            method: x.into(),
            over: y.into(),
            p: Estimate {
                point: p,
                lo: p,
                hi: p,
            },
            rank_p: 1.0,
            holm_p: 1.0,
            seeds_excluding: 0,
            verdict,
            runs_needed: None,
            per_task: vec![],
        }
    }

    /// Three methods with test scores, one (`c`) without: the test matrix is 2 × 2 in
    /// the comparison's order, every ordered pair in its cell, the diagonal empty; the
    /// return matrix covers all three.
    #[test]
    fn the_matrix_covers_every_ordered_pair() {
        let order: Vec<String> = ["b", "a", "c"].map(String::from).to_vec();
        let mut rows = vec![
            row("test", "a", "b", 0.8, Verdict::Separated),
            row("test", "b", "a", 0.2, Verdict::Separated),
        ];
        for (x, y) in [("a", "b"), ("a", "c"), ("b", "c")] {
            rows.push(row("return", x, y, 0.6, Verdict::Fragile));
            rows.push(row("return", y, x, 0.4, Verdict::Fragile));
        }
        let test = matrix(&order, &rows, "test");
        assert_eq!(test.methods, ["b", "a"]);
        assert_eq!(test.cells[0][1].unwrap().0.point, 0.2);
        assert_eq!(test.cells[1][0].unwrap().0.point, 0.8);
        assert_eq!(test.cells[1][0].unwrap().1, Verdict::Separated);
        let returns = matrix(&order, &rows, "return");
        assert_eq!(returns.methods, ["b", "a", "c"]);
        for x in 0..3 {
            for y in 0..3 {
                assert_eq!(returns.cells[x][y].is_some(), x != y, "({x}, {y})");
            }
        }
        // P(X > Y) and P(Y > X) in mirrored cells sum to 1.
        let (xy, yx) = (
            returns.cells[0][2].unwrap().0,
            returns.cells[2][0].unwrap().0,
        );
        assert!((xy.point + yx.point - 1.0).abs() < 1e-12);
    }

    #[test]
    fn shades_run_from_red_through_white_to_blue() {
        assert_eq!(shade(0.5), RGBColor(255, 255, 255));
        let (win, loss) = (shade(1.0), shade(0.0));
        assert!(win.2 > win.0 && loss.0 > loss.2, "{win:?} {loss:?}");
    }

    #[test]
    fn the_figure_grows_with_the_methods() {
        assert_eq!(size(2).0, 1000);
        let (w, h) = size(11);
        assert_eq!(w, 2 * (ROW_NAMES + 11 * CELL + 30));
        assert!(h > 11 * CELL + COLUMN_NAMES);
    }
}
