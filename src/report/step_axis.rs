//! A run read against the environment steps it took, for a protocol whose budget is in
//! steps ([`Budget::Steps`](crate::config::Budget)): every method was given the same
//! transitions, so its learning is read where rliable, openrlbenchmark and the zoos read
//! it, at fixed points of the step axis, and never per episode (a method that balances the
//! pole longer would be given more data per episode).
//!
//! - the **curve** at each point: the mean return of the last `window` episodes ended by
//!   that step (of all of them while fewer have ended, as Stable-Baselines3 logs
//!   `rollout/ep_rew_mean`);
//! - the **training score**: the curve's mean over the points, its area per step;
//! - the **final score**: the curve's last point, at the budget;
//! - a **threshold** is reached at the step whose episode completed the first full window
//!   of `window` episodes whose mean reached it.
//!
//! A run holds its last value up to the budget (the episode the budget cut never ended); a
//! run stopped early would hold it too, which is why reports leave stopped runs out.

use super::runs::TrainingEpisodes;

/// The `count` points, evenly spaced, of a budget of `budget` steps, the budget itself the
/// last: `⌈budget·k/count⌉` for k = 1 … count (fewer when the budget is shorter).
pub fn points(budget: u64, count: usize) -> Vec<u64> {
    let count = (count as u64).clamp(1, budget.max(1));
    let mut points: Vec<u64> = (1..=count)
        .map(|k| (u128::from(budget) * u128::from(k)).div_ceil(u128::from(count)) as u64)
        .collect();
    points.dedup();
    points
}

/// The run's curve at `points` (ascending): at each, the mean return of the last `window`
/// episodes that ended by it, or of all that did while fewer have; `None` before its first
/// episode ended. One pass over the episodes, keeping the last `window + 1` running sums:
/// a run of millions of episodes costs no vector of its length.
pub fn curve(run: &TrainingEpisodes, window: usize, points: &[u64]) -> Vec<Option<f64>> {
    let mut end = 0u64;
    let episodes = run.returns.iter().zip(&run.lengths).map(|(&r, &l)| {
        end += u64::from(l);
        (r, end)
    });
    means_at(episodes, window, points)
}

/// The same curve of any per-episode values, each with the end of its episode (ascending,
/// on any axis: steps, episodes, seconds): at each of `points` (ascending), the mean of the
/// last `window` values whose episodes ended by it, or of all that did while fewer have.
/// One pass, keeping the last `window + 1` running sums.
pub fn means_at<X: PartialOrd + Copy>(
    episodes: impl IntoIterator<Item = (f64, X)>,
    window: usize,
    points: &[X],
) -> Vec<Option<f64>> {
    let window = window.max(1);
    // sums[i % kept] = Σ values[..i] for the last `kept` values of i: every window's mean
    // in O(1), each sum added up in the episodes' order.
    let kept = window + 1;
    let mut sums = vec![0.0; kept];
    let mut sum = 0.0;
    let mut ended = 0;
    let mut episodes = episodes.into_iter().peekable();
    points
        .iter()
        .map(|&point| {
            while let Some(&(value, end)) = episodes.peek() {
                if end > point {
                    break;
                }
                sum += value;
                ended += 1;
                sums[ended % kept] = sum;
                episodes.next();
            }
            let first = ended.saturating_sub(window);
            (ended > 0).then(|| (sums[ended % kept] - sums[first % kept]) / (ended - first) as f64)
        })
        .collect()
}

/// How many of the run's episodes ended by step `step`.
pub fn ended_by(run: &TrainingEpisodes, step: u64) -> usize {
    let mut end = 0u64;
    run.lengths
        .iter()
        .take_while(|&&l| {
            end += u64::from(l);
            end <= step
        })
        .count()
}

