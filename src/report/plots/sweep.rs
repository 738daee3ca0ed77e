//! `sweep.png` (and `.svg`) in a sweep's `merged/`: each method's IQM of the greedy test
//! score and of the training return against each value of each axis, with its 95%
//! stratified bootstrap interval: a row of two panels per axis, the values in the
//! sweep's order, evenly spaced (values need not be numbers: lists of methods, tasks).

use std::path::Path;

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::legend::{self, Entry, Swatch};
use super::palette::{method_pens, Pen};
use super::{atomically, png, register_font, Drawn, FAMILY};
use crate::report::{Aggregates, MethodComparison, Units};
use crate::reuse::MethodKind;
use crate::stats::Estimate;

/// One axis of a sweep: its values in order, the comparison of the methods at each.
#[derive(Debug, Clone)]
pub struct SweepAxis {
    pub axis: String,
    pub values: Vec<String>,
    /// Per value, the methods compared there and what their scores are in.
    pub comparisons: Vec<(Vec<MethodComparison>, Units)>,
}

/// A method's IQM at every value of an axis (None where it did not run or has no such
/// score).
#[derive(Debug, PartialEq)]
pub(super) struct Series {
    pub method: String,
    pub kind: MethodKind,
    pub points: Vec<Option<Estimate>>,
}

/// The series of `axis` for the score `pick` chooses, the methods in the order first met.
pub(super) fn series(
    axis: &SweepAxis,
    pick: fn(&MethodComparison) -> Option<Aggregates>,
) -> Vec<Series> {
    let mut methods: Vec<(String, MethodKind)> = Vec::new();
    for (comparison, _) in &axis.comparisons {
        for m in comparison {
            if !methods.iter().any(|(label, _)| *label == m.method) {
                methods.push((m.method.clone(), m.kind));
            }
        }
    }
    methods
        .into_iter()
        .map(|(method, kind)| {
            let points = axis
                .comparisons
                .iter()
                .map(|(comparison, _)| {
                    let m = comparison.iter().find(|m| m.method == method)?;
                    pick(m).map(|a| a.iqm)
                })
                .collect();
            Series {
                method,
                kind,
                points,
            }
        })
        .collect()
}

/// A method's points sit side by side around each value, `0.5` of a value's width apart
/// in all: the offset of method `k` of `n`.
pub(super) fn dodge(k: usize, n: usize) -> f64 {
    if n <= 1 {
        return 0.0;
    }
    -0.25 + 0.5 * k as f64 / (n - 1) as f64
}

/// Writes `sweep.png` and `sweep.svg` into `dir`: the sweep on `tasks` (as titles name
/// them, [`super::task_title`]).
pub fn write_sweep(dir: &Path, tasks: &[String], axes: &[SweepAxis]) -> Result<()> {
    register_font()?;
    let size = (1100 + legend::WIDTH, 60 + 360 * axes.len().max(1) as u32);
    let title = format!(
        "{}: IQM over the runs of every cell with each axis value, 95% stratified bootstrap CI",
        tasks.join(", ")
    );
    atomically(&dir.join("sweep.png"), |path| {
        draw(png(path, size), &title, axes).map_err(|e| e.to_string())
    })?;
    atomically(&dir.join("sweep.svg"), |path| {
        draw(
            SVGBackend::new(path, size).into_drawing_area(),
            &title,
            axes,
        )
        .map_err(|e| e.to_string())
    })
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    axes: &[SweepAxis],
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let root = root.titled(title, (FAMILY, 20))?;
    let width = root.dim_in_pixel().0;
    let (area, legend_area) = root.split_horizontally(width.saturating_sub(legend::WIDTH));
    // One pen per method across the whole figure, in the order first met.
    let mut methods: Vec<(String, MethodKind)> = Vec::new();
    for axis in axes {
        for s in series(axis, |m| m.training.or(m.test)) {
            if !methods.iter().any(|(l, _)| *l == s.method) {
                methods.push((s.method, s.kind));
            }
        }
    }
    let pens = method_pens(&methods.iter().map(|(_, k)| *k).collect::<Vec<_>>());
    let pen_of = |label: &str| {
        methods
            .iter()
            .position(|(l, _)| l == label)
            .map(|i| (i, pens[i]))
    };
    let rows = area.split_evenly((axes.len().max(1), 2));
    for (a, axis) in axes.iter().enumerate() {
        for (c, (score, pick)) in [
            (
                "greedy test score",
                (|m| m.test) as fn(&MethodComparison) -> Option<Aggregates>,
            ),
            ("training return", |m| m.training),
        ]
        .into_iter()
        .enumerate()
        {
            let units = match axis.comparisons.first().map(|(_, u)| *u) {
                Some(Units::Normalised) => "normalised",
                _ => "return",
            };
            panel(
                &rows[a * 2 + c],
                &format!("{score} against {}", axis.axis),
                &format!("{score} ({units}), IQM"),
                axis,
                &series(axis, pick),
                (&pen_of, methods.len()),
            )?;
        }
    }
    let entries: Vec<Entry> = methods
        .iter()
        .zip(&pens)
        .map(|((label, _), &pen)| Entry {
            label: label.clone(),
            swatch: Swatch::Line(pen),
        })
        .collect();
    let notes = vec![
        "point: the IQM over the runs of every cell with that value; whiskers: its 95% \
         stratified bootstrap CI"
            .to_string(),
    ];
    legend::draw(&legend_area.margin(48, 0, 4, 0), &entries, &notes)?;
    root.present()
}

