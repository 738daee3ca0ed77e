//! The one rule by which sapnet says two methods are told apart by their runs.
//!
//! A pair X, Y is **separated** only if
//! 1. the 95% interval of `P(X > Y)` ([`super::improvement`]) excludes ½,
//! 2. under every one of [`BOOTSTRAP_SEEDS`] bootstrap seeds (a percentile interval at 10
//!    runs has an end that moves with the resamples: one that sits at 0.49–0.51 is luck),
//! 3. and the rank test ([`super::rank_test`]) agrees after Holm's adjustment
//!    ([`super::multiplicity`]) over every comparison of its table: adjusted p < [`ALPHA`].
//!
//! It is **fragile** when the evidence disagrees (some seeds' intervals exclude ½ and
//! others do not, or the intervals and the corrected test say different things), and **not
//! separated** when nothing tells the two apart. Not separated is no finding: the runs
//! may be too few, and [`super::power::runs_per_method`] says how many would detect the
//! difference they show.

use serde::Serialize;

use super::Estimate;

/// How many bootstrap seeds a separation must hold under.
pub const BOOTSTRAP_SEEDS: usize = 5;

/// The family-wise level of the rank tests, after Holm's adjustment.
pub const ALPHA: f64 = 0.05;

/// What the runs say of a pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    Separated,
    Fragile,
    NotSeparated,
}

impl Verdict {
    /// The verdict of a pair whose `P(X > Y)` has the 95% `intervals`, one per bootstrap
    /// seed, and whose rank test's Holm-adjusted p-value is `holm_p`.
    ///
    /// # Panics
    /// If `intervals` is empty (a caller bug: there is always the seed of the row itself).
    pub fn of(intervals: &[Estimate], holm_p: f64) -> Self {
        assert!(!intervals.is_empty(), "a verdict needs an interval");
        let excluding = excluding_half(intervals);
        let test_rejects = holm_p < ALPHA;
        if excluding == intervals.len() && test_rejects {
            Self::Separated
        } else if excluding == 0 && !test_rejects {
            Self::NotSeparated
        } else {
            Self::Fragile
        }
    }

    /// As `improvement.csv` and the tables write it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Separated => "separated",
            Self::Fragile => "fragile",
            Self::NotSeparated => "not separated",
        }
    }
}

/// How many of `intervals` exclude ½, on either side.
pub fn excluding_half(intervals: &[Estimate]) -> usize {
    intervals
        .iter()
        .filter(|e| e.lo > 0.5 || e.hi < 0.5)
        .count()
}

/// `P(Y > X)` from `P(X > Y)`: with ties counted half the two add up to 1 on every
/// resample, so the interval mirrors too.
pub fn reversed(p: Estimate) -> Estimate {
    Estimate {
        point: 1.0 - p.point,
        lo: 1.0 - p.hi,
        hi: 1.0 - p.lo,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn e(lo: f64, hi: f64) -> Estimate {
        Estimate {
            point: (lo + hi) / 2.0,
            lo,
            hi,
        }
    }

    #[test]
    fn separated_needs_every_seed_and_the_corrected_test() {
        let clear = [e(0.6, 0.9), e(0.58, 0.88), e(0.61, 0.92)];
        assert_eq!(Verdict::of(&clear, 0.001), Verdict::Separated);
        // The intervals agree, the corrected test does not.
        assert_eq!(Verdict::of(&clear, 0.2), Verdict::Fragile);
        // Below ½ is separated too: the pair is told apart the other way.
        assert_eq!(
            Verdict::of(&[e(0.02, 0.35), e(0.03, 0.4)], 0.01),
            Verdict::Separated
        );
    }

    #[test]
    fn an_end_that_moves_across_half_with_the_seed_is_fragile() {
        // REUSE.md's Acrobot row: the upper end at 0.49 under one seed, 0.50 under others.
        let seeds = [e(0.06, 0.49), e(0.06, 0.50), e(0.05, 0.50)];
        assert_eq!(excluding_half(&seeds), 1);
        assert_eq!(Verdict::of(&seeds, 0.01), Verdict::Fragile);
    }

    #[test]
    fn nothing_telling_them_apart_is_not_separated() {
        let seeds = [e(0.3, 0.7), e(0.31, 0.69)];
        assert_eq!(Verdict::of(&seeds, 0.6), Verdict::NotSeparated);
        // A test alone, against every interval, is not enough either.
        assert_eq!(Verdict::of(&seeds, 0.01), Verdict::Fragile);
    }

    #[test]
    fn the_reverse_pair_mirrors_the_interval() {
        let p = Estimate {
            point: 0.75,
            lo: 0.6,
            hi: 0.875,
        };
        let q = reversed(p);
        assert_eq!((q.point, q.lo, q.hi), (0.25, 0.125, 0.4));
        assert_eq!(reversed(q), p);
    }
}
