//! The pictures researchers read since Agarwal et al. (NeurIPS 2021), in `rliable`'s
//! style, written together: `intervals.png`, each aggregate of each method as a bar from
//! the low to the high end of its 95% interval with the point marked (drawn here);
//! `profiles.png` ([`super::profiles`]); `improvement.png` ([`super::improvement`]). Each
//! also as `.svg`.

use std::path::Path;

use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::comparison_style::{pens, runs, title};
use super::legend;
use super::{atomically, axes, png, register_font, Drawn, FAMILY};
use crate::report::{Aggregates, Report, Units};
use crate::stats::{bootstrap, Estimate};

/// Writes `intervals`, `profiles` and `improvement` (`.png` and `.svg`) into `dir`.
pub fn write_intervals(dir: &Path, report: &Report) -> Result<()> {
    register_font()?;
    let methods = report.comparison.len().max(1) as u32;
    let panels = (1400, 2 * (40 + 26 * methods) + 80);
    let square = (1000 + legend::WIDTH, 650);
    let improvement = super::improvement::size(report.comparison.len());
    macro_rules! both {
        ($name:literal, $size:expr, $draw:expr) => {
            atomically(&dir.join(concat!($name, ".png")), |path| {
                $draw(png(path, $size), report).map_err(|e| e.to_string())
            })?;
            atomically(&dir.join(concat!($name, ".svg")), |path| {
                $draw(SVGBackend::new(path, $size).into_drawing_area(), report)
                    .map_err(|e| e.to_string())
            })?;
        };
    }
    both!("intervals", panels, aggregates);
    both!("profiles", square, super::profiles::profiles);
    both!(
        "improvement",
        improvement,
        super::improvement::probabilities
    );
    Ok(())
}

/// What the scores are measured in, for titles.
fn units(report: &Report) -> &'static str {
    match report.units {
        Units::Returns => "return",
        Units::Normalised => "normalised score",
    }
}

fn colours(report: &Report) -> Vec<RGBColor> {
    pens(report).iter().map(|p| p.colour).collect()
}

/// Two rows of panels (the test score, the training return), one column per aggregate:
/// a method's bar spans its 95% interval, the tick marks the point.
fn aggregates<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, report: &Report) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let (heading, body) = root.split_vertically(50);
    heading.titled(
        &title(
            report,
            &format!(
                "95% stratified bootstrap intervals ({} resamples) over {} per method",
                bootstrap::RESAMPLES,
                runs(report)
            ),
        ),
        (FAMILY, 22),
    )?;
    let rows = body.split_evenly((2, 4));
    let colours = colours(report);
    let names: Vec<String> = report.comparison.iter().map(|m| m.method.clone()).collect();
    type Pick = fn(&Aggregates) -> Estimate;
    let columns: [(&str, Pick); 4] = [
        ("median", |a| a.median),
        ("IQM", |a| a.iqm),
        ("mean", |a| a.mean),
        ("optimality gap (normalised)", |a| a.optimality_gap),
    ];
    let test_score = report.test_score.long();
    for (r, (score, pick_score)) in [
        (
            test_score.as_str(),
            (|m| m.test) as fn(&crate::report::MethodComparison) -> Option<Aggregates>,
        ),
        ("training return", |m| m.training),
    ]
    .into_iter()
    .enumerate()
    {
        for (c, (aggregate, pick)) in columns.iter().enumerate() {
            let area = &rows[r * 4 + c];
            let estimates: Vec<Option<Estimate>> = report
                .comparison
                .iter()
                .map(|m| pick_score(m).map(|a| pick(&a)))
                .collect();
            let unit = if c == 3 { "" } else { units(report) };
            let caption = format!("{score}: {aggregate}");
            interval_panel(area, &caption, unit, &names, &estimates, &colours, c == 0)?;
        }
    }
    root.present()
}

/// One panel: a horizontal bar per method from lo to hi, a tick at the point.
fn interval_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    unit: &str,
    names: &[String],
    estimates: &[Option<Estimate>],
    colours: &[RGBColor],
    with_names: bool,
) -> Drawn<DB> {
    let (low, high) = axes::value_range(
        estimates
            .iter()
            .flatten()
            .flat_map(|e| [e.lo, e.hi, e.point]),
    );
    let n = names.len().max(1);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FAMILY, 16))
        .margin(8)
        // Room for the last x label ("1.00"), which plotters centres on the axis's end.
        .margin_right(24)
        .x_label_area_size(36)
        .y_label_area_size(if with_names { 150 } else { 10 })
        .build_cartesian_2d(low..high, -0.5f64..n as f64 - 0.5)?;
    let names_shown = names.to_vec();
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(if with_names { n } else { 0 })
        .y_label_formatter(&move |y| {
            let i = y.round();
            if (y - i).abs() < 1e-6 && i >= 0.0 {
                names_shown
                    .get(n - 1 - i as usize)
                    .cloned()
                    .unwrap_or_default()
            } else {
                String::new()
            }
        })
        .x_desc(unit)
        .x_labels(5)
        .x_label_formatter(&|x| {
            if (high - low) >= 10.0 {
                format!("{x:.0}")
            } else {
                format!("{x:.2}")
            }
        })
        .label_style((FAMILY, 13))
        .draw()?;
    for (i, e) in estimates.iter().enumerate() {
        let Some(e) = e else { continue };
        // The first method at the top.
        let y = (n - 1 - i) as f64;
        let colour = colours[i];
        chart.draw_series(std::iter::once(Rectangle::new(
            [(e.lo, y - 0.32), (e.hi.max(e.lo), y + 0.32)],
            colour.mix(0.8).filled(),
        )))?;
        chart.draw_series(std::iter::once(PathElement::new(
            [(e.point, y - 0.4), (e.point, y + 0.4)],
            BLACK.stroke_width(2),
        )))?;
    }
    Ok(())
}