type PenOf<'a> = dyn Fn(&str) -> Option<(usize, Pen)> + 'a;

/// One axis's panel of one score: each method's IQM and interval at each value, joined.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    y_desc: &str,
    axis: &SweepAxis,
    series: &[Series],
    (pen_of, methods): (&PenOf<'_>, usize),
) -> Drawn<DB> {
    let (low, high) = super::axes::value_range(
        series
            .iter()
            .flat_map(|s| s.points.iter().flatten())
            .flat_map(|e| [e.lo, e.hi]),
    );
    let n = axis.values.len().max(1);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, 16))
        .margin(10)
        .margin_right(20)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(-0.5f64..n as f64 - 0.5, low..high)?;
    let values = axis.values.clone();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n)
        .x_label_formatter(&move |x| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 {
                values.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .y_label_formatter(&|y| {
            if high - low >= 10.0 {
                format!("{y:.0}")
            } else {
                format!("{y:.2}")
            }
        })
        .y_desc(y_desc)
        .label_style((FAMILY, 13))
        .draw()?;
    for s in series {
        let Some((k, pen)) = pen_of(&s.method) else {
            continue;
        };
        let at = |v: usize| v as f64 + dodge(k, methods);
        let points: Vec<(f64, f64)> = s
            .points
            .iter()
            .enumerate()
            .filter_map(|(v, e)| e.map(|e| (at(v), e.point)))
            .collect();
        legend::draw_line(&mut chart, points.clone(), Pen { faint: true, ..pen })?;
        chart.draw_series(s.points.iter().enumerate().filter_map(|(v, e)| {
            e.map(|e| {
                ErrorBar::new_vertical(at(v), e.lo, e.point, e.hi, pen.colour.stroke_width(2), 8)
            })
        }))?;
        chart.draw_series(
            points
                .iter()
                .map(|&p| Circle::new(p, 4, pen.colour.filled())),
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn aggregates(iqm: f64) -> Aggregates {
        let e = Estimate {
            point: iqm,
            lo: iqm - 1.0,
            hi: iqm + 1.0,
        };
        Aggregates {
            mean: e,
            median: e,
            iqm: e,
            optimality_gap: e,
        }
    }

    fn method(label: &str, training: f64) -> MethodComparison {
        MethodComparison {
            method: label.into(),
            kind: crate::reuse::sapnet::KIND,
            runs: 2,
            tested: "source",
            unit: "episode",
            thresholds: vec![],
            training: Some(aggregates(training)),
            final_score: None,
            env_steps: None,
            updates_per_step: None,
            non_greedy_share: None,
            test: None,
            test_std: None,
            source_shares: vec![],
            task_shares: vec![],
            ranks: vec![],
            lock_in_median: None,
            locked_runs: 0,
            lock_in_measured: false,
        }
    }

    /// A method missing at one value has no point there; the methods come in the order
    /// first met; a score no method has leaves every point empty.
    #[test]
    fn each_method_has_a_point_per_value_where_it_ran() {
        let axis = SweepAxis {
            axis: "sapnet.temperature".into(),
            values: vec!["0.5".into(), "1.0".into()],
            comparisons: vec![
                (vec![method("sapnet", 10.0)], Units::Returns),
                (
                    vec![method("dqn", 5.0), method("sapnet", 20.0)],
                    Units::Returns,
                ),
            ],
        };
        let training = series(&axis, |m| m.training);
        assert_eq!(training.len(), 2);
        assert_eq!(training[0].method, "sapnet");
        let points: Vec<Option<f64>> = training[0]
            .points
            .iter()
            .map(|e| e.map(|e| e.point))
            .collect();
        assert_eq!(points, [Some(10.0), Some(20.0)]);
        assert_eq!(training[1].points[0], None);
        assert!(series(&axis, |m| m.test)
            .iter()
            .all(|s| s.points.iter().all(Option::is_none)));
    }

    #[test]
    fn methods_sit_side_by_side_around_a_value() {
        assert_eq!(dodge(0, 1), 0.0);
        assert_eq!((dodge(0, 3), dodge(1, 3), dodge(2, 3)), (-0.25, 0.0, 0.25));
    }

    #[test]
    fn the_figure_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let axis = SweepAxis {
            axis: "sapnet.temperature".into(),
            values: vec!["0.5".into(), "4.0".into()],
            comparisons: vec![
                (vec![method("sapnet", 10.0)], Units::Returns),
                (vec![method("sapnet", 20.0)], Units::Returns),
            ],
        };
        write_sweep(dir.path(), &["CartPole-v1".into()], &[axis]).unwrap();
        for file in ["sweep.png", "sweep.svg"] {
            let bytes = std::fs::read(dir.path().join(file)).unwrap();
            assert!(bytes.len() > 1000, "{file}");
        }
        let svg = std::fs::read_to_string(dir.path().join("sweep.svg")).unwrap();
        assert!(svg.contains("training return against sapnet.temperature"));
        assert!(svg.contains("CartPole-v1: IQM over the runs"));
    }
}
