//! The paper's figures: learning curves (Fig. 5 and 7) with a band over runs, and the
//! greedy test returns (Fig. 6 and 8).

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::axes::{self, Fit};
use super::legend::{self, Entry, Swatch};
use super::palette::{emphasised, method_pens, Pen, MANY};
use super::{Curve, Drawn, PlotData, FAMILY};
use crate::config::Budget;
use crate::report::sample_efficiency::{average_at, EfficiencyPoint};
use crate::seeds::{self, Part};
use crate::stats::{aggregate, bootstrap, Estimate, Scores};

/// Element-wise mean of series of different lengths: index `i` averages the series that
/// reach it (a stopped run is shorter).
pub fn mean_over_runs(series: &[Vec<f64>]) -> Vec<f64> {
    let longest = series.iter().map(Vec::len).max().unwrap_or(0);
    (0..longest)
        .map(|i| {
            let values: Vec<f64> = series.iter().filter_map(|s| s.get(i).copied()).collect();
            values.iter().sum::<f64>() / values.len() as f64
        })
        .collect()
}

/// Lines of at most this many points are drawn whole: every figure of a protocol or a
/// comparison of runs up to 65,536 episodes is drawn from every point.
pub const DRAWN_WHOLE: usize = 1 << 16;

/// A longer line is cut into this many spans of consecutive points, each drawn by its
/// first, lowest, highest and last point: a figure is about a thousand pixels wide, so a
/// span is under a pixel, and the line covers the same pixels (the same lowest and highest
/// values, the same ends) from at most 4 × 4,096 points instead of millions.
const SPANS: usize = 1 << 12;

/// The `count` points of a line, thinned as [`SPANS`] says when they are more than
/// [`DRAWN_WHOLE`]; else every one of them.
pub fn thinned(points: impl Iterator<Item = (f64, f64)>, count: usize) -> Vec<(f64, f64)> {
    if count <= DRAWN_WHOLE {
        return points.collect();
    }
    let span = count.div_ceil(SPANS);
    let mut kept = Vec::with_capacity(4 * SPANS);
    let mut points = points.peekable();
    while points.peek().is_some() {
        let mut indexed = points.by_ref().take(span).enumerate();
        let Some((_, first)) = indexed.next() else {
            break;
        };
        let (mut low, mut high, mut last) = ((0, first), (0, first), (0, first));
        for (i, p) in indexed {
            if p.1 < low.1 .1 {
                low = (i, p);
            }
            if p.1 > high.1 .1 {
                high = (i, p);
            }
            last = (i, p);
        }
        let mut span_points = [(0, first), low, high, last];
        span_points.sort_by_key(|&(i, _)| i);
        let mut previous = None;
        for (i, p) in span_points {
            if previous != Some(i) {
                kept.push(p);
                previous = Some(i);
            }
        }
    }
    kept
}

/// Resamples per interval of a figure's band or whiskers: many intervals drawn at once,
/// where 2,000 suffice (as the sample-efficiency curves').
const RESAMPLES: usize = 2_000;

/// Element-wise mean over runs with its 95% bootstrap interval (the runs resampled), over
/// the runs that reach each index; `label` seeds the resampling.
pub fn mean_intervals(label: &str, series: &[Vec<f64>]) -> Vec<Estimate> {
    let longest = series.iter().map(Vec::len).max().unwrap_or(0);
    (0..longest)
        .map(|i| {
            let values: Vec<f64> = series.iter().filter_map(|s| s.get(i).copied()).collect();
            let scores = Scores::one_task(values).expect("the longest series reaches i");
            let seed = seeds::derive(
                0,
                &[
                    Part::Name("figure"),
                    Part::Name(label),
                    Part::Index(i as u64),
                ],
            );
            bootstrap::interval_of(&scores, aggregate::mean, RESAMPLES, seed)
        })
        .collect()
}

/// A chart of returns over episodes or environment steps.
pub(super) type EpisodeChart<'a, DB> =
    ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The x axis of a curve under `data`'s budget, up to `last` (the last episode drawn, or
