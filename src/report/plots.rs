//! The paper's figures, drawn with plotters: learning curves (Fig. 5 and 7) with a band of
//! ± one standard deviation over runs, greedy test returns (Fig. 6 and 8), the activation
//! of every source policy over the episodes, and, per method that reuses the library, the
//! share of the steps each source acted (`selections.png`).

use std::path::Path;
use std::sync::Once;

use anyhow::{anyhow, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::runs::moving_average;

/// DejaVu Sans (licence in `assets/fonts/`): plotters' `ab_glyph` backend needs a font and
/// a headless machine may have none.
static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
const FAMILY: &str = "sans-serif";
const SIZE: (u32, u32) = (1000, 600);

/// One method's results.
#[derive(Debug, Clone)]
pub struct Curve {
    pub label: String,
    /// SAP-Net's curves get the paper's red.
    pub sapnet: bool,
    /// Training returns of each run.
    pub returns: Vec<Vec<f64>>,
    /// Greedy test returns of each tested run.
    pub tests: Vec<Vec<f64>>,
}

/// What the plots show.
#[derive(Debug, Clone)]
pub struct PlotData {
    pub task: String,
    pub window: usize,
    /// In the protocol's order; SAP-Net first if it ran.
    pub curves: Vec<Curve>,
    pub policy_names: Vec<String>,
    /// SAP-Net (the first SAP-Net method listed): activations at the end of each episode
    /// (run → episode → policy).
    pub activations: Vec<Vec<Vec<f64>>>,
    /// Per method that reuses the library: the steps each source acted in each episode
    /// (run → episode → policy).
    pub acted: Vec<(String, Vec<Vec<Vec<u64>>>)>,
}

/// What a reusing run's selector did, episode by episode.
#[derive(Debug, Clone, Default)]
pub struct SelectionHistory {
    /// Its scores at the end of each episode (SAP-Net: the activations).
    pub scores: Vec<Vec<f64>>,
    /// Steps each source acted in each episode.
    pub acted: Vec<Vec<u64>>,
}

/// Writes `learning_curve.png`, `learning_curve.svg`, `tests.png` and, with SAP-Net
/// activations, `activations.png` into `dir`.
pub fn write_all(dir: &Path, data: &PlotData) -> Result<()> {
    register_font()?;
    let png = dir.join("learning_curve.png");
    learning_curve(BitMapBackend::new(&png, SIZE).into_drawing_area(), data)
        .map_err(|e| anyhow!("{}: {e}", png.display()))?;
    let svg = dir.join("learning_curve.svg");
    learning_curve(SVGBackend::new(&svg, SIZE).into_drawing_area(), data)
        .map_err(|e| anyhow!("{}: {e}", svg.display()))?;
    let tests = dir.join("tests.png");
    test_bars(BitMapBackend::new(&tests, SIZE).into_drawing_area(), data)
        .map_err(|e| anyhow!("{}: {e}", tests.display()))?;
    if !data.activations.is_empty() {
        let path = dir.join("activations.png");
        activation_lines(BitMapBackend::new(&path, SIZE).into_drawing_area(), data)
            .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    }
    if !data.acted.is_empty() {
        let path = dir.join("selections.png");
        let height = 220 * data.acted.len() as u32 + 60;
        selection_shares(
            BitMapBackend::new(&path, (SIZE.0, height)).into_drawing_area(),
            data,
        )
        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    }
    Ok(())
}

fn register_font() -> Result<()> {
    static REGISTER: Once = Once::new();
    let mut result = Ok(());
    REGISTER.call_once(|| {
        result = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT)
            .map_err(|_| anyhow!("the embedded plot font is not a valid TrueType font"));
    });
    result
}

/// SAP-Net in the paper's red (its variants in other reds and pinks), then the paper's blue,
/// orange and green for the other methods in the order they are listed.
fn method_colour(curves: &[Curve], i: usize) -> RGBColor {
    const SAPNETS: [RGBColor; 5] = [
        RGBColor(214, 39, 40),
        RGBColor(255, 152, 150),
        RGBColor(140, 20, 25),
        RGBColor(227, 119, 194),
        RGBColor(247, 182, 210),
    ];
    // tab10 without its red and pink, which are SAP-Net's.
    const OTHERS: [usize; 8] = [0, 1, 2, 4, 5, 7, 9, 8];
    let same_kind = curves[..i]
        .iter()
        .filter(|c| c.sapnet == curves[i].sapnet)
        .count();
    if curves[i].sapnet {
        SAPNETS[same_kind % SAPNETS.len()]
    } else {
        SOURCE_COLOURS[OTHERS[same_kind % OTHERS.len()]]
    }
}

