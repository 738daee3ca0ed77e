//! What one number says of a method's runs. Each is computed over every run of every
//! task pooled, as `rliable` computes its interquartile mean; with the same number of
//! runs per task (every protocol and sweep here) the pooled mean is also `rliable`'s mean
//! of the tasks' means.

/// The arithmetic mean.
pub fn mean(scores: &[f64]) -> f64 {
    scores.iter().sum::<f64>() / scores.len() as f64
}

/// The median of the runs (the middle value, or the mean of the two middle ones).
/// `rliable`'s `aggregate_median` is the median over tasks of each task's mean, which on
/// one task is the mean: here it is the runs' median, robust to one run's luck.
pub fn median(scores: &[f64]) -> f64 {
    let sorted = sorted(scores);
    let n = sorted.len();
    if n % 2 == 1 {
        sorted[n / 2]
    } else {
        (sorted[n / 2 - 1] + sorted[n / 2]) / 2.0
    }
}

/// The interquartile mean: the mean of the middle 50% of the runs, as
/// `scipy.stats.trim_mean(scores, 0.25)` computes it — ⌊n/4⌋ values cut from each end
/// of the sorted runs (none for n < 4), the rest averaged.
pub fn iqm(scores: &[f64]) -> f64 {
    let sorted = sorted(scores);
    let cut = sorted.len() / 4;
    mean(&sorted[cut..sorted.len() - cut])
}

/// The optimality gap of normalised scores: how far the runs fall short of 1 on average,
/// `mean(max(1 − x, 0))` (`rliable`'s `aggregate_optimality_gap` with γ = 1). Lower is
/// better.
pub fn optimality_gap(normalised: &[f64]) -> f64 {
    mean(
        &normalised
            .iter()
            .map(|x| (1.0 - x).max(0.0))
            .collect::<Vec<_>>(),
    )
}

fn sorted(scores: &[f64]) -> Vec<f64> {
    let mut sorted = scores.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_interquartile_mean_cuts_a_quarter_from_each_end_as_trim_mean_does() {
        // n = 8: cut 2 each end → mean(3, 4, 5, 6) = 4.5; order does not matter.
        assert_eq!(iqm(&[8.0, 1.0, 7.0, 2.0, 6.0, 3.0, 5.0, 4.0]), 4.5);
        // n = 10: cut ⌊2.5⌋ = 2 each end → mean of the middle 6: (3+…+8)/6 = 5.5.
        assert_eq!(iqm(&(1..=10).map(f64::from).collect::<Vec<_>>()), 5.5);
        // n = 5: cut 1 → mean(2, 3, 100) = 35; an outlier in the middle half stays.
        assert_eq!(iqm(&[1.0, 2.0, 3.0, 100.0, 1000.0]), 35.0);
        // n = 3: ⌊0.75⌋ = 0 cut: the mean.
        assert_eq!(iqm(&[1.0, 2.0, 6.0]), 3.0);
        // Ties: [0, 0, 5, 5, 5, 9, 9] (n = 7, cut 1) → mean(0, 5, 5, 5, 9) = 4.8.
        assert!((iqm(&[5.0, 9.0, 0.0, 5.0, 9.0, 0.0, 5.0]) - 4.8).abs() < 1e-12);
    }

    #[test]
    fn median_mean_and_gap_by_hand() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(mean(&[1.0, 2.0, 6.0]), 3.0);
        // Shortfalls 1 − x: 0.5, 0, 0 (x = 1.2 counts 0) → 0.5 / 3.
        assert!((optimality_gap(&[0.5, 1.0, 1.2]) - 0.5 / 3.0).abs() < 1e-15);
    }
}