/// the step budget): its end and what it counts.
pub(super) fn x_axis(data: &PlotData, last: u64) -> (f64, String) {
    let w = data.window.max(1);
    match data.budget {
        Budget::Episodes(_) => (
            last as f64,
            format!("episode (the last of each window of {w})"),
        ),
        Budget::Steps(budget) => (
            budget.max(last) as f64,
            format!("environment step (a run's mean return of its last {w} episodes ended by it)"),
        ),
    }
}

/// The chart of a curve in `area`: x `(end, description)` from [`x_axis`], y fitted by
/// `fit`, labelled as every curve of these figures is.
pub(super) fn episode_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: String,
    y_desc: String,
    (end, x_desc): (f64, String),
    fit: &Fit,
) -> Result<EpisodeChart<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, 20))
        .margin(12)
        // Room for the last x label, which plotters centres on the axis's end.
        .margin_right(30)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0f64..end, fit.low..fit.high)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .label_style((FAMILY, 15))
        .draw()?;
    Ok(chart)
}

/// A translucent band of `pen`'s colour through the intervals `(x, estimate)`, clamped to
/// the chart's fit.
pub(super) fn band_polygon(
    intervals: impl Iterator<Item = (u64, Estimate)> + Clone,
    fit: &Fit,
    pen: Pen,
) -> Polygon<(f64, f64)> {
    let upper = intervals.clone().map(|(x, e)| (x as f64, fit.clamp(e.hi)));
    let lower: Vec<(f64, f64)> = intervals
        .map(|(x, e)| (x as f64, fit.clamp(e.lo)))
        .collect();
    let points = upper.chain(lower.into_iter().rev()).collect::<Vec<_>>();
    Polygon::new(points, pen.colour.mix(0.15).filled())
}

/// The methods' pens, in the order listed; of many methods, those not
/// [`emphasised`] by their mean training return faded.
pub(super) fn pens(curves: &[Curve]) -> Vec<Pen> {
    let kinds: Vec<_> = curves.iter().map(|c| c.kind).collect();
    let labels: Vec<String> = curves.iter().map(|c| c.label.clone()).collect();
    let scores: Vec<f64> = curves
        .iter()
        .map(|c| {
            let means: Vec<f64> = c
                .runs
                .iter()
                .filter(|r| !r.is_empty())
                .map(|r| r.returns.iter().sum::<f64>() / r.len() as f64)
                .collect();
            if means.is_empty() {
                f64::NEG_INFINITY
            } else {
                means.iter().sum::<f64>() / means.len() as f64
            }
        })
        .collect();
    method_pens(&kinds)
        .into_iter()
        .zip(emphasised(&kinds, &labels, &scores))
        .map(|(pen, full)| if full { pen } else { pen.faded() })
        .collect()
}

/// What the faint pens mean, for the legend, when there are any.
pub(super) fn emphasis_note(pens: &[Pen]) -> Option<String> {
    pens.iter().any(|p| p.faint).then(|| {
        format!(
            "of more than {MANY} methods, the paper's {} and the best of each family (mean \
             training return) in full; the others faint, without band",
            crate::reuse::Method::the_papers().label()
        )
    })
}

/// The methods' indices, the faint ones first: drawn in this order, no faint line lies
/// over a method drawn in full.
pub(super) fn in_drawing_order(pens: &[Pen]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..pens.len()).collect();
    order.sort_by_key(|&i| !pens[i].faint);
    order
}

/// The chart's area and the legend's column beside it, a little below the title.
pub(super) fn beside_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
) -> (DrawingArea<DB, Shift>, DrawingArea<DB, Shift>) {
    let width = root.dim_in_pixel().0;
    let (chart, legend) = root.split_horizontally(width.saturating_sub(legend::WIDTH));
    (chart, legend.margin(48, 0, 4, 0))
}