/// Matplotlib's `tab10`: ten colours told apart at a glance (plotters' `Palette99` puts
/// near-identical ones next to each other).
const SOURCE_COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

fn source_colour(p: usize) -> RGBColor {
    SOURCE_COLOURS[p % SOURCE_COLOURS.len()]
}

/// Marker `shape` (any number: four shapes in turn) at `at` pixels from its anchor.
fn marker<DB: DrawingBackend>(
    shape: usize,
    at: (i32, i32),
    colour: RGBColor,
) -> DynElement<'static, DB, (i32, i32)> {
    match shape % 4 {
        0 => Circle::new(at, 4, colour.filled()).into_dyn(),
        1 => TriangleMarker::new(at, 6, colour.filled()).into_dyn(),
        2 => Cross::new(at, 5, colour.stroke_width(2)).into_dyn(),
        _ => Circle::new(at, 4, colour.stroke_width(2)).into_dyn(),
    }
}

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

type Drawn<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Fig. 5/7: moving average of `window` returns, averaged over runs, one line per method.
fn learning_curve<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, data: &PlotData) -> Drawn<DB> {
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
fn test_bars<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, data: &PlotData) -> Drawn<DB> {
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

/// The activation of each source policy at the end of every episode, averaged over runs.
fn activation_lines<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let policies = data.policy_names.len();
    let per_policy: Vec<Vec<f64>> = (0..policies)
        .map(|p| {
            let runs: Vec<Vec<f64>> = data
                .activations
                .iter()
                .map(|run| run.iter().map(|a| a[p]).collect())
                .collect();
            mean_over_runs(&runs)
        })
        .collect();
    let episodes = per_policy.iter().map(Vec::len).max().unwrap_or(1).max(1);
    let (_, high) = value_range(per_policy.iter().flatten().copied().chain([0.0]));
    let runs = data.activations.len();
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: activation of each source policy, mean of {runs} run{}",
                data.task,
                if runs == 1 { "" } else { "s" }
            ),
            (FAMILY, 22),
        )
        .margin(12)
        // Room for the last x label, which plotters centres on the axis's end.
        .margin_right(30)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(1f64..episodes as f64, 0f64..high)?;
    chart
        .configure_mesh()
        .x_desc("episode")
        .y_desc("activation A")
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| {
            if high >= 10.0 {
                format!("{y:.0}")
            } else {
                format!("{y:.2}")
            }
        })
        .label_style((FAMILY, 15))
        .draw()?;
    // Curves that coincide (two sources that never act keep the same activation) must
    // still each be seen: ten colours far apart, and a marker shape of its own every tenth
    // of the episodes, shifted per source so that the markers of equal curves sit side by
    // side instead of on top of each other.
    let every = (episodes / 10).max(1);
    for (p, line) in per_policy.iter().enumerate() {
        let colour = source_colour(p);
        let shape = p / SOURCE_COLOURS.len() + p;
        chart
            .draw_series(LineSeries::new(
                line.iter().enumerate().map(|(e, &a)| ((e + 1) as f64, a)),
                colour.stroke_width(2),
            ))?
            .label(data.policy_names[p].clone())
            .legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new([(0, 0), (20, 0)], colour.stroke_width(2))
                    + marker(shape, (10, 0), colour)
            });
        let offset = p * every / policies.max(1);
        let points: Vec<(f64, f64)> = line
            .iter()
            .enumerate()
            .skip(offset)
            .step_by(every)
            .map(|(e, &a)| ((e + 1) as f64, a))
            .collect();
        chart.draw_series(
            points
                .into_iter()
                .map(|point| EmptyElement::at(point) + marker(shape, (0, 0), colour)),
        )?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FAMILY, 14))
        .draw()?;
    root.present()
}

