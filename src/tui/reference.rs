//! A finished protocol beside the live run (`--compare DIR`): for each method the moving
//! average of its runs' returns, their mean and a band of ± one standard deviation, drawn
//! under the live curves of the same method.

use super::dashboard::CURVE_POINTS;

/// One method's finished runs, as the reward chart draws them.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// The method's label in results (`sapnet`, `dqn[100]`).
    pub label: String,
    /// Runs that went into it.
    pub runs: usize,
    /// `(episode, mean of the runs' moving averages)`.
    pub mean: Vec<(f64, f64)>,
    /// `(episode, mean − sd)` and `(episode, mean + sd)`.
    pub low: Vec<(f64, f64)>,
    pub high: Vec<(f64, f64)>,
}

impl Band {
    /// The band of `runs` (each run's returns, episode 1 first) under a moving average of
    /// `window` episodes: a point per episode from the `window`-th on, mean and sample
    /// standard deviation over the runs that reach it, thinned to at most [`CURVE_POINTS`].
    pub fn from_runs(label: &str, runs: &[Vec<f64>], window: usize) -> Self {
        let window = window.max(1);
        let averages: Vec<Vec<f64>> = runs
            .iter()
            .map(|returns| {
                returns
                    .windows(window)
                    .map(|w| w.iter().sum::<f64>() / window as f64)
                    .collect()
            })
            .collect();
        let longest = averages.iter().map(Vec::len).max().unwrap_or(0);
        let stride = longest.div_ceil(CURVE_POINTS).max(1);
        let mut band = Band {
            label: label.to_string(),
            runs: runs.len(),
            mean: Vec::new(),
            low: Vec::new(),
            high: Vec::new(),
        };
        for i in (0..longest).step_by(stride) {
            let values: Vec<f64> = averages.iter().filter_map(|a| a.get(i).copied()).collect();
            let n = values.len() as f64;
            let mean = values.iter().sum::<f64>() / n;
            let sd = if values.len() < 2 {
                0.0
            } else {
                (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
            };
            let episode = (i + window) as f64;
            band.mean.push((episode, mean));
            band.low.push((episode, mean - sd));
            band.high.push((episode, mean + sd));
        }
        band
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two runs by hand, window 2: MA10s of [1, 3, 5] and [3, 5, 7] are [2, 4] and [4, 6];
    /// their means 3 and 5 at episodes 2 and 3, sample sd √2 each.
    #[test]
    fn the_band_is_the_mean_and_sd_of_the_runs_moving_averages() {
        let band = Band::from_runs("sapnet", &[vec![1.0, 3.0, 5.0], vec![3.0, 5.0, 7.0]], 2);
        assert_eq!(band.mean, vec![(2.0, 3.0), (3.0, 5.0)]);
        let sd = 2f64.sqrt();
        assert_eq!(band.low, vec![(2.0, 3.0 - sd), (3.0, 5.0 - sd)]);
        assert_eq!(band.high, vec![(2.0, 3.0 + sd), (3.0, 5.0 + sd)]);
        assert_eq!(band.runs, 2);
    }

    #[test]
    fn a_long_protocol_is_thinned_to_the_curves_budget() {
        let run: Vec<f64> = (0..20_000).map(f64::from).collect();
        let band = Band::from_runs("dqn[100]", &[run], 10);
        assert!(band.mean.len() <= CURVE_POINTS, "{}", band.mean.len());
        assert_eq!(band.mean[0], (10.0, 4.5));
        assert_eq!(band.low, band.mean, "one run: no spread");
    }
}
