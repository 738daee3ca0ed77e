//! The report of runs sapnet did not train — `sapnet compare`'s runs of other tools — from
//! what each run scored: its training return and its final score, on one task whose range
//! of returns the caller fixes. Every measure, pair and plot is then made as for a
//! protocol's own runs; the final score stands where a protocol's greedy test score does
//! (the method's kind says so: [`crate::reuse::Tested::LastEpisodes`]).

use super::{MethodRuns, Report, RunScores, TestScore, Units};
use crate::reuse::MethodKind;
use crate::stats::Scores;

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
    use crate::reuse::Tested;

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
