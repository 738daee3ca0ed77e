//! The share of runs that reached something (a moving average of 195, say), with the
//! Wilson score interval: unlike a bootstrap of 0s and 1s it does not collapse to a
//! point when every run (or none) reached it — 10 of 10 runs say "at least 72%", not
//! "100%".

use super::Estimate;

/// z for a two-sided 95% interval.
const Z: f64 = 1.959_963_984_540_054;

/// `hits` of `trials` with its 95% Wilson interval; `None` without trials.
pub fn wilson(hits: usize, trials: usize) -> Option<Estimate> {
    if trials == 0 {
        return None;
    }
    let n = trials as f64;
    let p = hits as f64 / n;
    let z2 = Z * Z;
    let centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
    let half = Z / (1.0 + z2 / n) * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    Some(Estimate {
        point: p,
        lo: (centre - half).max(0.0),
        hi: (centre + half).min(1.0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_intervals_by_hand() {
        // 10 of 10: centre (1 + 0.19207)/(1.38415) = 0.86124, half 0.13876 → [0.7225, 1].
        let all = wilson(10, 10).unwrap();
        assert_eq!(all.point, 1.0);
        assert!((all.lo - 0.722_467).abs() < 1e-5, "{all:?}");
        assert!((all.hi - 1.0).abs() < 1e-12, "{all:?}");
        // 5 of 10: symmetric about ½, [0.2366, 0.7634] (statsmodels' proportion_confint,
        // method="wilson").
        let half = wilson(5, 10).unwrap();
        assert!((half.lo - 0.236_593).abs() < 1e-5 && (half.hi - 0.763_407).abs() < 1e-5);
        // 0 of 10 mirrors 10 of 10.
        let none = wilson(0, 10).unwrap();
        assert!(none.lo.abs() < 1e-12 && (none.hi - (1.0 - all.lo)).abs() < 1e-12);
        assert_eq!(wilson(0, 0), None);
    }
}