/// Fig. 5/7: moving average of `window` returns, averaged over runs, one line per method,
/// with the 95% bootstrap interval of that mean as a band (`efficiency`: the
/// sample-efficiency curves' points, one list per method, whose mean carries it). Under a
/// step budget the line is those points' mean too, on the step axis.
pub(super) fn learning_curve<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
    efficiency: &[Vec<EfficiencyPoint>],
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let w = data.window.max(1);
    // Per method: the mean over runs of each run's moving average, at each point.
    let lines: Vec<Vec<(f64, f64)>> = match data.budget {
        Budget::Episodes(_) => data
            .curves
            .iter()
            .map(|c| {
                // As mean_over_runs of each run's moving_average, one index at a time:
                // no average kept whole.
                let returns: Vec<&[f64]> = c.runs.iter().map(|r| r.returns.as_slice()).collect();
                let longest = returns
                    .iter()
                    .map(|r| (r.len() + 1).saturating_sub(w))
                    .max()
                    .unwrap_or(0);
                let mean = (0..longest).map(|i| {
                    let at = || returns.iter().filter_map(|r| average_at(r, i, w));
                    ((i + w) as f64, at().sum::<f64>() / at().count() as f64)
                });
                thinned(mean, longest)
            })
            .collect(),
        Budget::Steps(_) => efficiency
            .iter()
            .map(|points| points.iter().map(|p| (p.at as f64, p.mean.point)).collect())
            .collect(),
    };
    let last = lines
        .iter()
        .filter_map(|l| l.last().map(|&(x, _)| x as u64))
        .max()
        .unwrap_or(w as u64);
    let thinned_lines = match data.budget {
        Budget::Episodes(_) => data
            .curves
            .iter()
            .map(|c| {
                let longest = c.runs.iter().map(|r| (r.len() + 1).saturating_sub(w));
                longest.max().unwrap_or(0) > DRAWN_WHOLE
            })
            .collect(),
        Budget::Steps(_) => vec![false; lines.len()],
    };
    let banded = |i: usize| data.curves[i].runs.len() > 1;
    let fit = axes::fit(
        lines.iter().flatten().map(|&(_, y)| y).chain(
            efficiency
                .iter()
                .enumerate()
                .filter(|(i, _)| banded(*i))
                .flat_map(|(_, points)| points.iter().flat_map(|p| [p.mean.lo, p.mean.hi])),
        ),
        data.return_range,
    );
    let mut notes = vec![];
    let banded_runs: Vec<usize> = (0..data.curves.len())
        .filter(|&i| banded(i))
        .map(|i| data.curves[i].runs.len())
        .collect();
    if !banded_runs.is_empty() {
        notes.push(format!(
            "band: 95% bootstrap CI of the mean over {}",
            legend::runs_phrase(banded_runs.iter().copied())
        ));
    }
    if banded_runs.len() < data.curves.len() {
        notes.push("a method of 1 run has no band".into());
    }
    let bands = efficiency
        .iter()
        .enumerate()
        .map(|(i, points)| banded(i).then(|| points.iter().map(|p| (p.at, p.mean)).collect()))
        .collect();
    curves_chart(
        root,
        data,
        Curves {
            caption: format!(
                "{}: episode return, moving average of {w}, mean over runs",
                data.task
            ),
            y_desc: format!("episode return, MA{w}"),
            last,
            fit,
            lines,
            thinned: thinned_lines,
            bands,
            notes,
        },
    )
}

/// What a chart of curves over the budget's axis draws: one line per method of the data
/// and, where a method has one, its band.
pub(super) struct Curves {
    pub caption: String,
    pub y_desc: String,
    /// The last point of the axis drawn (the budget's end, under a step budget).
    pub last: u64,
    pub fit: Fit,
    pub lines: Vec<Vec<(f64, f64)>>,
    /// Whether each line was [`thinned`]: drawn segment by segment, so that the wide
    /// stroke's joins at its spans' sharp turns cannot spike out of the chart.
    pub thinned: Vec<bool>,
    /// Each method's band, `(x, interval)`; none for a method without one.
    pub bands: Vec<Option<Vec<(u64, Estimate)>>>,
    /// The legend's notes before the faint pens' and the fit's.
    pub notes: Vec<String>,
}