/// The mean of the curve's points where it has a value: the area under it per step.
pub fn area(curve: &[Option<f64>]) -> Option<f64> {
    let values: Vec<f64> = curve.iter().flatten().copied().collect();
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// The step at which the mean of `window` consecutive episodes first reached `threshold`:
/// the end of the window's last episode. `None` if no full window did.
pub fn step_reached(run: &TrainingEpisodes, window: usize, threshold: f64) -> Option<u64> {
    let window = window.max(1);
    let averages = super::runs::moving_average(&run.returns, window);
    let first = averages.iter().position(|&a| a >= threshold)?;
    run.ends().get(first + window - 1).copied()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(episodes: &[(f64, u32)]) -> TrainingEpisodes {
        let mut run = TrainingEpisodes::default();
        for &(r, l) in episodes {
            run.push(r, l);
        }
        run
    }

    #[test]
    fn points_are_evenly_spaced_and_end_at_the_budget() {
        assert_eq!(points(1000, 4), [250, 500, 750, 1000]);
        assert_eq!(points(10, 3), [4, 7, 10]);
        // A budget shorter than the count: one point per step.
        assert_eq!(points(3, 200), [1, 2, 3]);
    }

    /// Episodes of returns 10, 20, 30, 40 ending at steps 10, 30, 60, 100; window 2.
    /// At step 5 none has ended; at 30: (10 + 20)/2 = 15; at 59 still 15; at 60: (20 + 30)/2
    /// = 25; at 100: (30 + 40)/2 = 35. Window 3 at step 10: only one ended: 10.
    #[test]
    fn each_point_is_the_mean_of_the_last_episodes_ended_by_it() {
        let r = run(&[(10.0, 10), (20.0, 20), (30.0, 30), (40.0, 40)]);
        assert_eq!(
            curve(&r, 2, &[5, 30, 59, 60, 100]),
            [None, Some(15.0), Some(15.0), Some(25.0), Some(35.0)]
        );
        assert_eq!(curve(&r, 3, &[10]), [Some(10.0)]);
        // (15 + 15 + 25 + 35) / 4, the undefined point left out.
        assert_eq!(area(&curve(&r, 2, &[5, 30, 59, 60, 100])), Some(90.0 / 4.0));
        assert_eq!(area(&[None, None]), None);
    }

    /// The curve as first written, from every end and every running sum: the streaming
    /// one must give the same bits.
    fn curve_by_definition(
        run: &TrainingEpisodes,
        window: usize,
        points: &[u64],
    ) -> Vec<Option<f64>> {
        let ends = run.ends();
        let sums: Vec<f64> = std::iter::once(0.0)
            .chain(run.returns.iter().scan(0.0, |sum, &r| {
                *sum += r;
                Some(*sum)
            }))
            .collect();
        points
            .iter()
            .map(|&point| {
                let ended = ends.partition_point(|&end| end <= point);
                let first = ended.saturating_sub(window);
                (ended > 0).then(|| (sums[ended] - sums[first]) / (ended - first) as f64)
            })
            .collect()
    }

    #[test]
    fn the_streamed_curve_is_the_definitions_to_the_bit() {
        // Returns with fractions that round, lengths of 0 (an episode placed behind the
        // furthest), windows shorter and longer than the run.
        let mut r = TrainingEpisodes::default();
        let mut x = 0.1f64;
        for i in 0..3_000u32 {
            x = (x * 3.7 + 0.123).fract();
            r.push(
                x * 500.0 - 100.0,
                if i % 7 == 0 { 0 } else { 1 + (i * 31) % 400 },
            );
        }
        let total = r.steps();
        for window in [1, 2, 10, 100, 2_999, 3_000, 10_000] {
            for count in [1, 7, 200, 5_000] {
                let at = points(total + 1_000, count);
                assert_eq!(curve(&r, window, &at), curve_by_definition(&r, window, &at));
            }
        }
        for step in [0, 1, 399, total / 2, total, total + 1] {
            assert_eq!(
                ended_by(&r, step),
                r.ends().partition_point(|&end| end <= step)
            );
        }
    }

    #[test]
    fn a_threshold_is_reached_where_its_windows_last_episode_ended() {
        let r = run(&[(10.0, 10), (20.0, 20), (30.0, 30), (40.0, 40)]);
        // MA2: 15, 25, 35 → 25 first over episodes 2–3, which ended at step 60.
        assert_eq!(step_reached(&r, 2, 25.0), Some(60));
        assert_eq!(step_reached(&r, 2, 15.0), Some(30));
        assert_eq!(step_reached(&r, 2, 36.0), None);
    }
}
