//! What a plot says about itself: the legend beside the chart (never over the data), the
//! notes under it that name the band or whiskers and the runs they are over, and the
//! phrases those notes share.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::palette::{marker, Dash, Pen};
use super::{Drawn, FAMILY};
use crate::env::EnvConfig;

/// The width of the legend column beside a chart.
pub(super) const WIDTH: u32 = 300;

/// How an entry is drawn in the legend.
pub(super) enum Swatch {
    Line(Pen),
    Bar(Pen),
    /// A line of a colour with marker shape `usize` on it ([`super::palette::marker`]).
    Marked(RGBColor, usize),
}

/// A bar of `pen` between two corners: filled, and outlined for a dashed pen.
pub(super) fn bar<C: Clone>(corners: [C; 2], pen: Pen) -> Vec<Rectangle<C>> {
    let mut shapes = vec![Rectangle::new(corners.clone(), pen.fill())];
    shapes.extend(pen.outline().map(|style| Rectangle::new(corners, style)));
    shapes
}

pub(super) struct Entry {
    pub label: String,
    pub swatch: Swatch,
}

/// "1 run", "5 runs", or "2–5 runs" when the counts differ ("no runs" without any).
pub(super) fn runs_phrase(counts: impl IntoIterator<Item = usize>) -> String {
    let counts: Vec<usize> = counts.into_iter().collect();
    match (counts.iter().min(), counts.iter().max()) {
        (Some(1), Some(1)) => "1 run".into(),
        (Some(lo), Some(hi)) if lo == hi => format!("{lo} runs"),
        (Some(lo), Some(hi)) => format!("{lo}–{hi} runs"),
        _ => "no runs".into(),
    }
}

/// A label with its run count: "sapnet (2 runs)".
pub(super) fn with_runs(label: &str, runs: usize) -> String {
    format!("{label} ({})", runs_phrase([runs]))
}

/// The plot's title with what it is about first, when it is one value of a sweep's axis:
/// "sapnet.temperature = 1.0 · CartPole-v1: …".
pub(super) fn title(subject: Option<&str>, rest: &str) -> String {
    match subject {
        Some(subject) => format!("{subject} · {rest}"),
        None => rest.to_string(),
    }
}

/// A task as every figure's title names it: its Gymnasium id, then what differs from the
/// task's defaults (`CartPole-v1`, `CartPole-v1(length=1.0)`; results label it
/// `cartpole(length=1.0)`).
pub fn task_title(env: &EnvConfig) -> String {
    let label = env.label();
    match label.strip_prefix(env.task_name().as_str()) {
        Some(changed) => format!("{}{changed}", env.gym_id()),
        // A Gymnasium task's label starts with its id already.
        None => label,
    }
}

/// A line of `pen` through `points`.
pub(super) fn draw_line<DB: DrawingBackend>(
    chart: &mut ChartContext<DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    points: Vec<(f64, f64)>,
    pen: Pen,
) -> Drawn<DB> {
    let style = pen.colour.stroke_width(pen.width());
    match pen.dash {
        Dash::Solid => chart.draw_series(LineSeries::new(points, style))?,
        Dash::Dashed => chart.draw_series(DashedLineSeries::new(points, 9, 5, style))?,
    };
    Ok(())
}

/// A line of `pen` through `points` drawn as its segments, each on its own (solid): no
/// join between them, whose miter a wide stroke turning back on itself would stretch far
/// past the points (a [`thinned`](super::curves::thinned) line turns back at every span).
pub(super) fn draw_segments<DB: DrawingBackend>(
    chart: &mut ChartContext<DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    points: &[(f64, f64)],
    pen: Pen,
) -> Drawn<DB> {
    let style = pen.colour.stroke_width(pen.width());
    chart.draw_series(
        points
            .windows(2)
            .map(|w| PathElement::new(vec![w[0], w[1]], style)),
    )?;
    Ok(())
}

/// The entries, one a row, then the notes, wrapped to the column.
pub(super) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
    notes: &[String],
) -> Drawn<DB> {
    let row = 20;
    let (x, mut y) = (8, 14);
    let font = (FAMILY, 14).into_font();
    for entry in entries {
        match entry.swatch {
            Swatch::Line(pen) => {
                let points = vec![(x, y), (x + 28, y)];
                let style = pen.colour.stroke_width(2);
                match pen.dash {
                    Dash::Solid => area.draw(&PathElement::new(points, style))?,
                    Dash::Dashed => area.draw(&plotters::element::DashedPathElement::new(
                        points, 9, 5, style,
                    ))?,
                }
            }
            Swatch::Bar(pen) => {
                for shape in bar([(x + 7, y - 6), (x + 21, y + 6)], pen) {
                    area.draw(&shape)?;
                }
            }
            Swatch::Marked(colour, shape) => {
                area.draw(&PathElement::new(
                    vec![(x, y), (x + 28, y)],
                    colour.stroke_width(2),
                ))?;
                area.draw(&(EmptyElement::at((x + 14, y)) + marker(shape, (0, 0), colour)))?;
            }
        }
        area.draw(&Text::new(
            entry.label.clone(),
            (x + 36, y - 8),
            font.clone(),
        ))?;
        y += row;
    }
    y += row / 2;
    let small = (FAMILY, 13).into_font().color(&BLACK.mix(0.8));
    for note in notes {
        for line in wrap(note, 38) {
            area.draw(&Text::new(line, (x, y - 8), small.clone()))?;
            y += 17;
        }
        y += 4;
    }
    Ok(())
}

/// `text` in lines of at most `width` characters, broken at spaces.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ') {
        match lines.last_mut() {
            Some(line) if line.chars().count() + 1 + word.chars().count() <= width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_counts_read_as_one_phrase() {
        assert_eq!(runs_phrase([1]), "1 run");
        assert_eq!(runs_phrase([2, 2, 2]), "2 runs");
        assert_eq!(runs_phrase([5, 2, 3]), "2–5 runs");
        assert_eq!(runs_phrase([]), "no runs");
        assert_eq!(with_runs("dqn[100]", 1), "dqn[100] (1 run)");
    }

    #[test]
    fn titles_name_the_axis_value_first() {
        assert_eq!(
            title(Some("sapnet.temperature = 1.0"), "CartPole-v1: tests"),
            "sapnet.temperature = 1.0 · CartPole-v1: tests"
        );
        assert_eq!(title(None, "CartPole-v1: tests"), "CartPole-v1: tests");
    }

    #[test]
    fn tasks_are_named_by_their_gymnasium_id() {
        let cartpole = EnvConfig::CartPole(Default::default());
        assert_eq!(task_title(&cartpole), "CartPole-v1");
        let EnvConfig::CartPole(mut longer) = cartpole else {
            unreachable!()
        };
        longer.length = 1.0;
        let longer = EnvConfig::CartPole(longer);
        assert_eq!(longer.label(), "cartpole(length=1.0)");
        assert_eq!(task_title(&longer), "CartPole-v1(length=1.0)");
        let acrobot = EnvConfig::Acrobot(Default::default());
        assert_eq!(task_title(&acrobot), "Acrobot-v1");
    }

    #[test]
    fn notes_wrap_at_spaces() {
        assert_eq!(
            wrap("band: ± 1 sd over 2 runs", 12),
            ["band: ± 1 sd", "over 2 runs"]
        );
        assert_eq!(wrap("short", 38), ["short"]);
    }
}