/// The frame the learning curve and the sample-efficiency curve share: the chart beside
/// its legend, each method's band (the faint ones without), the lines over every band
/// (the faint under the others), the legend of methods with their runs, and its notes.
pub(super) fn curves_chart<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
    curves: Curves,
) -> Drawn<DB> {
    let Curves {
        caption,
        y_desc,
        last,
        fit,
        lines,
        thinned,
        bands,
        mut notes,
    } = curves;
    let (area, legend_area) = beside_legend(&root);
    let mut chart = episode_chart(
        &area,
        legend::title(data.subject.as_deref(), &caption),
        y_desc,
        x_axis(data, last),
        &fit,
    )?;
    let pens = pens(&data.curves);
    for (band, pen) in bands.into_iter().zip(&pens) {
        if let Some(band) = band.filter(|_| !pen.faint) {
            chart.draw_series(std::iter::once(band_polygon(band.into_iter(), &fit, *pen)))?;
        }
    }
    for i in in_drawing_order(&pens) {
        if thinned[i] {
            legend::draw_segments(&mut chart, &lines[i], pens[i])?;
        } else {
            legend::draw_line(&mut chart, lines[i].clone(), pens[i])?;
        }
    }
    let entries: Vec<Entry> = data
        .curves
        .iter()
        .zip(&pens)
        .map(|(c, &pen)| Entry {
            label: legend::with_runs(&c.label, c.runs.len()),
            swatch: Swatch::Line(pen),
        })
        .collect();
    notes.extend(emphasis_note(&pens));
    notes.extend(fit.note().map(|n| format!("band {n}")));
    legend::draw(&legend_area, &entries, &notes)?;
    root.present()
}

