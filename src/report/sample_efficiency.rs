//! Sample-efficiency curves, as openrlbenchmark draws them: at every point of training, the
//! interquartile mean (and the mean) over runs of each run's moving average, with its 95%
//! bootstrap interval over the runs ([`crate::stats::bootstrap`], the resampling checked
//! against rliable). Under an episode budget the points are episodes; under a step budget
//! they are environment steps, each run's value there the mean return of its last episodes
//! ended by it ([`super::step_axis`]). `sample_efficiency.csv` holds the points
//! (`episode` or `step` in its second column), `sample_efficiency.png` draws the IQM.

use crate::config::Budget;
use crate::report::runs::TrainingEpisodes;
use crate::report::step_axis;
use crate::seeds::{self, Part};
use crate::stats::{aggregate, bootstrap, Estimate, Scores};

/// Points per curve: a figure is a thousand pixels wide, and each point costs a bootstrap
/// per statistic.
pub const POINTS: usize = 200;

/// Resamples per point: a band drawn from many intervals at once, where 2,000 suffice
/// (as `--compare`'s bands).
pub const RESAMPLES: usize = 2_000;

/// One point of a method's curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EfficiencyPoint {
    /// Where on the budget's axis: the episode the moving averages end at, or the
    /// environment step.
    pub at: u64,
    /// Runs that have a value there (a stopped run is shorter; a run has none on the step
    /// axis before its first episode ended).
    pub runs: usize,
    pub iqm: Estimate,
    pub mean: Estimate,
}

/// The curve of `label`'s runs under `budget` and a moving average of `window` episodes:
/// under an episode budget, from the `window`-th episode on, at most [`POINTS`] episodes
/// evenly spaced, the last always included; under a step budget, [`POINTS`] steps evenly
/// spaced up to the budget.
pub fn curve(
    label: &str,
    runs: &[TrainingEpisodes],
    window: usize,
    budget: Budget,
) -> Vec<EfficiencyPoint> {
    match budget {
        Budget::Episodes(_) => {
            let returns: Vec<&[f64]> = runs.iter().map(|r| r.returns.as_slice()).collect();
            episode_curve(label, &returns, window)
        }
        Budget::Steps(budget) => step_curve(label, runs, window, budget),
    }
}

/// The points of a step budget: each run's [`step_axis::curve`], aggregated at each step.
fn step_curve(
    label: &str,
    runs: &[TrainingEpisodes],
    window: usize,
    budget: u64,
) -> Vec<EfficiencyPoint> {
    let at = step_axis::points(budget, POINTS);
    let curves: Vec<Vec<Option<f64>>> = runs
        .iter()
        .map(|r| step_axis::curve(r, window, &at))
        .collect();
    at.iter()
        .enumerate()
        .filter_map(|(i, &step)| {
            let values: Vec<f64> = curves.iter().filter_map(|c| c[i]).collect();
            point(label, step, i, values)
        })
        .collect()
}

/// The IQM and mean of `values` (one per run) at `at`, the `i`-th point, with their
/// intervals; none without a value.
fn point(label: &str, at: u64, i: usize, values: Vec<f64>) -> Option<EfficiencyPoint> {
    let (runs, iqm, mean) = over_runs(label, i, values)?;
    Some(EfficiencyPoint {
        at,
        runs,
        iqm,
        mean,
    })
}

/// Over how many runs, and the IQM and mean of `values` (one per run) at the `i`-th point
/// of `label`'s curve, with their 95% bootstrap intervals (the seeds named by `label`, the
/// statistic and `i`); none without a value.
pub fn over_runs(label: &str, i: usize, values: Vec<f64>) -> Option<(usize, Estimate, Estimate)> {
    let runs = values.len();
    let scores = Scores::one_task(values)?;
    let seed = |statistic: &str| {
        seeds::derive(
            0,
            &[
                Part::Name("sample efficiency"),
                Part::Name(label),
                Part::Name(statistic),
                Part::Index(i as u64),
            ],
        )
    };
    Some((
        runs,
        bootstrap::interval_of(&scores, aggregate::iqm, RESAMPLES, seed("iqm")),
        bootstrap::interval_of(&scores, aggregate::mean, RESAMPLES, seed("mean")),
    ))
}

/// The points of an episode budget. Each run's moving average is computed at the points
/// only (as [`moving_average`](super::moving_average) would give it there), never kept whole.
fn episode_curve(label: &str, runs: &[&[f64]], window: usize) -> Vec<EfficiencyPoint> {
    let window = window.max(1);
    let longest = runs
        .iter()
        .map(|r| (r.len() + 1).saturating_sub(window))
        .max()
        .unwrap_or(0);
    if longest == 0 {
        return Vec::new();
    }
    let stride = longest.div_ceil(POINTS).max(1);
    let mut at: Vec<usize> = (0..longest).step_by(stride).collect();
    if at.last() != Some(&(longest - 1)) {
        at.push(longest - 1);
    }
    at.into_iter()
        .filter_map(|i| {
            let values: Vec<f64> = runs
                .iter()
                .filter_map(|r| average_at(r, i, window))
                .collect();
            point(label, (i + window) as u64, i, values)
        })
        .collect()
}

/// The `i`-th value of the moving average of `window` over `values`, if it has one: the
/// mean of `values[i..i + window]`, summed in order as [`moving_average`](super::moving_average) sums
/// it.
pub fn average_at(values: &[f64], i: usize, window: usize) -> Option<f64> {
    let w = values.get(i..i.checked_add(window)?)?;
    Some(w.iter().sum::<f64>() / window as f64)
}

