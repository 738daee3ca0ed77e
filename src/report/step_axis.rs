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
/// episode ended.
pub fn curve(run: &TrainingEpisodes, window: usize, points: &[u64]) -> Vec<Option<f64>> {
    means_at(&run.returns, &run.ends(), window, points)
}

/// The same curve of any per-episode `values` whose episodes end at `ends` (ascending, on
/// any axis: steps, episodes, seconds): at each of `points`, the mean of the last `window`
/// values whose episodes ended by it, or of all that did while fewer have.
pub fn means_at<X: PartialOrd + Copy>(
    values: &[f64],
    ends: &[X],
    window: usize,
    points: &[X],
) -> Vec<Option<f64>> {
    let window = window.max(1);
    // sums[i] = Σ values[..i], for every window's mean in O(1).
    let sums: Vec<f64> = std::iter::once(0.0)
        .chain(values.iter().scan(0.0, |sum, &r| {
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

    #[test]
    fn a_threshold_is_reached_where_its_windows_last_episode_ended() {
        let r = run(&[(10.0, 10), (20.0, 20), (30.0, 30), (40.0, 40)]);
        // MA2: 15, 25, 35 → 25 first over episodes 2–3, which ended at step 60.
        assert_eq!(step_reached(&r, 2, 25.0), Some(60));
        assert_eq!(step_reached(&r, 2, 15.0), Some(30));
        assert_eq!(step_reached(&r, 2, 36.0), None);
    }
}
