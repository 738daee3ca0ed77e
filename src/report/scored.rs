//! The report of runs sapnet did not train — `sapnet compare`'s runs of other tools — from
//! what each run scored: its training return and its final score, on one task whose range
//! of returns the caller fixes. Every measure, pair and plot is then made as for a
//! protocol's own runs; the final score stands where a protocol's greedy test score does
//! (the method's kind says so: [`crate::reuse::Tested::LastEpisodes`]).
//!
//! [`compare_report`] scores each run under compare's [`Scoring`] and makes the report:
//! `sapnet compare` writes its files by it, and `sapnet open` shows a compare folder by it,
//! from the runs the folder recorded ([`crate::outside_runs::compare_folder`]), so that
//! what the workbench shows is what the folder's CSV files hold.

use std::num::NonZeroUsize;

use super::{sample_efficiency, step_axis, MethodRuns, Report, RunScores, TestScore, Units};
use crate::config::Budget;
use crate::outside_runs::compare_folder::{Alignment, Scoring};
use crate::outside_runs::OutsideRun;
use crate::reuse::{MethodKind, Tested};
use crate::stats::episodes::TrainingEpisodes;
use crate::stats::Scores;

/// A run's episodes as compare scores them: an outside run as read, or as a compare folder
/// recorded it.
#[derive(Debug, Clone, Copy)]
pub struct RunEpisodes<'a> {
    pub episodes: &'a TrainingEpisodes,
    /// Whether every episode's length is known (else those not given are 0): a step axis
    /// needs each one.
    pub lengths_known: bool,
    /// The environment steps its file says it took by its last episode's end.
    pub steps: Option<u64>,
}

impl<'a> RunEpisodes<'a> {
    pub fn of(run: &'a OutsideRun) -> Self {
        Self {
            episodes: &run.episodes,
            lengths_known: run.lengths_known,
            steps: run.steps(),
        }
    }

    /// The training return by episode: the plain mean of every episode's return, as
    /// sapnet scores its own runs (`RunScores::of` in `report/scores.rs`: the sum of the
    /// training returns over their count, the area under the learning curve per episode).
    /// No moving average enters it: sapnet's window only smooths the curves and places the
    /// episode at which a threshold was reached.
    pub fn training_return(&self) -> f64 {
        let returns = &self.episodes.returns;
        // A run has at least one episode (reading refuses an empty one).
        returns.iter().sum::<f64>() / returns.len() as f64
    }

    /// The mean return of the last `k` episodes, or of all of them if the run has fewer.
    pub fn final_score(&self, k: NonZeroUsize) -> f64 {
        let returns = &self.episodes.returns;
        let last = &returns[returns.len().saturating_sub(k.get())..];
        last.iter().sum::<f64>() / last.len() as f64
    }
}

/// compare's alignment as the budget its curves and step scores are read under.
pub fn budget(alignment: Alignment) -> Budget {
    match alignment {
        Alignment::Steps(n) => Budget::Steps(n),
        // A compare folder's episodes are bounded far below u32::MAX.
        Alignment::Episodes(n) => Budget::Episodes(u32::try_from(n).unwrap_or(u32::MAX)),
    }
}

/// `budget` as compare records its alignment.
pub fn alignment(budget: Budget) -> Alignment {
    match budget {
        Budget::Steps(n) => Alignment::Steps(n),
        Budget::Episodes(n) => Alignment::Episodes(u64::from(n)),
    }
}

