//! A finished protocol beside the live run (`--compare DIR`): for each method the moving
//! average of its runs' returns, their mean and the 95% bootstrap interval of that mean,
//! drawn under the live curves of the same method.

use std::path::Path;

use anyhow::{Context, Result};

use crate::report::plots;
use crate::results;
use crate::results::folder_state::{FolderReader, RunStatus};
use crate::seeds::{self, Part};
use crate::stats::{aggregate, bootstrap, Scores};

/// Points of a band: the terminal draws a few hundred columns at most, and each point
/// costs a bootstrap.
pub const BAND_POINTS: usize = 512;

/// Resamples per point of a band: the usual floor, which keeps `--compare` of a 55-run
/// protocol to a fraction of a second.
const BAND_RESAMPLES: usize = 2000;

/// One method's finished runs, as the reward chart draws them.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// The method's label in results (`sapnet`, `dqn[100]`).
    pub label: String,
    /// Runs that went into it.
    pub runs: usize,
    /// `(episode, mean of the runs' moving averages)`.
    pub mean: Vec<(f64, f64)>,
    /// `(episode, low end)` and `(episode, high end)` of the mean's 95% interval.
    pub low: Vec<(f64, f64)>,
    pub high: Vec<(f64, f64)>,
}

impl Band {
    /// The band of `runs` (each run's returns, episode 1 first) under a moving average of
    /// `window` episodes: from the `window`-th episode on, thinned to at most
    /// [`BAND_POINTS`], the mean over the runs that reach it and its 95% bootstrap
    /// interval (the runs resampled).
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
        let stride = longest.div_ceil(BAND_POINTS).max(1);
        let mut band = Band {
            label: label.to_string(),
            runs: runs.len(),
            mean: Vec::new(),
            low: Vec::new(),
            high: Vec::new(),
        };
        for i in (0..longest).step_by(stride) {
            let values: Vec<f64> = averages.iter().filter_map(|a| a.get(i).copied()).collect();
            let episode = (i + window) as f64;
            let Some(scores) = Scores::one_task(values) else {
                continue;
            };
            let seed = seeds::derive(
                0,
                &[Part::Name("band"), Part::Name(label), Part::Index(i as u64)],
            );
            let e = bootstrap::interval_of(&scores, aggregate::mean, BAND_RESAMPLES, seed);
            band.mean.push((episode, e.point));
            band.low.push((episode, e.lo));
            band.high.push((episode, e.hi));
        }
        band
    }
}

/// The bands of a protocol's methods (`--compare DIR`) over its finished runs; refused
/// when that protocol trained on another task than `task`, the dashboard's (its returns
/// would be drawn on the wrong scale). A folder with run records — finished, stopped, or
/// live and being written by another process — is read from them, as `sapnet open` reads
/// it (never written, its lock never taken); a folder shipped with its top-level files
/// only, from its episodes.csv.
pub fn bands_of_folder(dir: &Path, task: &str) -> Result<Vec<Band>> {
    let expected = || {
        format!(
            "--compare {}: expected the output folder of a `sapnet --headless` run",
            dir.display()
        )
    };
    let live = crate::folder_lock::holder(dir)
        .with_context(expected)?
        .is_some();
    if !live && !results::records::any(dir).with_context(expected)? {
        let data = results::read_plot_data(dir).with_context(expected)?;
        refuse_other_task(dir, &data.task, task)?;
        return Ok(data
            .curves
            .iter()
            .map(|c| {
                let returns: Vec<Vec<f64>> = c.runs.iter().map(|r| r.returns.clone()).collect();
                Band::from_runs(&c.label, &returns, data.window)
            })
            .collect());
    }
    let folder = FolderReader::new(dir).read().with_context(expected)?;
    refuse_other_task(dir, &plots::task_title(&folder.config.env), task)?;
    let window = folder.config.protocol.moving_average;
    let mut bands = Vec::new();
    for method in crate::trainer::MethodId::all(&folder.config.protocol.methods) {
        let runs: Vec<Vec<f64>> = folder
            .runs
            .iter()
            .filter(|r| r.method == method && r.status == RunStatus::Done)
            .map(|r| r.training.returns.clone())
            .collect();
        if !runs.is_empty() {
            bands.push(Band::from_runs(method.label(), &runs, window));
        }
    }
    Ok(bands)
}

fn refuse_other_task(dir: &Path, theirs: &str, task: &str) -> Result<()> {
    anyhow::ensure!(
        theirs == task,
        "--compare {}: its results are on {theirs}, the dashboard trains on {task}: compare \
         with a protocol on the same task",
        dir.display(),
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two runs by hand, window 2: MA10s of [1, 3, 5] and [3, 5, 7] are [2, 4] and [4, 6];
    /// their means 3 and 5 at episodes 2 and 3. Resampling two runs gives the mean of
    /// (a, a), (a, b) or (b, b): the interval runs from the lower run to the higher.
    #[test]
    fn the_band_is_the_mean_of_the_runs_moving_averages_and_its_interval() {
        let band = Band::from_runs("sapnet", &[vec![1.0, 3.0, 5.0], vec![3.0, 5.0, 7.0]], 2);
        assert_eq!(band.mean, vec![(2.0, 3.0), (3.0, 5.0)]);
        assert_eq!(band.low, vec![(2.0, 2.0), (3.0, 4.0)]);
        assert_eq!(band.high, vec![(2.0, 4.0), (3.0, 6.0)]);
        assert_eq!(band.runs, 2);
    }

    #[test]
    fn a_long_protocol_is_thinned_to_the_curves_budget() {
        let run: Vec<f64> = (0..20_000).map(f64::from).collect();
        let band = Band::from_runs("dqn[100]", &[run], 10);
        assert!(band.mean.len() <= BAND_POINTS, "{}", band.mean.len());
        assert_eq!(band.mean[0], (10.0, 4.5));
        assert_eq!(band.low, band.mean, "one run: no spread");
        assert_eq!(band.high, band.mean);
    }
}