/// Fig. 6/8: the return of each greedy test episode, averaged over runs, as bars grouped
/// by test and coloured by method, with the 95% bootstrap interval of that mean.
pub(super) fn test_bars<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let pens = pens(&data.curves);
    // (method, its pen, mean over runs of each test, its 95% interval).
    let tested: Vec<(&Curve, Pen, Vec<f64>, Vec<Estimate>)> = data
        .curves
        .iter()
        .zip(&pens)
        .filter(|(c, _)| !c.tests.is_empty())
        .map(|(c, &pen)| {
            (
                c,
                pen,
                mean_over_runs(&c.tests),
                mean_intervals(&c.label, &c.tests),
            )
        })
        .collect();
    let tests = tested
        .iter()
        .map(|(_, _, t, _)| t.len())
        .max()
        .unwrap_or(1)
        .max(1);
    // The bars grow up (or hang down) from 0; whiskers where there are runs to differ.
    let whiskered = |c: &Curve| c.tests.len() > 1;
    let fit = axes::fit(
        tested
            .iter()
            .flat_map(|(c, _, means, intervals)| {
                let intervals = if whiskered(c) {
                    intervals.as_slice()
                } else {
                    &[]
                };
                means
                    .iter()
                    .copied()
                    .chain(intervals.iter().flat_map(|e| [e.lo, e.hi]))
            })
            .chain([0.0]),
        data.return_range,
    );
    let (area, legend_area) = beside_legend(&root);
    let mut chart = ChartBuilder::on(&area)
        .caption(
            legend::title(
                data.subject.as_deref(),
                &format!("{}: greedy test episodes, mean over runs", data.task),
            ),
            (FAMILY, 20),
        )
        .margin(12)
        // Room for the last x label, which plotters centres on the axis's end.
        .margin_right(30)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.5f64..tests as f64 + 0.5, fit.low..fit.high)?;
    chart
        .configure_mesh()
        .x_desc("greedy test episode")
        .y_desc("episode return")
        .x_labels(tests)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .disable_x_mesh()
        .label_style((FAMILY, 15))
        .draw()?;
    let group = 0.8;
    let width = group / tested.len().max(1) as f64;
    for (k, (curve, pen, means, intervals)) in tested.iter().enumerate() {
        let left = |t: usize| t as f64 + 1.0 - group / 2.0 + k as f64 * width;
        chart.draw_series(
            means.iter().enumerate().flat_map(|(t, &v)| {
                legend::bar([(left(t), 0.0), (left(t) + width * 0.9, v)], *pen)
            }),
        )?;
        if whiskered(curve) {
            chart.draw_series(means.iter().zip(intervals).enumerate().map(|(t, (&m, e))| {
                let x = left(t) + width * 0.45;
                ErrorBar::new_vertical(x, fit.clamp(e.lo), m, fit.clamp(e.hi), BLACK, 6)
            }))?;
        }
    }
    let entries: Vec<Entry> = tested
        .iter()
        .map(|(c, pen, _, _)| Entry {
            label: legend::with_runs(&c.label, c.tests.len()),
            swatch: Swatch::Bar(*pen),
        })
        .collect();
    let mut notes = vec![];
    let whiskered_runs: Vec<usize> = tested
        .iter()
        .filter(|(c, ..)| whiskered(c))
        .map(|(c, ..)| c.tests.len())
        .collect();
    if !whiskered_runs.is_empty() {
        notes.push(format!(
            "whiskers: 95% bootstrap CI of the mean over {}",
            legend::runs_phrase(whiskered_runs)
        ));
    }
    notes.extend(emphasis_note(&pens));
    notes.extend(fit.note().map(|n| format!("whiskers {n}")));
    legend::draw(&legend_area, &entries, &notes)?;
    root.present()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_line_is_thinned_to_its_spans_lows_highs_and_ends() {
        let short: Vec<(f64, f64)> = (0..DRAWN_WHOLE)
            .map(|i| (i as f64, (i % 7) as f64))
            .collect();
        assert_eq!(thinned(short.iter().copied(), short.len()), short);
        let count = 3 * DRAWN_WHOLE + 5;
        let long = (0..count).map(|i| (i as f64, ((i * 7919) % 1000) as f64 - 500.0));
        let kept = thinned(long.clone(), count);
        assert!(kept.len() <= 4 * SPANS, "{}", kept.len());
        assert_eq!(kept.first(), long.clone().next().as_ref());
        assert_eq!(kept.last(), long.clone().next_back().as_ref());
        assert!(
            kept.windows(2).all(|w| w[0].0 < w[1].0),
            "in order, none twice"
        );
        let extent = |points: &[(f64, f64)]| {
            points
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p.1), hi.max(p.1))
                })
        };
        assert_eq!(extent(&kept), extent(&long.collect::<Vec<_>>()));
    }

    #[test]
    fn means_cover_the_runs_that_reach_each_index() {
        assert_eq!(
            mean_over_runs(&[vec![1.0, 2.0, 3.0], vec![3.0, 4.0]]),
            vec![2.0, 3.0, 3.0]
        );
        assert!(mean_over_runs(&[]).is_empty());
    }

    /// `tests.svg` drawn from two SAP-Net runs whose tests differ widely (mean 250, its
    /// interval from one run to the other: CartPole's whole 0..500) and one DQN run.
    #[test]
    fn the_test_bars_say_what_their_whiskers_are_and_where_they_stop() {
        let data = PlotData {
            task: "CartPole-v1".into(),
            subject: None,
            return_range: Some((0.0, 500.0)),
            window: 10,
            budget: Budget::Episodes(10),
            curves: vec![
                Curve {
                    label: "sapnet".into(),
                    kind: crate::reuse::sapnet::KIND,
                    runs: vec![],
                    tests: vec![vec![0.0, 10.0], vec![500.0, 20.0]],
                },
                Curve {
                    label: "dqn[100]".into(),
                    kind: crate::reuse::from_scratch::KIND,
                    runs: vec![],
                    tests: vec![vec![9.0, 10.0]],
                },
            ],
            policy_names: vec![],
            activations: vec![],
            acted: vec![],
        };
        super::super::register_font().unwrap();
        let mut svg = String::new();
        test_bars(
            SVGBackend::with_string(&mut svg, (1300, 600)).into_drawing_area(),
            &data,
        )
        .unwrap();
        for text in [
            "sapnet (2 runs)",
            "dqn[100] (1 run)",
            "whiskers: 95% bootstrap CI of the",
            "episode return",
        ] {
            assert!(svg.contains(text), "tests.svg lacks {text:?}");
        }
    }

    /// Two runs resample to (a, a), (a, b) or (b, b): the mean's interval runs from one run
    /// to the other; one run has none wider than itself.
    #[test]
    fn mean_intervals_cover_the_runs_that_reach_each_index() {
        let intervals = mean_intervals("m", &[vec![0.0, 5.0], vec![500.0]]);
        assert_eq!(intervals.len(), 2);
        assert_eq!(
            (intervals[0].point, intervals[0].lo, intervals[0].hi),
            (250.0, 0.0, 500.0)
        );
        assert_eq!(
            (intervals[1].point, intervals[1].lo, intervals[1].hi),
            (5.0, 5.0, 5.0)
        );
    }
}
