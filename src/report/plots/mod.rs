//! The paper's figures, drawn with plotters: learning curves (Fig. 5 and 7) with a band of
//! ± one standard deviation over runs, greedy test returns (Fig. 6 and 8), the activation
//! of every source policy over the episodes, and, per method that reuses the library, the
//! share of the steps each source acted (`selections.png`).

mod curves;
mod intervals;
mod library;

use std::path::Path;
use std::sync::Once;

use anyhow::{anyhow, Result};
use plotters::prelude::*;

/// DejaVu Sans (licence in `assets/fonts/`): plotters' `ab_glyph` backend needs a font and
/// a headless machine may have none.
static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");
pub(super) const FAMILY: &str = "sans-serif";
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
    atomically(&dir.join("learning_curve.png"), |path| {
        curves::learning_curve(BitMapBackend::new(path, SIZE).into_drawing_area(), data)
            .map_err(|e| e.to_string())
    })?;
    atomically(&dir.join("learning_curve.svg"), |path| {
        curves::learning_curve(SVGBackend::new(path, SIZE).into_drawing_area(), data)
            .map_err(|e| e.to_string())
    })?;
    atomically(&dir.join("tests.png"), |path| {
        curves::test_bars(BitMapBackend::new(path, SIZE).into_drawing_area(), data)
            .map_err(|e| e.to_string())
    })?;
    if !data.activations.is_empty() {
        atomically(&dir.join("activations.png"), |path| {
            library::activation_lines(BitMapBackend::new(path, SIZE).into_drawing_area(), data)
                .map_err(|e| e.to_string())
        })?;
    }
    if !data.acted.is_empty() {
        let height = 220 * data.acted.len() as u32 + 60;
        atomically(&dir.join("selections.png"), |path| {
            library::selection_shares(
                BitMapBackend::new(path, (SIZE.0, height)).into_drawing_area(),
                data,
            )
            .map_err(|e| e.to_string())
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

pub(super) fn register_font() -> Result<()> {
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
pub(super) fn method_colour(curves: &[Curve], i: usize) -> RGBColor {
    let sapnet: Vec<bool> = curves.iter().map(|c| c.sapnet).collect();
    colour_of(&sapnet, i)
}

/// The colour of method `i` among methods of which `sapnet` says which are SAP-Net's.
pub(super) fn colour_of(sapnet: &[bool], i: usize) -> RGBColor {
    const SAPNETS: [RGBColor; 5] = [
        RGBColor(214, 39, 40),
        RGBColor(255, 152, 150),
        RGBColor(140, 20, 25),
        RGBColor(227, 119, 194),
        RGBColor(247, 182, 210),
    ];
    // tab10 without its red and pink, which are SAP-Net's.
    const OTHERS: [usize; 8] = [0, 1, 2, 4, 5, 7, 9, 8];
    let same_kind = sapnet[..i].iter().filter(|&&s| s == sapnet[i]).count();
    if sapnet[i] {
        SAPNETS[same_kind % SAPNETS.len()]
    } else {
        SOURCE_COLOURS[OTHERS[same_kind % OTHERS.len()]]
    }
}

/// Matplotlib's `tab10`: ten colours told apart at a glance (plotters' `Palette99` puts
/// near-identical ones next to each other).
pub(super) const SOURCE_COLOURS: [RGBColor; 10] = [
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

pub(super) fn source_colour(p: usize) -> RGBColor {
    SOURCE_COLOURS[p % SOURCE_COLOURS.len()]
}

/// Marker `shape` (any number: four shapes in turn) at `at` pixels from its anchor.
pub(super) fn marker<DB: DrawingBackend>(
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

pub use curves::{mean_over_runs, std_over_runs};
pub use intervals::write_intervals;

pub(super) type Drawn<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A y range with a little room around the values (and some height when they are all
/// equal or there are none).
pub(super) fn value_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
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
