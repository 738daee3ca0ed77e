//! `profiles.png`: performance profiles of the normalised test score (the share of runs
//! above τ, with its 95% band), as rliable draws them, over the τ where they change.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::comparison_style::{pens, runs, title};
use super::curves::{emphasis_note, in_drawing_order};
use super::legend::{self, Entry, Swatch};
use super::palette::{emphasised, Pen};
use super::{Drawn, FAMILY};
use crate::report::Report;
use crate::stats::{bootstrap, profile, Estimate};

/// The τ worth drawing: from the last level where every band still holds every run (share
/// 1 at its low end) to the first where every band holds none (0 at its high end), with
/// 5% room, within [0, 1]. Profiles of scores that end at 0.55 end there, not at 1.
pub(super) fn tau_range(levels: &[f64], profiles: &[&[Estimate]]) -> (f64, f64) {
    let (Some(&first), Some(&last)) = (levels.first(), levels.last()) else {
        return (0.0, 1.0);
    };
    let all_above = |i: usize| {
        profiles
            .iter()
            .all(|p| p.get(i).is_none_or(|e| e.lo >= 1.0))
    };
    let none_above = |i: usize| {
        profiles
            .iter()
            .all(|p| p.get(i).is_none_or(|e| e.hi <= 0.0))
    };
    let start = (0..levels.len())
        .take_while(|&i| all_above(i))
        .last()
        .map_or(first, |i| levels[i]);
    let end = (0..levels.len())
        .find(|&i| none_above(i))
        .map_or(last, |i| levels[i]);
    if end <= start {
        return (first, last);
    }
    let room = (end - start) * 0.05;
    ((start - room).max(first), (end + room).min(last))
}

/// The profiles of `report`, the legend beside. Every band is drawn before any line, so
/// that no line lies under another method's band.
pub(super) fn profiles<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    report: &Report,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let levels = profile::levels();
    let pens = faded(report);
    // Each profile with its method's index in the comparison.
    let drawn: Vec<(usize, &[Estimate])> = report
        .profiles
        .iter()
        .filter_map(|p| {
            let i = report
                .comparison
                .iter()
                .position(|m| m.method == p.method)?;
            Some((i, p.shares.as_slice()))
        })
        .collect();
    let shares: Vec<&[Estimate]> = drawn.iter().map(|(_, s)| *s).collect();
    let (low, high) = tau_range(&levels, &shares);
    let width = root.dim_in_pixel().0;
    let (area, legend_area) = root.split_horizontally(width.saturating_sub(legend::WIDTH));
    let mut chart = ChartBuilder::on(&area)
        .caption(
            title(
                report,
                &format!("performance profiles of the {}", report.test_score.long()),
            ),
            (FAMILY, 20),
        )
        .margin(12)
        .margin_right(30)
        .x_label_area_size(55)
        .y_label_area_size(60)
        .build_cartesian_2d(low..high, 0f64..1.02f64)?;
    chart
        .configure_mesh()
        .x_desc(format!(
            "normalised {} τ: (return − lowest) / (highest − lowest) of the task",
            report.test_score.short()
        ))
        .y_desc("share of runs with score > τ")
        .x_label_formatter(&|x| format!("{x:.2}"))
        .y_label_formatter(&|y| format!("{y:.1}"))
        .light_line_style(WHITE)
        .label_style((FAMILY, 15))
        .draw()?;
    let inside = |t: f64| (low - 1e-9..=high + 1e-9).contains(&t);
    for &(i, shares) in drawn.iter().filter(|(i, _)| !pens[*i].faint) {
        let on = || levels.iter().zip(shares).filter(|(&t, _)| inside(t));
        let band: Vec<(f64, f64)> = on()
            .map(|(&t, e)| (t, e.hi))
            .chain(
                on().collect::<Vec<_>>()
                    .into_iter()
                    .rev()
                    .map(|(&t, e)| (t, e.lo)),
            )
            .collect();
        chart.draw_series(std::iter::once(Polygon::new(
            band,
            pens[i].colour.mix(0.08).filled(),
        )))?;
    }
    // Faint lines first, under the others; the legend in the comparison's order.
    let drawn_pens: Vec<Pen> = drawn.iter().map(|(i, _)| pens[*i]).collect();
    for k in in_drawing_order(&drawn_pens) {
        let (i, shares) = drawn[k];
        let points = levels
            .iter()
            .zip(shares)
            .filter(|(&t, _)| inside(t))
            .map(|(&t, e)| (t, e.point))
            .collect();
        legend::draw_line(&mut chart, points, pens[i])?;
    }
    let mut entries = Vec::new();
    for &(i, _) in &drawn {
        entries.push(Entry {
            label: legend::with_runs(&report.comparison[i].method, report.comparison[i].runs),
            swatch: Swatch::Line(pens[i]),
        });
    }
    let mut notes = vec![format!(
        "band: 95% stratified bootstrap CI ({} resamples) over {}",
        bootstrap::RESAMPLES,
        runs(report)
    )];
    notes.extend(emphasis_note(&drawn_pens));
    if (low, high) != (0.0, 1.0) {
        notes.push(format!(
            "τ shown from {low:.2} to {high:.2}: every profile is 1 below and 0 above"
        ));
    }
    legend::draw(&legend_area.margin(48, 0, 4, 0), &entries, &notes)?;
    root.present()
}

