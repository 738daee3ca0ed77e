//! Every colour the plots use. Methods come in families, one hue each (SAP-Net and its
//! variants red, the random selectors blue, UCB1 green, PRQ-learning purple, the best
//! source orange); the members of a family differ in lightness and, on lines, in dash, so
//! that eleven methods or more stay apart. The DQN baselines get a colour each. A chart of
//! many methods draws the paper's SAP-Net and the best of each family in full, the others
//! faint ([`emphasised`]). Source policies get twenty categorical colours.

use plotters::prelude::*;

use crate::reuse::MethodKind;

/// How a method's line is stroked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Dash {
    Solid,
    Dashed,
}

/// A method's colour and dash.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Pen {
    pub colour: RGBColor,
    pub dash: Dash,
    /// A method drawn in the background of a figure of many ([`emphasised`]): a thin
    /// line, a pale bar, no band.
    pub faint: bool,
}

impl Pen {
    /// A solid pen of `colour` (a source's, in a legend).
    pub fn solid(colour: RGBColor) -> Self {
        Self {
            colour,
            dash: Dash::Solid,
            faint: false,
        }
    }

    /// This pen in the background: its colour halfway to white, thin.
    pub fn faded(self) -> Self {
        let pale = |c: u8| ((f64::from(c) + 255.0) / 2.0).round() as u8;
        let RGBColor(r, g, b) = self.colour;
        Self {
            colour: RGBColor(pale(r), pale(g), pale(b)),
            faint: true,
            ..self
        }
    }

    /// A line's width in pixels.
    pub fn width(&self) -> u32 {
        if self.faint {
            1
        } else {
            2
        }
    }

    /// How a bar of this pen is filled: a dashed pen's paler, so that bars side by side
    /// differ as its lines do.
    pub fn fill(&self) -> ShapeStyle {
        match self.dash {
            Dash::Solid => self.colour.filled(),
            Dash::Dashed => self.colour.mix(0.35).filled(),
        }
    }

    /// A dashed pen's bar is outlined in its colour.
    pub fn outline(&self) -> Option<ShapeStyle> {
        (self.dash == Dash::Dashed).then(|| self.colour.stroke_width(2))
    }
}

/// The hue (degrees) and saturation of a family, as its method's file gives them (DQN's
/// is grey); methods of one hue are one family here (both random selectors).
fn family(kind: MethodKind) -> (f64, f64) {
    (f64::from(kind.hue), f64::from(kind.saturation) / 100.0)
}

/// The members of a family in turn: three solid lines 0.2 apart in lightness, then two
/// dashed ones between them; a sixth member and on repeat with the dash swapped. Neighbours
/// in this order (bars side by side) are at least 0.2 apart.
const MEMBERS: [(f64, Dash); 5] = [
    (0.45, Dash::Solid),
    (0.25, Dash::Solid),
    (0.65, Dash::Solid),
    (0.35, Dash::Dashed),
    (0.55, Dash::Dashed),
];

/// A family without a hue (DQN from scratch: the baselines) would be greys too alike to
/// tell apart (three DQN sizes in the paper's protocol): each member gets a colour of its
/// own, a grey then hues no family uses (teal, olive), solid, then the same dashed.
const BASELINES: [(f64, f64, f64); 3] = [(0.0, 0.0, 0.40), (175.0, 0.60, 0.32), (60.0, 0.60, 0.33)];

/// The pens of methods of these kinds, in order: member `k` of its family is the `k`-th
/// method of that family listed.
pub(super) fn method_pens(kinds: &[MethodKind]) -> Vec<Pen> {
    kinds
        .iter()
        .enumerate()
        .map(|(i, &kind)| {
            let (hue, saturation) = family(kind);
            let member = kinds[..i]
                .iter()
                .filter(|&&k| family(k) == (hue, saturation))
                .count();
            if saturation == 0.0 {
                let (hue, saturation, lightness) = BASELINES[member % BASELINES.len()];
                let dash = if (member / BASELINES.len()).is_multiple_of(2) {
                    Dash::Solid
                } else {
                    Dash::Dashed
                };
                return Pen {
                    colour: hsl(hue, saturation, lightness),
                    dash,
                    faint: false,
                };
            }
            let (lightness, dash) = MEMBERS[member % MEMBERS.len()];
            let dash = match (member / MEMBERS.len() % 2, dash) {
                (0, dash) => dash,
                (_, Dash::Solid) => Dash::Dashed,
                (_, Dash::Dashed) => Dash::Solid,
            };
            Pen {
                colour: hsl(hue, saturation, lightness),
                dash,
                faint: false,
            }
        })
        .collect()
}

/// The colour of each method of these kinds, in order, as the plots draw it (8-bit RGB):
/// the terminal's views use the same, so that a method reads the same on screen and in
/// the PNG files.
pub fn method_colours(kinds: &[MethodKind]) -> Vec<(u8, u8, u8)> {
    method_pens(kinds)
        .into_iter()
        .map(|pen| (pen.colour.0, pen.colour.1, pen.colour.2))
        .collect()
}

