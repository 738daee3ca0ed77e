//! How many runs would detect an effect: where two methods are not separated, the number
//! of runs per method at which the rank test would see the difference the runs show.

use super::normal;

/// The two-sided level the sample size is for.
pub const ALPHA: f64 = 0.05;

/// The chance of detecting the effect, if it is as large as observed.
pub const POWER: f64 = 0.8;

/// Runs per method for a two-sided Wilcoxon–Mann–Whitney test at level [`ALPHA`] to
/// detect `P(X > Y) = p` with probability [`POWER`], by Noether's formula (G. E. Noether,
/// "Sample Size Determination for Some Common Nonparametric Tests", Journal of the
/// American Statistical Association 82(398), 645–647, 1987) for equal groups:
///
/// `N = (z_{1−α/2} + z_{1−β})² / (12·c·(1 − c)·(p − ½)²)`, c = ½ (half the runs each),
///
/// so `N = (1.96 + 0.84)²/(3·(p − ½)²)` runs in all and ⌈N/2⌉ per method. `p` is the
/// observed `P(X > Y)` of [`super::improvement::probability`], ties counted half; `None`
/// when p = ½: there is no difference to detect.
///
/// An estimate, not a guarantee: the formula takes the test statistic's variance under
/// the null for that under the alternative, which holds for small effects and a
/// location-shift-like alternative (Y's distribution moved, not reshaped), and p itself
/// is measured on the runs at hand, with their noise. It is for one task: over several,
/// the van Elteren test pools the tasks and the count is no longer per task.
///
/// Precondition: `0 ≤ p ≤ 1`.
pub fn runs_per_method(p: f64) -> Option<usize> {
    runs_per_method_at(p, ALPHA)
}

/// [`runs_per_method`] at the two-sided level `alpha`: a table's pairs are tested with
/// Holm's adjustment, under which the pair with the smallest p must pass `ALPHA / pairs`,
/// so a plan that the rule can pass is made at that level (Bonferroni's, which Holm's
/// first step is).
///
/// Precondition: `0 ≤ p ≤ 1`, `0 < alpha < 1`.
pub fn runs_per_method_at(p: f64, alpha: f64) -> Option<usize> {
    debug_assert!((0.0..=1.0).contains(&p), "a probability, not {p}");
    if p == 0.5 {
        return None;
    }
    let z = normal::quantile(1.0 - alpha / 2.0) + normal::quantile(POWER);
    let share = 0.5;
    let all_runs = z * z / (12.0 * share * (1.0 - share) * (p - 0.5).powi(2));
    // At least (z/0.5)²/3 ≈ 10.5 runs in all, when p is 0 or 1; a p a hair from ½ asks
    // for more than usize holds, and the cast saturates at usize::MAX.
    Some((all_runs / 2.0).ceil() as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At the level Holm's adjustment tests the first of 55 pairs, 0.05/55: z = 3.317,
    /// (3.317 + 0.842)²/(3·¼) = 23.06 runs in all, 12 per method for a complete separation
    /// (p = 1) — where 6 runs a method, whose smallest exact p (0.0022) cannot pass
    /// 0.05/55 = 0.00091, would be promised at 0.05.
    #[test]
    fn a_plan_at_holms_level_asks_for_more_runs() {
        assert_eq!(runs_per_method(1.0), Some(6));
        assert_eq!(runs_per_method_at(1.0, 0.05 / 55.0), Some(12));
        assert!(runs_per_method_at(0.75, 0.05 / 55.0).unwrap() > runs_per_method(0.75).unwrap());
    }

    #[test]
    fn noether_runs_as_the_reference_script_counts_them() {
        // scripts/stats_reference.py with scipy 1.17.1's norm.ppf. By hand for p = 0.75:
        // (1.959964 + 0.841621)² = 7.8489, over 3·0.25² = 0.1875 → N = 41.86, 20.93 per
        // method → 21.
        let cases = [
            (0.75, 21),
            (0.6, 131),
            (0.9, 9),
            (1.0, 6),
            (0.0, 6),
            (0.3, 33),
            (0.55, 524),
            (0.52, 3271),
            (0.625, 84),
        ];
        for (p, runs) in cases {
            assert_eq!(runs_per_method(p), Some(runs), "p = {p}");
        }
    }

    #[test]
    fn a_coin_toss_has_nothing_to_detect_and_either_direction_counts_alike() {
        assert_eq!(runs_per_method(0.5), None);
        assert_eq!(runs_per_method(0.25), runs_per_method(0.75));
    }
}
