//! The paper's figures, drawn with plotters: learning curves (Fig. 5 and 7) with the 95%
//! bootstrap interval of the mean over runs as a band, how fast each method learns
//! (`sample_efficiency.png`, the IQM's interval), greedy test returns (Fig. 6 and 8), the
//! activation of every source policy over the episodes per method that spreads
//! (`activations.png`), and, per run of each method that reuses the library, the share of
//! the steps each source acted (`selections.png`). Every plot's y axis fits what
//! it draws within the task's return range (`axes`), its legend sits beside the chart and
//! says what the band or whiskers are over how many runs (`legend`), and its colours come
//! from one palette (`palette`).

mod activations;
mod axes;
mod comparison_style;
mod curves;
mod efficiency;
mod improvement;
mod intervals;
mod legend;
pub mod palette;
mod profiles;
mod selections;
mod sweep;
mod text;

use std::path::Path;
use std::sync::Once;

use anyhow::{anyhow, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::runs::TrainingEpisodes;
use super::sample_efficiency::{self, EfficiencyPoint};
use crate::config::Budget;
use crate::reuse::MethodKind;

/// DejaVu Sans (licence in `assets/fonts/`): plotters' `ab_glyph` backend needs a font and
/// a headless machine may have none.
static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");
pub(super) const FAMILY: &str = "sans-serif";
const SIZE: (u32, u32) = (1000, 600);
/// A chart of SIZE with the legend's column beside it.
const WITH_LEGEND: (u32, u32) = (SIZE.0 + legend::WIDTH, SIZE.1);

/// One method's results.
#[derive(Debug, Clone)]
pub struct Curve {
    pub label: String,
    /// Its kind picks its colour family (SAP-Net's the paper's red).
    pub kind: MethodKind,
    /// Training episodes of each run.
    pub runs: Vec<TrainingEpisodes>,
    /// Greedy test returns of each tested run.
    pub tests: Vec<Vec<f64>>,
}

/// What the plots show.
#[derive(Debug, Clone)]
pub struct PlotData {
    pub task: String,
    /// What the plots are about beyond the task, first in their titles: a sweep's axis
    /// value ("sapnet.temperature = 1.0").
    pub subject: Option<String>,
    /// The lowest and highest return an episode of the task can have, if known: the
    /// y axes stop there.
    pub return_range: Option<(f64, f64)>,
    pub window: usize,
    /// The protocol's budget: its curves are drawn on its axis (episodes or environment
    /// steps, up to the budget).
    pub budget: Budget,
    /// In the protocol's order; SAP-Net first if it ran.
    pub curves: Vec<Curve>,
    pub policy_names: Vec<String>,
    /// Per method that spreads activation (SAP-Net and its variants): the activations at
    /// the end of each episode (run → episode → policy).
    pub activations: Vec<(String, Vec<Vec<Vec<f64>>>)>,
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
    /// The probability of picking each source next, at the end of each episode (empty in
    /// a file without the `P_` columns).
    pub probabilities: Vec<Vec<f64>>,
    /// Each row's episode (1-based).
    pub episodes: Vec<u32>,
}

/// Writes `learning_curve.png`, `learning_curve.svg`, `sample_efficiency.csv`, `.png` and
/// `.svg`, `tests.png` and, with SAP-Net activations, `activations.png` (a panel per
/// method that spreads), with methods that reuse the library `selections.png` (a strip per
/// run), into `dir`.
pub fn write_all(dir: &Path, data: &PlotData) -> Result<()> {
    register_font()?;
    let efficiency: Vec<Vec<EfficiencyPoint>> = data
        .curves
        .iter()
        .map(|c| sample_efficiency::curve(&c.label, &c.runs, data.window, data.budget))
        .collect();
    let labelled: Vec<(String, Vec<EfficiencyPoint>)> = data
        .curves
        .iter()
        .map(|c| c.label.clone())
        .zip(efficiency.iter().cloned())
        .collect();
    let (header, rows) = sample_efficiency::records(&labelled, data.budget.unit());
    super::write_rows(&dir.join("sample_efficiency.csv"), &header, &rows)?;
    atomically(&dir.join("sample_efficiency.png"), |path| {
        efficiency::sample_efficiency(png(path, WITH_LEGEND), data, &efficiency)
            .map_err(|e| e.to_string())
    })?;
    atomically(&dir.join("sample_efficiency.svg"), |path| {
        efficiency::sample_efficiency(
            SVGBackend::new(path, WITH_LEGEND).into_drawing_area(),
            data,
            &efficiency,
        )
        .map_err(|e| e.to_string())
    })?;
    atomically(&dir.join("learning_curve.png"), |path| {
        curves::learning_curve(png(path, WITH_LEGEND), data, &efficiency).map_err(|e| e.to_string())
    })?;
    atomically(&dir.join("learning_curve.svg"), |path| {
        curves::learning_curve(
            SVGBackend::new(path, WITH_LEGEND).into_drawing_area(),
            data,
            &efficiency,
        )
        .map_err(|e| e.to_string())
    })?;
    // Runs of other tools (`sapnet compare`) have no greedy tests: no empty figure.
    if data.curves.iter().any(|c| !c.tests.is_empty()) {
        atomically(&dir.join("tests.png"), |path| {
            curves::test_bars(png(path, WITH_LEGEND), data).map_err(|e| e.to_string())
        })?;
    }
    if !data.activations.is_empty() {
        atomically(&dir.join("activations.png"), |path| {
            let size = activations::size(data.activations.len());
            activations::activation_panels(png(path, size), data).map_err(|e| e.to_string())
        })?;
    }
    if !data.acted.is_empty() {
        let size = (
            SIZE.0 + activations::SOURCES_LEGEND,
            selections::height(&data.acted),
        );
        atomically(&dir.join("selections.png"), |path| {
            selections::selection_strips(png(path, size), data).map_err(|e| e.to_string())
        })?;
    }
    Ok(())
}

/// Draws `path` by `draw`ing into a hidden sibling renamed over it: a kill or a full disk
/// leaves the old plot or none, never a truncated one. (The backends open the file
/// themselves: whatever a folder holds at the sibling's name, a planted link included, is
/// removed first.)
pub(super) fn atomically(
    path: &Path,
    draw: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<()> {
    let tmp = crate::safe_io::sibling(path, "tmp");
    let result = (|| {
        if std::fs::symlink_metadata(&tmp).is_ok() {
            std::fs::remove_file(&tmp).map_err(|e| e.to_string())?;
        }
        draw(&tmp)?;
        std::fs::rename(&tmp, path).map_err(|e| e.to_string())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(|e| anyhow!("{}: {e}", path.display()))
}

/// A PNG of `size` pixels at `path`, its text set on the baseline ([`text`]).
fn png(path: &Path, size: (u32, u32)) -> DrawingArea<text::Typeset<BitMapBackend<'_>>, Shift> {
    DrawingArea::from(text::Typeset(BitMapBackend::new(path, size)))
}

pub(super) fn register_font() -> Result<()> {
    static REGISTER: Once = Once::new();
    let mut result = Ok(());
    REGISTER.call_once(|| {
        result = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT)
            .map_err(|_| anyhow!("the embedded plot font is not a valid TrueType font"));
    });
    result
}

pub use axes::return_bounds;
pub use curves::mean_over_runs;
pub use intervals::write_intervals;
pub use legend::task_title;
pub use sweep::{write_sweep, SweepAxis};

pub(super) type Drawn<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_plot_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let data = PlotData {
            task: "CartPole-v1".into(),
            subject: Some("sapnet.temperature = 1.0".into()),
            return_range: Some((0.0, 500.0)),
            window: 2,
            budget: Budget::Episodes(3),
            curves: vec![
                Curve {
                    label: "sapnet".into(),
                    kind: crate::reuse::sapnet::KIND,
                    runs: vec![
                        TrainingEpisodes::uniform(&[10.0, 20.0, 30.0], 10),
                        TrainingEpisodes::uniform(&[12.0, 18.0], 10),
                    ],
                    tests: vec![vec![100.0, 90.0], vec![80.0, 95.0]],
                },
                Curve {
                    label: "dqn[100]".into(),
                    kind: crate::reuse::from_scratch::KIND,
                    runs: vec![TrainingEpisodes::uniform(&[9.0, 11.0, 10.0], 10)],
                    tests: vec![vec![9.0, 10.0]],
                },
            ],
            policy_names: vec!["source-0".into(), "source-1".into()],
            activations: vec![("sapnet".into(), vec![vec![vec![0.0, 1.0], vec![1.5, 1.0]]])],
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
        // What the band is, over the runs counted from the data (SAP-Net's two; DQN's one
        // run has none), the axis value in the title, the y label what it is.
        for text in [
            "band: 95% bootstrap CI of the mean",
            "over 2 runs",
            "a method of 1 run has no band",
            "sapnet.temperature = 1.0 · CartPole-v1",
            "episode return, MA2",
        ] {
            assert!(svg.contains(text), "learning_curve.svg lacks {text:?}");
        }
    }
}