/// More methods than this in one chart and the chart draws most of them faint.
pub(super) const MANY: usize = 6;

/// Which methods a chart draws in full, the others faint ([`Pen::faded`]): all of up to
/// [`MANY`]; of more, the paper's SAP-Net and the best of each family by `scores` (the
/// mean training return), so that eleven lines read as one per family.
pub(super) fn emphasised(kinds: &[MethodKind], labels: &[String], scores: &[f64]) -> Vec<bool> {
    if kinds.len() <= MANY {
        return vec![true; kinds.len()];
    }
    let papers = crate::reuse::Method::the_papers().label();
    (0..kinds.len())
        .map(|i| {
            let best_of_family = (0..kinds.len())
                .filter(|&j| family(kinds[j]) == family(kinds[i]))
                .max_by(|&a, &b| scores[a].total_cmp(&scores[b]).then(b.cmp(&a)));
            labels[i] == papers || best_of_family == Some(i)
        })
        .collect()
}

/// HSL to RGB (hue in degrees, saturation and lightness in [0, 1]).
fn hsl(hue: f64, saturation: f64, lightness: f64) -> RGBColor {
    let (r, g, b) = hsl_bytes(hue, saturation, lightness);
    RGBColor(r, g, b)
}

/// HSL (hue in degrees, saturation and lightness in [0, 1]) as 8-bit RGB: the plots' and
/// the terminal's method colours alike.
pub fn hsl_bytes(hue: f64, saturation: f64, lightness: f64) -> (u8, u8, u8) {
    let chroma = (1.0 - (2.0 * lightness - 1.0).abs()) * saturation;
    let h = hue.rem_euclid(360.0) / 60.0;
    let x = chroma * (1.0 - (h % 2.0 - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (chroma, x, 0.0),
        1 => (x, chroma, 0.0),
        2 => (0.0, chroma, x),
        3 => (0.0, x, chroma),
        4 => (x, 0.0, chroma),
        _ => (chroma, 0.0, x),
    };
    let m = lightness - chroma / 2.0;
    let byte = |v: f64| ((v + m) * 255.0).round().clamp(0.0, 255.0) as u8;
    (byte(r), byte(g), byte(b))
}

/// Matplotlib's `tab10`, then ten more far from them and from each other (five of
/// `tab20`'s light tints, navy, maroon, teal, near-black and gold; the nearest pair, the
/// lavender and the light pink, 50 apart in RGB): twenty colours told apart at a glance
/// (plotters' `Palette99` puts near-identical ones next to each other). A library of more
/// than twenty sources repeats them; the activation plot's markers still differ.
pub(super) const SOURCE_COLOURS: [RGBColor; 20] = [
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
    RGBColor(0, 0, 128),
    RGBColor(255, 187, 120),
    RGBColor(152, 223, 138),
    RGBColor(128, 0, 0),
    RGBColor(197, 176, 213),
    RGBColor(0, 128, 128),
    RGBColor(247, 182, 210),
    RGBColor(40, 40, 40),
    RGBColor(219, 219, 141),
    RGBColor(255, 215, 0),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn distance(a: RGBColor, b: RGBColor) -> f64 {
        let d = |x: u8, y: u8| (f64::from(x) - f64::from(y)).powi(2);
        (d(a.0, b.0) + d(a.1, b.1) + d(a.2, b.2)).sqrt()
    }

    /// The hue of an RGB colour in degrees, None for a grey.
    fn hue(c: RGBColor) -> Option<f64> {
        let (r, g, b) = (f64::from(c.0), f64::from(c.1), f64::from(c.2));
        let (max, min) = (r.max(g).max(b), r.min(g).min(b));
        if max - min < 1.0 {
            return None;
        }
        let h = if max == r {
            ((g - b) / (max - min)).rem_euclid(6.0)
        } else if max == g {
            (b - r) / (max - min) + 2.0
        } else {
            (r - g) / (max - min) + 4.0
        };
        Some(h * 60.0)
    }

    #[test]
    fn hsl_gives_the_known_colours() {
        // Pure red, a mid grey, and hsl(212°, 65%, 45%): C = 0.585, X = 0.585·(1 − |3.533 % 2
        // − 1|) = 0.273, m = 0.1575 → (0.1575, 0.4305, 0.7425) → (40, 110, 189).
        assert_eq!(hsl(0.0, 1.0, 0.5), RGBColor(255, 0, 0));
        assert_eq!(hsl(0.0, 0.0, 0.5), RGBColor(128, 128, 128));
        assert_eq!(hsl(212.0, 0.65, 0.45), RGBColor(40, 110, 189));
    }

    /// The reuse comparison's eleven methods (five SAP-Net, two random, UCB1, PRQ, the best
    /// source, DQN) and two more DQNs: every pen differs, every family but the baselines
    /// shares one hue.
    #[test]
    fn thirteen_methods_get_distinct_pens_with_families_by_hue() {
        use crate::reuse::Method;
        let sapnet = Method::SapNet.kind();
        let dqn = Method::Dqn { hidden: vec![100] }.kind();
        let kinds = [
            sapnet,
            sapnet,
            sapnet,
            sapnet,
            sapnet,
            Method::Random.kind(),
            Method::RandomPerEpisode.kind(),
            Method::Ucb1.kind(),
            Method::Prql(Default::default()).kind(),
            Method::BestSource.kind(),
            dqn,
            dqn,
            dqn,
        ];
        let pens = method_pens(&kinds);
        for i in 0..pens.len() {
            for j in 0..i {
                let apart = distance(pens[i].colour, pens[j].colour);
                assert!(apart > 30.0, "methods {j} and {i}: {apart:.1} apart");
                if kinds[i].saturation == 0 && kinds[j].saturation == 0 {
                    // The baselines: a colour each (asserted below).
                } else if family(kinds[i]) == family(kinds[j]) {
                    match (hue(pens[i].colour), hue(pens[j].colour)) {
                        (Some(a), Some(b)) => assert!((a - b).abs() < 1.5, "{i} {j}: {a} {b}"),
                        other => panic!("{i} and {j} of one family: hues {other:?}"),
                    }
                } else if let (Some(a), Some(b)) = (hue(pens[i].colour), hue(pens[j].colour)) {
                    let apart = (a - b).abs().min(360.0 - (a - b).abs());
                    assert!(apart > 25.0, "families of {i} and {j}: hues {a} and {b}");
                }
            }
        }
        // The SAP-Net family: three solid then two dashed; a lone comparator is solid.
        let dashes: Vec<Dash> = pens[..5].iter().map(|p| p.dash).collect();
        use Dash::*;
        assert_eq!(dashes, [Solid, Solid, Solid, Dashed, Dashed]);
        assert_eq!(pens[7].dash, Solid);
        // The two random selectors are one family: the second is its darker member.
        assert_eq!(pens[6].colour, hsl(212.0, 0.65, 0.25));
        // The three DQN baselines: a grey, a teal and an olive, no hue of a family's
        // within 25°, all solid.
        assert_eq!(hue(pens[10].colour), None);
        for pen in &pens[11..] {
            let h = hue(pen.colour).expect("a baseline past the first has a hue");
            for family in [0.0, 30.0, 125.0, 212.0, 280.0] {
                let apart = (h - family).abs().min(360.0 - (h - family).abs());
                assert!(apart > 25.0, "baseline hue {h} near {family}");
            }
            assert_eq!(pen.dash, Dash::Solid);
        }
    }

    /// The reuse comparison's eleven methods: the paper's SAP-Net, the best SAP-Net
    /// variant, the better random selector and each lone family's method in full; the
    /// other SAP-Net variants and the other random selector faint. Four methods: all.
    #[test]
    fn of_many_methods_the_papers_and_the_best_of_each_family_stand_out() {
        use crate::reuse::Method;
        let sapnet = Method::SapNet.kind();
        let kinds = [
            sapnet,
            sapnet,
            sapnet,
            Method::Random.kind(),
            Method::RandomPerEpisode.kind(),
            Method::Ucb1.kind(),
            Method::BestSource.kind(),
        ];
        let labels: Vec<String> = [
            "sapnet",
            "sapnet-k50",
            "sapnet-episode",
            "random",
            "random-episode",
            "ucb1",
            "best-source",
        ]
        .map(String::from)
        .to_vec();
        let scores = [100.0, 90.0, 150.0, 120.0, 130.0, 50.0, 10.0];
        assert_eq!(
            emphasised(&kinds, &labels, &scores),
            [true, false, true, false, true, true, true]
        );
        assert!(emphasised(&kinds[..4], &labels[..4], &scores[..4])
            .iter()
            .all(|&e| e));
        let faded = method_pens(&kinds)[1].faded();
        assert!(faded.faint && faded.width() < method_pens(&kinds)[1].width());
    }

    #[test]
    fn a_sixth_member_swaps_the_dash_of_the_first() {
        let pens = method_pens(&[crate::reuse::Method::SapNet.kind(); 6]);
        assert_eq!(pens[5].colour, pens[0].colour);
        assert_eq!((pens[0].dash, pens[5].dash), (Dash::Solid, Dash::Dashed));
    }

    #[test]
    fn twenty_sources_get_distinct_colours() {
        for i in 0..SOURCE_COLOURS.len() {
            for j in 0..i {
                let apart = distance(source_colour(i), source_colour(j));
                assert!(apart > 45.0, "sources {j} and {i}: {apart:.1} apart");
            }
        }
        assert_eq!(source_colour(20), source_colour(0));
    }
}