/// The methods' pens as the learning curves give them: of many, those not
/// [`emphasised`] by their mean training return faded.
fn faded(report: &Report) -> Vec<Pen> {
    let kinds: Vec<_> = report.comparison.iter().map(|m| m.kind).collect();
    let labels: Vec<String> = report.comparison.iter().map(|m| m.method.clone()).collect();
    let scores: Vec<f64> = report
        .comparison
        .iter()
        .map(|m| m.training.map_or(f64::NEG_INFINITY, |a| a.mean.point))
        .collect();
    pens(report)
        .into_iter()
        .zip(emphasised(&kinds, &labels, &scores))
        .map(|(pen, full)| if full { pen } else { pen.faded() })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(at: usize, levels: usize) -> Vec<Estimate> {
        (0..levels)
            .map(|i| {
                let v = if i < at { 1.0 } else { 0.0 };
                Estimate {
                    point: v,
                    lo: v,
                    hi: v,
                }
            })
            .collect()
    }

    #[test]
    fn the_tau_axis_ends_where_the_last_profile_reaches_zero() {
        let levels = profile::levels();
        // One method's runs all score 0.30, another's 0.55: every share is 1 up to τ =
        // 0.29 and 0 from τ = 0.55; 5% room of 0.26 = 0.013 each side.
        let a = step(30, levels.len());
        let b = step(55, levels.len());
        let (low, high) = tau_range(&levels, &[&a, &b]);
        assert!((low - (0.29 - 0.013)).abs() < 1e-9, "{low}");
        assert!((high - (0.55 + 0.013)).abs() < 1e-9, "{high}");
    }

    #[test]
    fn a_band_keeps_its_tau_in_view() {
        let levels = profile::levels();
        // The point is 0 from τ = 0.30 but the band's high end stays above 0 to 0.70.
        let mut wide = step(30, levels.len());
        for e in &mut wide[30..70] {
            e.hi = 0.5;
        }
        let (_, high) = tau_range(&levels, &[&wide]);
        assert!(high > 0.70, "{high}");
    }

    #[test]
    fn profiles_that_never_settle_span_the_whole_axis() {
        let levels = profile::levels();
        let half: Vec<Estimate> = levels
            .iter()
            .map(|_| Estimate {
                point: 0.5,
                lo: 0.0,
                hi: 1.0,
            })
            .collect();
        assert_eq!(tau_range(&levels, &[&half]), (0.0, 1.0));
        assert_eq!(tau_range(&levels, &[]), (0.0, 1.0));
    }
}
