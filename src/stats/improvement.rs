//! The probability of improvement: how likely a run of method X beats a run of method Y
//! on the same task, `P(X > Y) = 1/(n·m) Σ_i Σ_j S(x_i, y_j)` with `S = 1` if `x_i > y_j`,
//! ½ on a tie and 0 otherwise (the Mann–Whitney U statistic over n·m), averaged over the
//! tasks (`rliable`'s `probability_of_improvement`). 0.5 is a coin toss; its interval
//! comes from resampling X's runs and Y's runs independently within each task
//! (`rliable`'s `StratifiedIndependentBootstrap`).

use rand::rngs::StdRng;
use rand::SeedableRng;

use super::bootstrap::{self, LEVEL, RESAMPLES};
use super::{Estimate, Scores};

/// `P(X > Y)` over the tasks both have, in order; `x` and `y` must have the same number
/// of tasks.
pub fn probability(x: &Scores, y: &Scores) -> f64 {
    averaged_over_tasks(x.tasks(), y.tasks())
}

/// `P(X > Y)` with its 95% interval from [`RESAMPLES`] independent stratified resamples
/// of both, drawn from `seed`.
pub fn interval(x: &Scores, y: &Scores, seed: u64) -> Estimate {
    let mut rng = StdRng::seed_from_u64(seed);
    let buffers = |s: &Scores| -> Vec<Vec<f64>> {
        s.tasks()
            .iter()
            .map(|t| Vec::with_capacity(t.len()))
            .collect()
    };
    let (mut xs, mut ys) = (buffers(x), buffers(y));
    let mut values = Vec::with_capacity(RESAMPLES);
    for _ in 0..RESAMPLES {
        for (sample, scores) in [(&mut xs, x), (&mut ys, y)] {
            for (buffer, runs) in sample.iter_mut().zip(scores.tasks()) {
                buffer.clear();
                bootstrap::draw_task(runs, &mut rng, buffer);
            }
        }
        values.push(averaged_over_tasks(&xs, &ys));
    }
    let (lo, hi) = bootstrap::percentile_interval(&mut values, LEVEL);
    Estimate {
        point: probability(x, y),
        lo,
        hi,
    }
}

fn averaged_over_tasks(x: &[Vec<f64>], y: &[Vec<f64>]) -> f64 {
    assert_eq!(x.len(), y.len(), "scores on different tasks");
    let total: f64 = x.iter().zip(y).map(|(x, y)| on_one_task(x, y)).sum();
    total / x.len() as f64
}

/// `P(X > Y)` on one task, ties counted half: every pair compared (a few hundred for the
/// runs of a protocol), or, beyond a few thousand pairs, each x placed among the sorted y
/// by binary search (n log m).
fn on_one_task(x: &[f64], y: &[f64]) -> f64 {
    let score = |xi: f64, yj: f64| {
        if xi > yj {
            1.0
        } else if xi == yj {
            0.5
        } else {
            0.0
        }
    };
    let wins: f64 = if x.len() * y.len() <= 4096 {
        x.iter()
            .map(|&xi| y.iter().map(|&yj| score(xi, yj)).sum::<f64>())
            .sum()
    } else {
        let mut sorted = y.to_vec();
        sorted.sort_by(f64::total_cmp);
        x.iter()
            .map(|&xi| {
                let below = sorted.partition_point(|&yj| yj < xi);
                let not_above = sorted.partition_point(|&yj| yj <= xi);
                below as f64 + 0.5 * (not_above - below) as f64
            })
            .sum()
    };
    wins / (x.len() * y.len()) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(runs: &[f64]) -> Scores {
        Scores::one_task(runs.to_vec()).unwrap()
    }

    #[test]
    fn ties_count_half_and_pairs_are_counted_by_hand() {
        // x = [1, 3], y = [1, 2]: (1,1) tie ½, (1,2) 0, (3,1) 1, (3,2) 1 → 2.5 / 4.
        assert_eq!(probability(&one(&[1.0, 3.0]), &one(&[1.0, 2.0])), 0.625);
        assert_eq!(probability(&one(&[1.0, 2.0]), &one(&[1.0, 3.0])), 0.375);
        // Identical runs: a coin toss.
        assert_eq!(probability(&one(&[5.0, 5.0]), &one(&[5.0, 5.0])), 0.5);
        // Every x above every y.
        assert_eq!(probability(&one(&[9.0, 8.0]), &one(&[1.0, 2.0, 3.0])), 1.0);
    }

    #[test]
    fn many_runs_are_counted_by_binary_search_as_pairs_are() {
        // 100 × 100 pairs take the sorted path; ties in both (values 0 to 9).
        let x: Vec<f64> = (0..100).map(|i| f64::from(i * 7 % 10)).collect();
        let y: Vec<f64> = (0..100).map(|i| f64::from(i * 3 % 10)).collect();
        let pairs: f64 = x
            .iter()
            .flat_map(|a| y.iter().map(move |b| (a, b)))
            .map(|(a, b)| {
                if a > b {
                    1.0
                } else if a == b {
                    0.5
                } else {
                    0.0
                }
            })
            .sum::<f64>()
            / 10_000.0;
        assert!((on_one_task(&x, &y) - pairs).abs() < 1e-12);
    }

    #[test]
    fn tasks_are_averaged_not_pooled() {
        // Task 0: x wins all (1); task 1: x loses all (0) → 0.5, whatever the scales.
        let x = Scores::per_task(vec![vec![10.0], vec![-5.0]]).unwrap();
        let y = Scores::per_task(vec![vec![0.0], vec![100.0]]).unwrap();
        assert_eq!(probability(&x, &y), 0.5);
    }

    #[test]
    fn the_interval_holds_the_point_and_is_seeded() {
        let x = one(&[3.0, 5.0, 7.0, 9.0, 4.0]);
        let y = one(&[1.0, 2.0, 6.0, 3.0, 2.0]);
        let e = interval(&x, &y, 3);
        assert!(e.lo <= e.point && e.point <= e.hi, "{e:?}");
        assert!(e.point > 0.5 && e.hi <= 1.0 && e.lo < e.point, "{e:?}");
        assert_eq!(e, interval(&x, &y, 3));
        assert_ne!(e, interval(&x, &y, 4));
    }
}