/// What `run` scored under `scoring`: by episode, its mean return and the mean of its last
/// episodes; by step (chosen only when every run's lengths are known), its step curve's
/// area and the curve at the budget.
pub fn score(run: RunEpisodes, scoring: &Scoring) -> ScoredRun {
    match scoring.alignment {
        Alignment::Episodes(_) => ScoredRun {
            training_return: run.training_return(),
            final_score: run.final_score(scoring.last),
            episodes: run.episodes.len(),
            steps: run.steps,
        },
        Alignment::Steps(budget) => {
            let episodes = run.episodes;
            let points = step_axis::points(budget, sample_efficiency::POINTS);
            let curve = step_axis::curve(episodes, scoring.window, &points);
            ScoredRun {
                // Every run has an episode ended by the budget: compare and the compare
                // folder's reader refuse a budget before one's first episode ends.
                training_return: step_axis::area(&curve).unwrap_or(f64::NAN),
                final_score: step_axis::curve(episodes, scoring.last.get(), &[budget])[0]
                    .unwrap_or(f64::NAN),
                episodes: step_axis::ended_by(episodes, budget),
                steps: Some(budget),
            }
        }
    }
}

/// Each of `count` methods from elsewhere a family of its own, its hue a golden angle from
/// the last: methods from elsewhere are not variants of one another.
pub fn outside_kinds(count: usize) -> Vec<MethodKind> {
    (0..count)
        .map(|i| MethodKind {
            family: "Outside",
            hue: ((i as f64 * 137.508 + 210.0) % 360.0) as u16,
            saturation: 65,
            reuses: false,
            tested: Tested::LastEpisodes,
            picks_by_probability: false,
            spreads: false,
        })
        .collect()
}

/// The report of `methods` (each a name and its runs) scored under `scoring`, with what
/// each run scored: the report `sapnet compare` writes, and the one `sapnet open` shows
/// of the folder it wrote.
pub fn compare_report(
    scoring: &Scoring,
    methods: &[(&str, Vec<RunEpisodes>)],
) -> (Vec<ScoredMethod>, Report) {
    let scored: Vec<ScoredMethod> = methods
        .iter()
        .zip(outside_kinds(methods.len()))
        .map(|((name, runs), kind)| ScoredMethod {
            label: name.to_string(),
            kind,
            runs: runs.iter().map(|&r| score(r, scoring)).collect(),
        })
        .collect();
    let report = Report::of_scored(&scoring.task, scoring.range, scoring.last.get(), &scored);
    (scored, report)
}

/// One method's runs, as scored elsewhere.
#[derive(Debug, Clone)]
pub struct ScoredMethod {
    pub label: String,
    pub kind: MethodKind,
    pub runs: Vec<ScoredRun>,
}

/// What one run scored.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScoredRun {
    /// The mean return over all its episodes.
    pub training_return: f64,
    /// The mean return of its last episodes.
    pub final_score: f64,
    pub episodes: usize,
    /// The environment steps its episodes took, when the file says (a monitor file's
    /// lengths, a step column).
    pub steps: Option<u64>,
}

impl Report {
    /// The report of `methods` on `task`, in the task's returns, normalised (for the
    /// optimality gap and the profiles) by `range`. A method without runs is left out.
    /// `last`: the episodes each run's final score is the mean of.
    pub fn of_scored(task: &str, range: (f64, f64), last: usize, methods: &[ScoredMethod]) -> Self {
        let mut scores = Vec::new();
        let mut measured = Vec::new();
        let mut left_out = Vec::new();
        for method in methods {
            let Some(runs) = method_runs(method, range) else {
                left_out.push(method.label.clone());
                continue;
            };
            scores.extend(method.runs.iter().enumerate().map(|(r, run)| RunScores {
                method: method.label.clone(),
                run: r as u32,
                task: task.to_string(),
                test: Some(run.final_score),
                training_return: Some(run.training_return),
                final_return: None,
                episodes: run.episodes,
                steps: run.steps.unwrap_or(0),
                updates: 0,
                unit: "episode",
                reached: Vec::new(),
            }));
            measured.push(runs);
        }
        let mut report = Self::of_methods(
            Units::Returns,
            (vec![task.to_string()], vec![task.to_string()]),
            &measured,
            scores,
            left_out,
        );
        report.test_score = TestScore::LastEpisodes(last);
        report
    }
}