/// For each reusing method, a panel of stacked shares: the fraction of each episode's
/// acting steps taken by each source, mean over runs (episodes spent in the warm-up left
/// out).
fn selection_shares<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    data: &PlotData,
) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let root = root.titled(
        &format!(
            "{}: share of the acting steps taken by each source, mean of runs",
            data.task
        ),
        (FAMILY, 20),
    )?;
    let panels = root.split_evenly((data.acted.len(), 1));
    let policies = data.policy_names.len();
    for (panel, (label, runs)) in panels.iter().zip(&data.acted) {
        // run → episode → share per policy.
        let shares: Vec<Vec<Vec<f64>>> = runs
            .iter()
            .map(|run| {
                run.iter()
                    .filter(|acted| acted.iter().sum::<u64>() > 0)
                    .map(|acted| {
                        let total = acted.iter().sum::<u64>() as f64;
                        acted.iter().map(|&a| a as f64 / total).collect()
                    })
                    .collect()
            })
            .collect();
        let per_policy: Vec<Vec<f64>> = (0..policies)
            .map(|p| {
                let series: Vec<Vec<f64>> = shares
                    .iter()
                    .map(|run| run.iter().map(|s| s[p]).collect())
                    .collect();
                mean_over_runs(&series)
            })
            .collect();
        let episodes = per_policy.iter().map(Vec::len).max().unwrap_or(1).max(2);
        let mut chart = ChartBuilder::on(panel)
            .caption(label.as_str(), (FAMILY, 16))
            .margin(8)
            .margin_right(140)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(1f64..episodes as f64, 0f64..1f64)?;
        chart
            .configure_mesh()
            .x_desc("episode after the warm-up")
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.1}"))
            .label_style((FAMILY, 12))
            .draw()?;
        // Stacked from the top: each area reaches the cumulative share up to its policy.
        for p in (0..policies).rev() {
            let colour = source_colour(p);
            let top: Vec<(f64, f64)> = (0..episodes)
                .map(|e| {
                    let stacked: f64 = per_policy[..=p]
                        .iter()
                        .map(|l| l.get(e).copied().unwrap_or(0.0))
                        .sum();
                    ((e + 1) as f64, stacked.min(1.0))
                })
                .collect();
            chart
                .draw_series(AreaSeries::new(top, 0.0, colour.filled()))?
                .label(data.policy_names[p].clone())
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 12, y + 5)], colour.filled())
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .margin(4)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font((FAMILY, 11))
            .draw()?;
    }
    root.present()
}

/// A y range with a little room around the values (and some height when they are all
/// equal or there are none).
fn value_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (low, high) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
    if !low.is_finite() {
        return (0.0, 1.0);
    }
    let pad = ((high - low) * 0.05)
        .max(1e-9)
        .max(if high == low { 1.0 } else { 0.0 });
    (low - pad, high + pad)
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

    #[test]
    fn ranges_have_room() {
        assert_eq!(value_range([].into_iter()), (0.0, 1.0));
        assert_eq!(value_range([5.0].into_iter()), (4.0, 6.0));
        let (l, h) = value_range([0.0, 100.0].into_iter());
        assert!(l < 0.0 && h > 100.0);
    }

    #[test]
    fn every_plot_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let data = PlotData {
            task: "CartPole-v1".into(),
            window: 2,
            curves: vec![
                Curve {
                    label: "sapnet".into(),
                    sapnet: true,
                    returns: vec![vec![10.0, 20.0, 30.0], vec![12.0, 18.0]],
                    tests: vec![vec![100.0, 90.0], vec![80.0, 95.0]],
                },
                Curve {
                    label: "dqn[100]".into(),
                    sapnet: false,
                    returns: vec![vec![9.0, 11.0, 10.0]],
                    tests: vec![vec![9.0, 10.0]],
                },
            ],
            policy_names: vec!["source-0".into(), "source-1".into()],
            activations: vec![vec![vec![0.0, 1.0], vec![1.5, 1.0]]],
            acted: vec![(
                "sapnet".into(),
                vec![vec![vec![0, 0], vec![3, 1], vec![0, 4]]],
            )],
        };
        write_all(dir.path(), &data).unwrap();
        for file in [
            "learning_curve.png",
            "learning_curve.svg",
            "tests.png",
            "activations.png",
            "selections.png",
        ] {
            let bytes = std::fs::read(dir.path().join(file)).unwrap();
            assert!(bytes.len() > 1000, "{file} is {} bytes", bytes.len());
        }
        let svg = std::fs::read_to_string(dir.path().join("learning_curve.svg")).unwrap();
        assert!(svg.contains("sapnet (2 runs)") && svg.contains("dqn[100] (1 run)"));
    }
}
