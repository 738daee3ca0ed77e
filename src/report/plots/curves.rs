//! The paper's figures: learning curves (Fig. 5 and 7) with a band over runs, and the
//! greedy test returns (Fig. 6 and 8).

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{method_colour, value_range, Curve, Drawn, PlotData, FAMILY};
use crate::report::runs::moving_average;

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

/// Element-wise standard deviation over the runs that reach each index (0 where only one
/// does).
pub fn std_over_runs(series: &[Vec<f64>]) -> Vec<f64> {
    let means = mean_over_runs(series);
    means
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let values: Vec<f64> = series.iter().filter_map(|s| s.get(i).copied()).collect();
            if values.len() < 2 {
                return 0.0;
            }
            let ss: f64 = values.iter().map(|v| (v - m).powi(2)).sum();
            (ss / (values.len() - 1) as f64).sqrt()
        })
        .collect()
}

/// Fig. 5/7: moving average of `window` returns, averaged over runs, one line per method.
pub(super) fn learning_curve<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let w = data.window.max(1);
    let lines: Vec<(usize, &Curve, Vec<f64>)> = data
        .curves
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let averaged: Vec<Vec<f64>> = c.returns.iter().map(|r| moving_average(r, w)).collect();
            (i, c, mean_over_runs(&averaged))
        })
        .collect();
    let episodes = lines
        .iter()
        .map(|(_, _, l)| l.len() + w - 1)
        .max()
        .unwrap_or(w);
    let (low, high) = value_range(lines.iter().flat_map(|(_, _, l)| l.iter().copied()));
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: moving average of {w} episodes, mean of runs",
                data.task
            ),
            (FAMILY, 22),
        )
        .margin(12)
        // Room for the last x label, which plotters centres on the axis's end.
        .margin_right(30)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0f64..episodes as f64, low..high)?;
    chart
        .configure_mesh()
        .x_desc("episode")
        .y_desc("reward")
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .label_style((FAMILY, 15))
        .draw()?;
    for (i, curve, line) in &lines {
        let colour = method_colour(&data.curves, *i);
        let runs = curve.returns.len();
        if runs > 1 {
            let averaged: Vec<Vec<f64>> =
                curve.returns.iter().map(|r| moving_average(r, w)).collect();
            let spread = std_over_runs(&averaged);
            let upper = line.iter().zip(&spread).enumerate();
            let lower = line.iter().zip(&spread).enumerate().rev();
            let band: Vec<(f64, f64)> = upper
                .map(|(e, (m, s))| ((e + w) as f64, (m + s).min(high)))
                .chain(lower.map(|(e, (m, s))| ((e + w) as f64, (m - s).max(low))))
                .collect();
            chart.draw_series(std::iter::once(Polygon::new(
                band,
                colour.mix(0.12).filled(),
            )))?;
        }
        chart
            .draw_series(LineSeries::new(
                line.iter().enumerate().map(|(e, &v)| ((e + w) as f64, v)),
                colour.stroke_width(2),
            ))?
            .label(format!(
                "{} ({runs} run{})",
                curve.label,
                if runs == 1 { "" } else { "s" }
            ))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FAMILY, 15))
        .draw()?;
    root.present()
}

/// Fig. 6/8: the return of each greedy test episode, averaged over runs, as bars grouped
/// by test and coloured by method, with ± one standard deviation over runs.
pub(super) fn test_bars<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let tested: Vec<(usize, &Curve, Vec<f64>)> = data
        .curves
        .iter()
        .enumerate()
        .filter(|(_, c)| !c.tests.is_empty())
        .map(|(i, c)| (i, c, mean_over_runs(&c.tests)))
        .collect();
    let tests = tested
        .iter()
        .map(|(_, _, t)| t.len())
        .max()
        .unwrap_or(1)
        .max(1);
    let (low, high) = value_range(
        tested
            .iter()
            .flat_map(|(_, _, t)| t.iter().copied())
            .chain([0.0]),
    );
    // Headroom for the legend above the bars, which grow up (or hang down) from 0: about a
    // twentieth of the height per method, and some.
    let high = high + (high - low) * (0.08 + 0.06 * tested.len() as f64);
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{}: greedy test episodes, mean of runs", data.task),
            (FAMILY, 22),
        )
        .margin(12)
        // Room for the last x label, which plotters centres on the axis's end.
        .margin_right(30)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.5f64..tests as f64 + 0.5, low..high)?;
    chart
        .configure_mesh()
        .x_desc("test")
        .y_desc("reward")
        .x_labels(tests)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .disable_x_mesh()
        .label_style((FAMILY, 15))
        .draw()?;
    let group = 0.8;
    let width = group / tested.len().max(1) as f64;
    for (k, (i, curve, means)) in tested.iter().enumerate() {
        let colour = method_colour(&data.curves, *i);
        let left = |t: usize| t as f64 + 1.0 - group / 2.0 + k as f64 * width;
        chart
            .draw_series(means.iter().enumerate().map(|(t, &v)| {
                Rectangle::new(
                    [(left(t), 0.0), (left(t) + width * 0.9, v)],
                    colour.filled(),
                )
            }))?
            .label(curve.label.clone())
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 14, y + 6)], colour.filled()));
        // ± one standard deviation over runs, where there are runs to differ.
        if curve.tests.len() > 1 {
            let spread = std_over_runs(&curve.tests);
            chart.draw_series(means.iter().zip(&spread).enumerate().map(|(t, (&m, &sd))| {
                let x = left(t) + width * 0.45;
                ErrorBar::new_vertical(x, (m - sd).max(low), m, (m + sd).min(high), BLACK, 6)
            }))?;
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FAMILY, 15))
        .draw()?;
    root.present()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn means_cover_the_runs_that_reach_each_index() {
        assert_eq!(
            mean_over_runs(&[vec![1.0, 2.0, 3.0], vec![3.0, 4.0]]),
            vec![2.0, 3.0, 3.0]
        );
        assert!(mean_over_runs(&[]).is_empty());
    }

    #[test]
    fn spreads_are_sample_deviations_over_the_runs_that_reach_each_index() {
        // Index 0: 1 and 3 → mean 2, (1 + 1)/1 → 1.4142; index 1: one run → 0.
        let spread = std_over_runs(&[vec![1.0, 5.0], vec![3.0]]);
        assert!((spread[0] - 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(spread[1], 0.0);
    }
}
