//! Performance profiles: for each level τ of the normalised score, the share of runs that
//! scored above it, `F(τ) = 1/N Σ 1[x > τ]` over every run of every task (`rliable`'s
//! score distribution, `create_performance_profile`), with a 95% stratified bootstrap
//! band. One curve per method shows the whole distribution of its runs, not one number: a
//! curve that lies above another everywhere dominates it.

use super::bootstrap::{self, LEVEL, RESAMPLES};
use super::{Estimate, Scores};

/// The levels a profile is drawn at: τ = 0, 0.01, …, 1.
pub fn levels() -> Vec<f64> {
    (0..=100).map(|i| f64::from(i) / 100.0).collect()
}

/// The share of runs above each of `taus`, with its interval, from [`RESAMPLES`]
/// resamples drawn from `seed`.
pub fn profile(scores: &Scores, taus: &[f64], seed: u64) -> Vec<Estimate> {
    let mut shares: Vec<Vec<f64>> = vec![Vec::with_capacity(RESAMPLES); taus.len()];
    let mut sorted = Vec::new();
    bootstrap::resamples(scores, RESAMPLES, seed, |sample| {
        sorted.clear();
        sorted.extend_from_slice(sample);
        sorted.sort_by(f64::total_cmp);
        for (values, &tau) in shares.iter_mut().zip(taus) {
            values.push(above(&sorted, tau));
        }
    });
    let mut pooled = scores.pooled();
    pooled.sort_by(f64::total_cmp);
    shares
        .iter_mut()
        .zip(taus)
        .map(|(values, &tau)| {
            let (lo, hi) = bootstrap::percentile_interval(values, LEVEL);
            Estimate {
                point: above(&pooled, tau),
                lo,
                hi,
            }
        })
        .collect()
}

/// The share of sorted `values` strictly above `tau`.
fn above(sorted: &[f64], tau: f64) -> f64 {
    let at_or_below = sorted.partition_point(|&x| x <= tau);
    (sorted.len() - at_or_below) as f64 / sorted.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_profile_counts_runs_strictly_above_each_level() {
        let scores = Scores::one_task(vec![0.0, 0.25, 0.5, 1.0]).unwrap();
        let profile = profile(&scores, &[0.0, 0.25, 0.3, 1.0], 1);
        let points: Vec<f64> = profile.iter().map(|e| e.point).collect();
        // Above 0: three of four; above 0.25: two (0.25 itself is not above); above 1: none.
        assert_eq!(points, [0.75, 0.5, 0.5, 0.0]);
        for e in &profile {
            assert!(e.lo <= e.point && e.point <= e.hi, "{e:?}");
        }
        // Nothing is above 1 in any resample either.
        assert_eq!((profile[3].lo, profile[3].hi), (0.0, 0.0));
        assert_eq!(levels().len(), 101);
        assert_eq!(levels()[100], 1.0);
    }
}
