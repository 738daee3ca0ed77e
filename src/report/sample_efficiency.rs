//! Sample-efficiency curves, as openrlbenchmark draws them: at every point of training, the
//! interquartile mean (and the mean) over runs of each run's moving average, with its 95%
//! bootstrap interval over the runs ([`crate::stats::bootstrap`], the resampling checked
//! against rliable). `sample_efficiency.csv` holds the points, `sample_efficiency.png`
//! draws the IQM.

use crate::report::runs::moving_average;
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
    /// The episode the moving averages end at.
    pub episode: usize,
    /// Runs that reach it (a stopped run is shorter).
    pub runs: usize,
    pub iqm: Estimate,
    pub mean: Estimate,
}

/// The curve of `label`'s runs (each run's returns, episode 1 first) under a moving average
/// of `window` episodes: from the `window`-th episode on, at most [`POINTS`] episodes
/// evenly spaced, the last always included.
pub fn curve(label: &str, runs: &[Vec<f64>], window: usize) -> Vec<EfficiencyPoint> {
    let window = window.max(1);
    let averages: Vec<Vec<f64>> = runs.iter().map(|r| moving_average(r, window)).collect();
    let longest = averages.iter().map(Vec::len).max().unwrap_or(0);
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
            let values: Vec<f64> = averages.iter().filter_map(|a| a.get(i).copied()).collect();
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
            Some(EfficiencyPoint {
                episode: i + window,
                runs,
                iqm: bootstrap::interval_of(&scores, aggregate::iqm, RESAMPLES, seed("iqm")),
                mean: bootstrap::interval_of(&scores, aggregate::mean, RESAMPLES, seed("mean")),
            })
        })
        .collect()
}

/// The header and rows of `sample_efficiency.csv`: one row per method, episode and
/// statistic (`iqm`, `mean`).
pub fn records(curves: &[(String, Vec<EfficiencyPoint>)]) -> (Vec<String>, Vec<Vec<String>>) {
    let header = [
        "method",
        "episode",
        "runs",
        "statistic",
        "value",
        "lo",
        "hi",
    ]
    .map(String::from)
    .to_vec();
    let mut rows = Vec::new();
    for (label, points) in curves {
        for p in points {
            for (statistic, e) in [("iqm", p.iqm), ("mean", p.mean)] {
                rows.push(vec![
                    label.clone(),
                    p.episode.to_string(),
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
        let points = curve("m", &runs, 2);
        assert_eq!(points.len(), 2);
        assert_eq!((points[0].episode, points[0].runs), (2, 4));
        assert_eq!(points[0].iqm.point, (10.5 + 20.5) / 2.0);
        assert_eq!(points[0].mean.point, (1.5 + 10.5 + 20.5 + 30.5) / 4.0);
        assert_eq!(points[1].episode, 3);
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
        let points = curve("m", &runs, 10);
        assert!(points.len() <= POINTS + 1, "{}", points.len());
        assert_eq!(points.last().unwrap().episode, 5000);
        // Past episode 4000 only the longer run is left.
        assert_eq!(points.last().unwrap().runs, 1);
        assert_eq!(points[0].runs, 2);
    }

    #[test]
    fn the_csv_has_a_row_per_statistic() {
        let points = curve("sapnet", &[vec![1.0, 2.0], vec![3.0, 4.0]], 1);
        let (header, rows) = records(&[("sapnet".into(), points)]);
        assert_eq!(header[3], "statistic");
        assert_eq!(rows.len(), 4);
        assert_eq!(rows[0][..4], ["sapnet", "1", "2", "iqm"]);
        assert_eq!(rows[1][3], "mean");
    }
}