/// The header and rows of `sample_efficiency.csv`: one row per method, point and
/// statistic (`iqm`, `mean`); `unit` (`episode` or `step`) names the points' column.
pub fn records(
    curves: &[(String, Vec<EfficiencyPoint>)],
    unit: &str,
) -> (Vec<String>, Vec<Vec<String>>) {
    let header = ["method", unit, "runs", "statistic", "value", "lo", "hi"]
        .map(String::from)
        .to_vec();
    let mut rows = Vec::new();
    for (label, points) in curves {
        for p in points {
            for (statistic, e) in [("iqm", p.iqm), ("mean", p.mean)] {
                rows.push(vec![
                    label.clone(),
                    p.at.to_string(),
                    p.runs.to_string(),
                    statistic.to_string(),
                    format!("{:?}", e.point),
                    format!("{:?}", e.lo),
                    format!("{:?}", e.hi),
                ]);
            }
        }
    }
    (header, rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four runs by hand, window 2: the MA2s of each run, at episode 2 and 3, are
    /// 1.5, 2.5 / 10.5, 11.5 / 20.5, 21.5 / 30.5, 31.5. The IQM of four values is the
    /// mean of the middle two.
    #[test]
    fn each_point_is_the_iqm_and_mean_of_the_runs_moving_averages() {
        let runs = vec![
            vec![1.0, 2.0, 3.0],
            vec![10.0, 11.0, 12.0],
            vec![20.0, 21.0, 22.0],
            vec![30.0, 31.0, 32.0],
        ];
        let points = curve("m", &episodes(&runs), 2, Budget::Episodes(3));
        assert_eq!(points.len(), 2);
        assert_eq!((points[0].at, points[0].runs), (2, 4));
        assert_eq!(points[0].iqm.point, (10.5 + 20.5) / 2.0);
        assert_eq!(points[0].mean.point, (1.5 + 10.5 + 20.5 + 30.5) / 4.0);
        assert_eq!(points[1].at, 3);
        assert_eq!(points[1].mean.point, (2.5 + 11.5 + 21.5 + 31.5) / 4.0);
        for p in &points {
            for e in [p.iqm, p.mean] {
                assert!(e.lo <= e.point && e.point <= e.hi, "{e:?}");
                assert!(e.lo >= 1.5 && e.hi <= 31.5, "within the runs: {e:?}");
            }
        }
    }

    #[test]
    fn a_long_run_is_thinned_to_the_points_with_its_last_episode() {
        let runs = vec![vec![1.0; 5000], vec![2.0; 4000]];
        let points = curve("m", &episodes(&runs), 10, Budget::Episodes(5000));
        assert!(points.len() <= POINTS + 1, "{}", points.len());
        assert_eq!(points.last().unwrap().at, 5000);
        // Past episode 4000 only the longer run is left.
        assert_eq!(points.last().unwrap().runs, 1);
        assert_eq!(points[0].runs, 2);
    }

    #[test]
    fn the_average_at_a_point_is_the_moving_averages_value_there() {
        let values: Vec<f64> = (0..50).map(|i| (i as f64 * 0.37).sin() * 100.0).collect();
        for window in [1, 3, 10, 50, 51] {
            let whole = crate::report::moving_average(&values, window);
            for i in 0..60 {
                assert_eq!(average_at(&values, i, window), whole.get(i).copied());
            }
        }
        assert_eq!(average_at(&values, usize::MAX, 2), None);
    }

    fn episodes(returns: &[Vec<f64>]) -> Vec<TrainingEpisodes> {
        returns
            .iter()
            .map(|r| {
                let mut run = TrainingEpisodes::default();
                r.iter().for_each(|&x| run.push(x, 10));
                run
            })
            .collect()
    }

    /// Two runs of 10-step episodes, one of returns 1, 2, 3, 4, one of 5, 6 whose third
    /// episode was still going at the budget, under a budget of 40 steps at 200 points (one
    /// a step), window 2: at step 20 the MA2s are 1.5 and 5.5; at step 40, 3.5 and still
    /// 5.5 (the last episodes ended by then).
    #[test]
    fn under_a_step_budget_the_points_are_steps() {
        let runs = episodes(&[vec![1.0, 2.0, 3.0, 4.0], vec![5.0, 6.0]]);
        let points = curve("m", &runs, 2, Budget::Steps(40));
        assert_eq!(
            points.len(),
            31,
            "steps 10 to 40: none before an episode ended"
        );
        assert_eq!((points[0].at, points[0].runs), (10, 2));
        let at20 = points.iter().find(|p| p.at == 20).unwrap();
        assert_eq!(at20.mean.point, (1.5 + 5.5) / 2.0);
        let last = points.last().unwrap();
        assert_eq!(
            (last.at, last.runs, last.mean.point),
            (40, 2, (3.5 + 5.5) / 2.0)
        );
        let (header, _) = records(&[("m".into(), points)], "step");
        assert_eq!(header[1], "step");
    }

    #[test]
    fn the_csv_has_a_row_per_statistic() {
        let runs = episodes(&[vec![1.0, 2.0], vec![3.0, 4.0]]);
        let points = curve("sapnet", &runs, 1, Budget::Episodes(2));
        let (header, rows) = records(&[("sapnet".into(), points)], "episode");
        assert_eq!(header[1..4], ["episode", "runs", "statistic"]);
        assert_eq!(rows.len(), 4);
        assert_eq!(rows[0][..4], ["sapnet", "1", "2", "iqm"]);
        assert_eq!(rows[1][3], "mean");
    }
}
