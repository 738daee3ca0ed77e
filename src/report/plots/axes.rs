//! The y range of a plot: every value drawn (means, band and whisker ends) inside it, but
//! never past what the task can score, with the clamping said.

use crate::env::EnvConfig;

/// The returns an episode of `env` can have, where that is a bound the axes may stop at:
/// the native tasks' (each step +1 or −1 up to the time limit). A Gymnasium task's range
/// is a scale, not a bound (LunarLander's returns pass it): None.
pub fn return_bounds(env: &EnvConfig) -> Option<(f64, f64)> {
    match env {
        EnvConfig::Gymnasium(_) => None,
        native => Some(native.return_range()),
    }
}

/// A y range with a little room around the values (and some height when they are all
/// equal or there are none).
pub(super) fn value_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (low, high) = extent(values);
    if !low.is_finite() {
        return (0.0, 1.0);
    }
    padded(low, high)
}

fn extent(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        })
}

fn padded(low: f64, high: f64) -> (f64, f64) {
    let pad = ((high - low) * 0.05)
        .max(1e-9)
        .max(if high == low { 1.0 } else { 0.0 });
    (low - pad, high + pad)
}

/// A y axis fitted to the values drawn and the task's return range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Fit {
    pub low: f64,
    pub high: f64,
    /// The task's lowest return, when a value drawn ran below it (a mean − sd).
    pub cut_low: Option<f64>,
    /// The task's highest return, when a value drawn ran past it (a mean + sd).
    pub cut_high: Option<f64>,
}

/// The axis for `values` on a task whose returns lie in `task` (unknown: None): their
/// whole extent, clamped at the task's bounds, with 5% room.
pub(super) fn fit(values: impl Iterator<Item = f64>, task: Option<(f64, f64)>) -> Fit {
    let (mut low, mut high) = extent(values);
    if !low.is_finite() {
        (low, high) = task.unwrap_or((0.0, 1.0));
    }
    let (mut cut_low, mut cut_high) = (None, None);
    if let Some((task_low, task_high)) = task {
        if low < task_low {
            (low, cut_low) = (task_low, Some(task_low));
        }
        if high > task_high {
            (high, cut_high) = (task_high, Some(task_high));
        }
        // Values all past one bound (a band wholly outside): the bound alone.
        low = low.min(high);
    }
    let (low, high) = padded(low, high);
    Fit {
        low,
        high,
        cut_low,
        cut_high,
    }
}

impl Fit {
    /// `v` as drawn: at the task's bound where it ran past it.
    pub fn clamp(&self, v: f64) -> f64 {
        let v = self.cut_high.map_or(v, |h| v.min(h));
        self.cut_low.map_or(v, |l| v.max(l))
    }

    /// What was clamped, for the legend: "clamped at the task's max 500".
    pub fn note(&self) -> Option<String> {
        let number = |v: f64| {
            if v.fract() == 0.0 {
                format!("{v:.0}")
            } else {
                format!("{v}")
            }
        };
        match (self.cut_low, self.cut_high) {
            (None, None) => None,
            (Some(l), None) => Some(format!("clamped at the task's min {}", number(l))),
            (None, Some(h)) => Some(format!("clamped at the task's max {}", number(h))),
            (Some(l), Some(h)) => Some(format!(
                "clamped at the task's min {} and max {}",
                number(l),
                number(h)
            )),
        }
    }
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

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn a_band_inside_the_task_is_shown_whole() {
        // learning_curve.png's case: means near 180, mean + sd at 258 on CartPole (0..500).
        // Extent 10..258, room 5% of 248 = 12.4: the axis runs −2.4..270.4.
        let fit = fit([10.0, 180.0, 258.0].into_iter(), Some((0.0, 500.0)));
        assert!(close(fit.low, -2.4) && close(fit.high, 270.4), "{fit:?}");
        assert_eq!((fit.cut_low, fit.cut_high, fit.note()), (None, None, None));
        assert_eq!(fit.clamp(258.0), 258.0);
    }

    #[test]
    fn a_band_past_the_task_max_is_clamped_and_said() {
        // Mean 400 ± 220 on CartPole: 180..620 drawn as 180..500, room 5% of 320 = 16.
        let fit = fit([180.0, 400.0, 620.0].into_iter(), Some((0.0, 500.0)));
        assert!(close(fit.low, 164.0) && close(fit.high, 516.0), "{fit:?}");
        assert_eq!(fit.cut_high, Some(500.0));
        assert_eq!(fit.clamp(620.0), 500.0);
        assert_eq!(fit.clamp(180.0), 180.0);
        assert_eq!(fit.note().unwrap(), "clamped at the task's max 500");
    }

    #[test]
    fn whiskers_below_zero_are_shown_where_the_task_scores_below_zero() {
        // Acrobot (−500..0): a whisker to −540 is clamped at −500; one to −40 on a task
        // whose range is not known is shown whole: −40..300, room 17 → −57..317.
        let acrobot = fit([-540.0, -100.0, 0.0].into_iter(), Some((-500.0, 0.0)));
        assert!(close(acrobot.low, -525.0) && close(acrobot.high, 25.0));
        assert_eq!(acrobot.note().unwrap(), "clamped at the task's min -500");
        let unknown = fit([-40.0, 120.0, 300.0].into_iter(), None);
        assert!(
            close(unknown.low, -57.0) && close(unknown.high, 317.0),
            "{unknown:?}"
        );
        assert_eq!(unknown.clamp(-40.0), -40.0);
        // On CartPole the same whisker stops at 0, and both ends can be cut.
        let both = fit([-40.0, 620.0].into_iter(), Some((0.0, 500.0)));
        assert_eq!(
            both.note().unwrap(),
            "clamped at the task's min 0 and max 500"
        );
        assert!(close(both.low, -25.0) && close(both.high, 525.0));
    }

    #[test]
    fn the_axis_never_runs_far_past_the_task_max() {
        // The reuse tests.png of 11 methods ran to ~950 for a max of 500: the values alone
        // (0..500 and whiskers past it) now give at most 500 + 5%.
        let fit = fit([0.0, 480.0, 560.0].into_iter(), Some((0.0, 500.0)));
        assert!(close(fit.high, 525.0));
        // No values: the task's range.
        let empty = super::fit([].into_iter(), Some((-200.0, 0.0)));
        assert!(close(empty.low, -210.0) && close(empty.high, 10.0));
    }
}
