//! Any per-episode metric a results folder records, read across runs on any x axis, as
//! TensorBoard and W&B draw a scalar: each run's values smoothed by a moving average, and
//! at each point of the axis the IQM and mean over the runs with their 95% bootstrap
//! intervals ([`sample_efficiency::over_runs`]). A run's value at a point is the mean of
//! its last `window` values whose episodes ended by it ([`step_axis::means_at`], the step
//! axis's rule on every axis), so an episode without a value (no loss in the warm-up, no
//! activation before the selector runs) is left out, never drawn as a zero.
//!
//! The metrics are numbers per episode. The source acting in an episode (`episodes.csv`'s
//! `policy`) is a category, not a metric: it is not drawn as a line here (the Run view and
//! `selections.png` show it).

use super::sample_efficiency::{self, EfficiencyPoint};
use super::step_axis;
use crate::stats::Estimate;

/// A per-episode number of a run's files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Metric {
    /// The episode's undiscounted return (`episodes.csv`'s `reward`).
    Return,
    /// Its length in environment steps (`steps`).
    Length,
    /// The DQN's mean TD loss over the episode's updates (`loss`; none before learning).
    Loss,
    /// SAP-Net's statistic loss E at the episode's end (`statistic_loss`, Algorithm 3).
    StatisticLoss,
    /// The exploration rate at the episode's end (`epsilon`).
    Epsilon,
    /// Environment steps per second of wall time over the episode (`steps` over the
    /// difference of `wall_s`).
    StepsPerSecond,
    /// The selector's score of the library's source at this place (`activations.csv`'s
    /// `A_<name>`: SAP-Net's activation, UCB's mean, PRQ-learning's W).
    Activation(usize),
    /// The probability of picking that source next (`P_<name>`).
    Probability(usize),
}

impl Metric {
    /// As a title or legend names it; `sources` names the library's sources.
    pub fn name(self, sources: &[String]) -> String {
        let source = |i: usize| sources.get(i).map_or("?", String::as_str).to_string();
        match self {
            Metric::Return => "return".into(),
            Metric::Length => "length".into(),
            Metric::Loss => "TD loss".into(),
            Metric::StatisticLoss => "statistic loss E".into(),
            Metric::Epsilon => "ε".into(),
            Metric::StepsPerSecond => "steps/s".into(),
            Metric::Activation(i) => format!("A[{}]", source(i)),
            Metric::Probability(i) => format!("P[{}]", source(i)),
        }
    }

    /// Decimals its values are shown with.
    pub fn digits(self) -> usize {
        match self {
            Metric::Return | Metric::Length => 1,
            Metric::StepsPerSecond => 0,
            Metric::Epsilon | Metric::Activation(_) | Metric::Probability(_) => 3,
            Metric::Loss | Metric::StatisticLoss => 4,
        }
    }
}

/// What the curves are drawn against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum XAxis {
    /// The episode's number, from 1.
    Episode,
    /// The environment step the episode ended at.
    Step,
    /// The seconds of training when the episode ended (`wall_s`).
    Wall,
}

impl XAxis {
    /// As the axis's label says it.
    pub fn name(self) -> &'static str {
        match self {
            XAxis::Episode => "episode",
            XAxis::Step => "step",
            XAxis::Wall => "wall s",
        }
    }

    /// As a title's range says it (`ep 100–200`).
    pub fn short(self) -> &'static str {
        match self {
            XAxis::Episode => "ep",
            XAxis::Step => "step",
            XAxis::Wall => "s",
        }
    }
}

/// One run's values of a metric, one per episode (`None` where the episode has none),
/// and where its episodes end on each axis.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunMetric {
    pub values: Vec<Option<f64>>,
    /// Each episode's length in steps.
    pub lengths: Vec<u32>,
    /// Each episode's end in seconds of training, where the files hold it.
    pub wall_s: Option<Vec<f64>>,
}

impl RunMetric {
    /// Where each episode ends on `axis`; `None` for wall time the files do not hold.
    pub fn ends(&self, axis: XAxis) -> Option<Vec<f64>> {
        match axis {
            XAxis::Episode => Some((1..=self.lengths.len()).map(|e| e as f64).collect()),
            XAxis::Step => Some(
                self.lengths
                    .iter()
                    .scan(0.0, |steps, &l| {
                        *steps += f64::from(l);
                        Some(*steps)
                    })
                    .collect(),
            ),
            XAxis::Wall => self.wall_s.clone(),
        }
    }

    /// Its curve at `points` (ascending, on `axis`): the mean of its last `window`
    /// values whose episodes ended by each ([`step_axis::means_at`]).
    pub fn curve(&self, axis: XAxis, window: usize, points: &[f64]) -> Vec<Option<f64>> {
        let Some(ends) = self.ends(axis) else {
            return vec![None; points.len()];
        };
        let episodes = ends
            .iter()
            .zip(&self.values)
            .filter_map(|(&end, v)| Some(((*v)?, end)));
        step_axis::means_at(episodes, window, points)
    }
}

/// A point of a curve over runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// Where on the x axis.
    pub at: f64,
    /// Runs with a value there.
    pub runs: usize,
    pub iqm: Estimate,
    pub mean: Estimate,
}