fn method_runs(method: &ScoredMethod, range: (f64, f64)) -> Option<MethodRuns> {
    let both = |pick: fn(&ScoredRun) -> f64| {
        let shown: Vec<f64> = method.runs.iter().map(pick).collect();
        let normalised = shown
            .iter()
            .map(|&x| super::scores::normalise(x, range))
            .collect();
        Some((Scores::one_task(shown)?, Scores::one_task(normalised)?))
    };
    Some(MethodRuns {
        label: method.label.clone(),
        kind: method.kind,
        runs: method.runs.len(),
        test: Some(both(|r| r.final_score)?),
        training: Some(both(|r| r.training_return)?),
        final_return: None,
        unit: "episode",
        reached: Vec::new(),
        // What each run was given, where every run's file says (its updates never).
        steps: method
            .runs
            .iter()
            .map(|r| r.steps)
            .collect::<Option<Vec<u64>>>()
            .unwrap_or_default(),
        updates: Vec::new(),
        non_greedy: Vec::new(),
        source_shares: Vec::new(),
        task_shares: Vec::new(),
        ranks: Vec::new(),
        lock_in_steps: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_training_return_is_the_mean_of_every_episode_as_sapnet_scores_its_own() {
        // sapnet's own scores test: (10 + 30 + 50 + 70 + 20 + 20) / 6 = 200 / 6.
        let episodes = TrainingEpisodes::uniform(&[10.0, 30.0, 50.0, 70.0, 20.0, 20.0], 0);
        let r = RunEpisodes {
            episodes: &episodes,
            lengths_known: false,
            steps: None,
        };
        assert_eq!(r.training_return(), 200.0 / 6.0);
        let k = |k| NonZeroUsize::new(k).unwrap();
        // The last two: (20 + 20) / 2; the last four: (50 + 70 + 20 + 20) / 4 = 40.
        assert_eq!(r.final_score(k(2)), 20.0);
        assert_eq!(r.final_score(k(4)), 40.0);
        // More than the run has: all of them.
        assert_eq!(r.final_score(k(100)), r.training_return());
    }

    fn kind() -> MethodKind {
        MethodKind {
            family: "Outside",
            hue: 200,
            saturation: 60,
            reuses: false,
            tested: Tested::LastEpisodes,
            picks_by_probability: false,
            spreads: false,
        }
    }

    fn method(label: &str, returns: &[f64]) -> ScoredMethod {
        ScoredMethod {
            label: label.into(),
            kind: kind(),
            runs: returns
                .iter()
                .map(|&r| ScoredRun {
                    training_return: r,
                    final_score: 2.0 * r,
                    episodes: 10,
                    steps: None,
                })
                .collect(),
        }
    }

    #[test]
    fn each_run_is_scored_and_every_pair_compared() {
        let report = Report::of_scored(
            "CartPole-v1",
            (0.0, 500.0),
            20,
            &[
                method("a", &[10.0, 20.0, 30.0, 40.0]),
                method("b", &[100.0, 200.0, 300.0, 400.0]),
                method("none", &[]),
            ],
        );
        assert_eq!(report.left_out, ["none"]);
        assert_eq!(report.scores.len(), 8);
        assert_eq!(report.scores[1].training_return, Some(20.0));
        assert_eq!(report.scores[1].test, Some(40.0));
        let a = &report.comparison[0];
        // The mean of 10, 20, 30, 40; its optimality gap on [0, 500]: 1 − 25/500.
        let training = a.training.unwrap();
        assert_eq!(training.mean.point, 25.0);
        assert!((training.optimality_gap.point - 0.95).abs() < 1e-12);
        assert_eq!(a.tested, "last-episodes");
        // b's every run above a's: P(b > a) = 1 for both scores, in both directions' rows.
        let b_over_a: Vec<f64> = report
            .improvement
            .iter()
            .filter(|i| i.method == "b" && i.over == "a")
            .map(|i| i.p.point)
            .collect();
        assert_eq!(b_over_a, [1.0, 1.0]);
        assert_eq!(report.reference.as_deref(), Some("a"));
        assert_eq!(report.test_score, TestScore::LastEpisodes(20));
        assert!(report.table().contains("final IQM [95% CI]"));
    }
}