impl From<EfficiencyPoint> for CurvePoint {
    fn from(p: EfficiencyPoint) -> Self {
        Self {
            at: p.at as f64,
            runs: p.runs,
            iqm: p.iqm,
            mean: p.mean,
        }
    }
}

/// `count` points evenly spaced from `from` to `to`, both included (one if they meet).
pub fn grid(from: f64, to: f64, count: usize) -> Vec<f64> {
    if to.partial_cmp(&from) != Some(std::cmp::Ordering::Greater) || count < 2 {
        return vec![to];
    }
    (0..count)
        .map(|k| from + (to - from) * k as f64 / (count - 1) as f64)
        .collect()
}

/// Where the runs' episodes end on `axis`, first to last over every run: the axis's
/// extent.
pub fn extent<'a>(
    runs: impl IntoIterator<Item = &'a RunMetric>,
    axis: XAxis,
) -> Option<(f64, f64)> {
    let mut extent: Option<(f64, f64)> = None;
    for run in runs {
        let Some(ends) = run.ends(axis) else { continue };
        if let (Some(&first), Some(&last)) = (ends.first(), ends.last()) {
            extent = Some(match extent {
                Some((lo, hi)) => (lo.min(first), hi.max(last)),
                None => (first, last),
            });
        }
    }
    extent
}

/// `label`'s curve of its `runs`' values at `points` on `axis`, each run smoothed over
/// `window` values: at each point with a value of some run, the IQM and mean over those
/// runs with their 95% intervals.
pub fn curve(
    label: &str,
    runs: &[RunMetric],
    axis: XAxis,
    window: usize,
    points: &[f64],
) -> Vec<CurvePoint> {
    let curves: Vec<Vec<Option<f64>>> =
        runs.iter().map(|r| r.curve(axis, window, points)).collect();
    points
        .iter()
        .enumerate()
        .filter_map(|(i, &at)| {
            let values: Vec<f64> = curves.iter().filter_map(|c| c[i]).collect();
            let (runs, iqm, mean) = sample_efficiency::over_runs(label, i, values)?;
            Some(CurvePoint {
                at,
                runs,
                iqm,
                mean,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(values: &[Option<f64>], lengths: &[u32], wall: Option<&[f64]>) -> RunMetric {
        RunMetric {
            values: values.to_vec(),
            lengths: lengths.to_vec(),
            wall_s: wall.map(<[f64]>::to_vec),
        }
    }

    /// Losses of episodes 1–4: none in the warm-up (episode 1), then 0.4, 0.2, 0.6; the
    /// episodes end at steps 10, 30, 60, 100 and seconds 1, 2, 4, 8. Window 2: at episode
    /// 1 nothing; at 2: 0.4; at 3: (0.4 + 0.2)/2 = 0.3; at 4: (0.2 + 0.6)/2 = 0.4. On the
    /// step axis at 59 episode 3 has not ended: 0.4; at 60, 0.3. On the wall axis at 4 s:
    /// 0.3.
    #[test]
    fn a_missing_value_is_left_out_not_taken_for_zero() {
        let r = run(
            &[None, Some(0.4), Some(0.2), Some(0.6)],
            &[10, 20, 30, 40],
            Some(&[1.0, 2.0, 4.0, 8.0]),
        );
        let at = |axis, points: &[f64]| r.curve(axis, 2, points);
        let close = |got: Vec<Option<f64>>, want: &[Option<f64>]| {
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(want) {
                match (g, w) {
                    (Some(g), Some(w)) => assert!((g - w).abs() < 1e-12, "{got:?}"),
                    _ => assert_eq!(g, w, "{got:?}"),
                }
            }
        };
        close(
            at(XAxis::Episode, &[1.0, 2.0, 3.0, 4.0]),
            &[None, Some(0.4), Some(0.3), Some(0.4)],
        );
        close(
            at(XAxis::Step, &[10.0, 59.0, 60.0, 100.0]),
            &[None, Some(0.4), Some(0.3), Some(0.4)],
        );
        close(at(XAxis::Wall, &[4.0]), &[Some(0.3)]);
        assert_eq!(
            run(&[Some(1.0)], &[5], None).curve(XAxis::Wall, 2, &[1.0]),
            [None]
        );
        assert_eq!(extent([&r], XAxis::Step), Some((10.0, 100.0)));
    }

    #[test]
    fn the_returns_on_the_step_axis_are_the_reports_step_curve() {
        let r = run(
            &[Some(10.0), Some(20.0), Some(30.0), Some(40.0)],
            &[10, 20, 30, 40],
            None,
        );
        let mut episodes = super::super::TrainingEpisodes::default();
        for (v, l) in [(10.0, 10), (20.0, 20), (30.0, 30), (40.0, 40)] {
            episodes.push(v, l);
        }
        let steps = [5u64, 30, 59, 60, 100];
        let points: Vec<f64> = steps.iter().map(|&s| s as f64).collect();
        assert_eq!(
            r.curve(XAxis::Step, 2, &points),
            step_axis::curve(&episodes, 2, &steps)
        );
        assert_eq!(grid(0.0, 10.0, 3), [0.0, 5.0, 10.0]);
        assert_eq!(grid(4.0, 4.0, 3), [4.0]);
    }
}
