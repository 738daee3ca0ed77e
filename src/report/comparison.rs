//! The methods side by side: `comparison.csv` and the table printed at the end of a run.
//!
//! Per method, over its runs ([`super::scores`]), each with a 95% stratified bootstrap
//! interval ([`crate::stats`]): the greedy test score and the training return as mean,
//! median, interquartile mean (IQM) and optimality gap; per threshold of the moving
//! average, the share of runs that reached it (Wilson interval) and the median episode at
//! which they did, runs that never did counted as beyond the end (censored). On one task
//! the scores are in the task's returns; pooled over several tasks, normalised to [0, 1].
//! For methods that reuse the library: each source's share of the acting steps, the
//! library rank (1 = the best recorded score) of each run's chosen or most-used source,
//! and when one source first held P > 0.99.

use std::fmt::Write as _;

use serde::Serialize;

use super::runs::LibraryEntry;
use super::{MethodRuns, TestScore, Units};
use crate::reuse::{lock_in, MethodKind};
use crate::seeds::{self, Part};
use crate::stats::{aggregate, bootstrap, proportion, Estimate, Scores};

/// One method's measures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodComparison {
    pub method: String,
    pub kind: MethodKind,
    pub runs: usize,
    /// What its runs hand over to be tested ([`crate::reuse::Tested`]).
    pub tested: &'static str,
    /// What the thresholds are reached at: `episode`, or `step` under a step budget.
    pub unit: &'static str,
    /// Per threshold of the moving average (one task only: tasks have their own levels).
    pub thresholds: Vec<ThresholdReached>,
    /// The training return: mean over episodes (or, under a step budget, the step curve's
    /// area), aggregated over runs.
    pub training: Option<Aggregates>,
    /// Under a step budget, the step curve's last point, aggregated over runs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_score: Option<Aggregates>,
    /// What each run was given: its environment steps of training (mean over runs), and
    /// gradient updates per environment step (over all its runs); `None` for runs of other
    /// tools.
    pub env_steps: Option<f64>,
    pub updates_per_step: Option<f64>,
    /// For a method with a learner of its own, the share of a run's steps whose action was
    /// not its learner's greedy action (its exploration, and what the library changed),
    /// mean over runs with its 95% interval.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub non_greedy_share: Option<Estimate>,
    /// The greedy test score: mean over a run's test episodes, aggregated over runs.
    pub test: Option<Aggregates>,
    /// The sample standard deviation of the runs' test scores.
    pub test_std: Option<f64>,
    /// Share of the acting steps (after the warm-up) taken by each source, over all runs.
    pub source_shares: Vec<f64>,
    /// The same shares summed per source task, in the library's task order, for a library
    /// over several tasks (empty otherwise): does a method learn to avoid a harmful task?
    pub task_shares: Vec<(String, f64)>,
    /// Per run, the library rank (1 = best recorded score) of the chosen source, or of the
    /// most-used one for a method whose result is its own learner.
    pub ranks: Vec<usize>,
    /// Steps at which one source first held P > 0.99, median over the runs where it did,
    /// and how many did.
    pub lock_in_median: Option<f64>,
    pub locked_runs: usize,
    /// Whether the method picks by probabilities, so that lock-in is measured at all.
    pub lock_in_measured: bool,
}

/// A score aggregated over runs, each with its 95% interval. The optimality gap is of the
/// normalised scores (how far below the task's best return, on [0, 1]), whatever the units
/// of the rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Aggregates {
    pub mean: Estimate,
    pub median: Estimate,
    pub iqm: Estimate,
    pub optimality_gap: Estimate,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThresholdReached {
    pub threshold: f64,
    /// The median episode (or step) at which the moving average first reached the
    /// threshold, runs that never did counted as beyond their end; `None` when half or more never
    /// did. `lo` and `hi` bound it (`hi` is `None` when the interval reaches past the end).
    pub median_episode: Option<f64>,
    pub median_lo: Option<f64>,
    pub median_hi: Option<f64>,
    /// Runs that reached it, and that share with its Wilson interval.
    pub reached: usize,
    pub share: Estimate,
}

/// The measures of every method.
pub(super) fn compare(methods: &[MethodRuns], units: Units) -> Vec<MethodComparison> {
    methods.iter().map(|m| measures(m, units)).collect()
}

fn measures(m: &MethodRuns, units: Units) -> MethodComparison {
    let seed = |what: &str| {
        seeds::derive(
            0,
            &[
                Part::Name("bootstrap"),
                Part::Name(&m.label),
                Part::Name(what),
            ],
        )
    };
    let aggregates = |scores: &Option<(Scores, Scores)>, what: &str| {
        scores.as_ref().map(|(shown, normalised)| {
            let shown = match units {
                Units::Returns => shown,
                Units::Normalised => normalised,
            };
            Aggregates {
                mean: bootstrap::interval(shown, aggregate::mean, seed(&format!("{what} mean"))),
                median: bootstrap::interval(
                    shown,
                    aggregate::median,
                    seed(&format!("{what} median")),
                ),
                iqm: bootstrap::interval(shown, aggregate::iqm, seed(&format!("{what} iqm"))),
                optimality_gap: bootstrap::interval(
                    normalised,
                    aggregate::optimality_gap,
                    seed(&format!("{what} gap")),
                ),
            }
        })
    };
    let thresholds = m
        .reached
        .iter()
        .map(|(threshold, episodes)| {
            reached(*threshold, episodes, seed(&format!("reached {threshold}")))
        })
        .collect();
    let tests = m
        .test
        .as_ref()
        .map(|(raw, _)| raw.pooled())
        .unwrap_or_default();
    let steps: u64 = m.steps.iter().sum();
    MethodComparison {
        method: m.label.clone(),
        kind: m.kind,
        runs: m.runs,
        tested: m.kind.tested.name(),
        unit: m.unit,
        thresholds,
        training: aggregates(&m.training, "training"),
        final_score: aggregates(&m.final_return, "final"),
        env_steps: (!m.steps.is_empty()).then(|| steps as f64 / m.steps.len() as f64),
        updates_per_step: (m.updates.len() == m.steps.len() && steps > 0)
            .then(|| m.updates.iter().sum::<u64>() as f64 / steps as f64),
        non_greedy_share: Scores::one_task(m.non_greedy.clone())
            .map(|s| bootstrap::interval(&s, aggregate::mean, seed("non-greedy mean"))),
        test: aggregates(&m.test, "test"),
        test_std: std_dev(&tests),
        source_shares: m.source_shares.clone(),
        task_shares: m.task_shares.clone(),
        ranks: m.ranks.clone(),
        // A step recorded for a method lock-in means nothing for (the oracle's probability
        // of 1 passes 0.99 at its first step) is not a lock-in.
        lock_in_median: lock_in::measured(m.kind)
            .then(|| median(&m.lock_in_steps))
            .flatten(),
        locked_runs: if lock_in::measured(m.kind) {
            m.lock_in_steps.len()
        } else {
            0
        },
        lock_in_measured: lock_in::measured(m.kind),
    }
}

/// The threshold's measures from each run's episode of reaching it (infinite: never).
fn reached(threshold: f64, episodes: &[f64], seed: u64) -> ThresholdReached {
    let hits = episodes.iter().filter(|e| e.is_finite()).count();
    let finite = |x: f64| x.is_finite().then_some(x);
    let (median_episode, median_lo, median_hi) = match Scores::one_task(episodes.to_vec()) {
        Some(scores) => {
            let e = bootstrap::interval(&scores, aggregate::median, seed);
            (finite(e.point), finite(e.lo), finite(e.hi))
        }
        None => (None, None, None),
    };
    ThresholdReached {
        threshold,
        median_episode,
        median_lo,
        median_hi,
        reached: hits,
        share: proportion::wilson(hits, episodes.len()).unwrap_or(Estimate {
            point: 0.0,
            lo: 0.0,
            hi: 1.0,
        }),
    }
}

/// The library's task labels, each once, in the order the sources list them.
pub(super) fn library_tasks(library: &[LibraryEntry]) -> Vec<String> {
    let mut tasks: Vec<String> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for entry in library {
        if seen.insert(entry.task.as_str()) {
            tasks.push(entry.task.clone());
        }
    }
    tasks
}

/// Rank of each source by recorded score, 1 for the best (ties share the better rank;
/// unscored sources rank last).
pub(super) fn library_ranks(library: &[LibraryEntry]) -> Vec<usize> {
    let score = |e: &LibraryEntry| e.final_score.unwrap_or(f64::NEG_INFINITY);
    // 1 + the sources scored higher, counted in the scores sorted best first: O(n log n),
    // for a library of any length a folder lists.
    let mut best_first: Vec<f64> = library.iter().map(score).collect();
    best_first.sort_by(|a, b| b.total_cmp(a));
    library
        .iter()
        .map(|e| 1 + best_first.partition_point(|&o| o > score(e)))
        .collect()
}

/// The source that acted most steps (the first listed, on a tie), if any acted.
pub fn most_used(steps: &[u64]) -> Option<usize> {
    let most = *steps.iter().max()?;
    (most > 0).then(|| steps.iter().position(|&s| s == most).unwrap_or(0))
}

/// The sample standard deviation (n − 1); 0 for one value, `None` for none.
fn std_dev(values: &[f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    if values.len() < 2 {
        return Some(0.0);
    }
    let m = aggregate::mean(values);
    let ss: f64 = values.iter().map(|v| (v - m).powi(2)).sum();
    Some((ss / (values.len() - 1) as f64).sqrt())
}

/// A count of steps as a table shows it: `950`, `304k`, `1.50M`.
fn steps_count(steps: f64) -> String {
    if steps >= 999_500.0 {
        format!("{:.2}M", steps / 1e6)
    } else if steps >= 10_000.0 {
        format!("{:.0}k", steps / 1e3)
    } else {
        format!("{steps:.0}")
    }
}

fn median(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| aggregate::median(values))
}

fn cell(x: Option<f64>) -> String {
    x.map_or(String::new(), |v| format!("{v:?}"))
}

/// The header and the rows of `comparison.csv`. The columns a script looks for are named
/// `<score>_<aggregate>[_lo|_hi]`: `test_iqm`, `test_iqm_lo`, `return_mean_hi`, … (`return`
/// is the training return, `final` under a step budget the curve's last point), `units`
/// saying whether they are returns or normalised; per threshold `episodes_to_<t>` (or
/// `steps_to_<t>`: the censored median) with `_lo`/`_hi`, `reached_<t>` (a count) and
/// `reached_<t>_share` with `_lo`/`_hi`; `env_steps` (per run) and `updates_per_step`, what
/// each method was given.
pub fn csv_records(rows: &[MethodComparison], units: Units) -> (Vec<String>, Vec<Vec<String>>) {
    let mut header: Vec<String> = vec!["method".into(), "runs".into(), "tested".into()];
    if let Some(first) = rows.first() {
        let unit = first.unit;
        for t in &first.thresholds {
            let t = t.threshold;
            header.extend([
                format!("{unit}s_to_{t}"),
                format!("{unit}s_to_{t}_lo"),
                format!("{unit}s_to_{t}_hi"),
                format!("reached_{t}"),
                format!("reached_{t}_share"),
                format!("reached_{t}_share_lo"),
                format!("reached_{t}_share_hi"),
            ]);
        }
    }
    header.push("units".into());
    let finals = rows.iter().any(|r| r.final_score.is_some());
    let scores: &[&str] = if finals {
        &["return", "final", "test"]
    } else {
        &["return", "test"]
    };
    for score in scores {
        for aggregate in ["mean", "median", "iqm", "optimality_gap"] {
            for end in ["", "_lo", "_hi"] {
                header.push(format!("{score}_{aggregate}{end}"));
            }
        }
    }
    header.extend(
        [
            "mean_return",
            "test_std",
            "ranks",
            "lock_in_median_step",
            "locked_runs",
            "source_shares",
            "env_steps",
            "updates_per_step",
            "non_greedy_share",
            "non_greedy_share_lo",
            "non_greedy_share_hi",
        ]
        .map(String::from),
    );
    let tasks = share_tasks(rows);
    header.extend(tasks.iter().map(|t| format!("share_{t}")));
    let mut records = Vec::new();
    for row in rows {
        let mut record = vec![row.method.clone(), row.runs.to_string(), row.tested.into()];
        for t in &row.thresholds {
            record.extend([
                cell(t.median_episode),
                cell(t.median_lo),
                cell(t.median_hi),
                t.reached.to_string(),
                cell(Some(t.share.point)),
                cell(Some(t.share.lo)),
                cell(Some(t.share.hi)),
            ]);
        }
        record.push(units.name().into());
        let scores = if finals {
            vec![&row.training, &row.final_score, &row.test]
        } else {
            vec![&row.training, &row.test]
        };
        for score in scores {
            for e in aggregates(score.as_ref()) {
                record.extend([
                    cell(e.map(|e| e.point)),
                    cell(e.map(|e| e.lo)),
                    cell(e.map(|e| e.hi)),
                ]);
            }
        }
        let ranks: Vec<String> = row.ranks.iter().map(ToString::to_string).collect();
        let shares: Vec<String> = row
            .source_shares
            .iter()
            .map(|s| format!("{s:.4}"))
            .collect();
        record.extend([
            cell(row.training.map(|a| a.mean.point)),
            cell(row.test_std),
            ranks.join(" "),
            // Empty, as the table's `-`, for a method lock-in means nothing for.
            cell(row.lock_in_median),
            if row.lock_in_measured {
                row.locked_runs.to_string()
            } else {
                String::new()
            },
            shares.join(" "),
            cell(row.env_steps),
            cell(row.updates_per_step),
            cell(row.non_greedy_share.map(|e| e.point)),
            cell(row.non_greedy_share.map(|e| e.lo)),
            cell(row.non_greedy_share.map(|e| e.hi)),
        ]);
        for task in &tasks {
            let share = row.task_shares.iter().find(|(t, _)| t == task);
            record.push(share.map_or(String::new(), |(_, s)| format!("{s:.4}")));
        }
        records.push(record);
    }
    (header, records)
}

fn aggregates(a: Option<&Aggregates>) -> [Option<Estimate>; 4] {
    match a {
        Some(a) => [
            Some(a.mean),
            Some(a.median),
            Some(a.iqm),
            Some(a.optimality_gap),
        ],
        None => [None; 4],
    }
}

fn share_tasks(rows: &[MethodComparison]) -> Vec<String> {
    rows.iter()
        .find(|r| !r.task_shares.is_empty())
        .map(|r| r.task_shares.iter().map(|(t, _)| t.clone()).collect())
        .unwrap_or_default()
}

/// An aggregate over `runs` runs as a view shows it: with its interval, or for one run
/// its value alone (`195.3 (1 run)`): a bootstrap of one value is no interval.
pub fn interval_of_runs(e: &Estimate, runs: usize, digits: usize) -> String {
    if runs <= 1 {
        format!("{:.digits$} (1 run)", e.point)
    } else {
        interval(e, digits)
    }
}

/// An interval as the table shows it: `123.4 [100.2, 140.0]`, with `digits` decimals.
pub fn interval(e: &Estimate, digits: usize) -> String {
    format!(
        "{:.digits$} [{:.digits$}, {:.digits$}]",
        e.point, e.lo, e.hi
    )
}

/// The comparison as a plain-text table, for stdout: IQMs with their 95% intervals.
pub fn table(rows: &[MethodComparison], units: Units, test_score: TestScore) -> String {
    let digits = units.digits();
    let mut header = vec!["method".to_string(), "runs".to_string()];
    if let Some(first) = rows.first() {
        let arrow = if first.unit == "step" {
            "steps→"
        } else {
            "ep→"
        };
        for t in &first.thresholds {
            header.push(format!("{arrow}{}", t.threshold));
        }
    }
    let finals = rows.iter().any(|r| r.final_score.is_some());
    header.push(if finals {
        "return AUC IQM [95% CI]".to_string()
    } else {
        "return IQM [95% CI]".to_string()
    });
    if finals {
        header.push("final IQM [95% CI]".to_string());
    }
    header.extend([
        format!("{} IQM [95% CI]", test_score.short()),
        "tested".to_string(),
        "steps/run".to_string(),
        "upd/step".to_string(),
        "ranks".to_string(),
        "lock-in step".to_string(),
    ]);
    let tasks = share_tasks(rows);
    if !tasks.is_empty() {
        header.push("% steps by task".into());
    }
    let mut lines = vec![header];
    for row in rows {
        let mut line = vec![row.method.clone(), row.runs.to_string()];
        for t in &row.thresholds {
            line.push(match t.median_episode {
                Some(e) => format!("{e:.0} ({}/{})", t.reached, row.runs),
                None => format!("- ({}/{})", t.reached, row.runs),
            });
        }
        let scores = if finals {
            vec![&row.training, &row.final_score, &row.test]
        } else {
            vec![&row.training, &row.test]
        };
        for score in scores {
            line.push(score.map_or("-".into(), |a| interval(&a.iqm, digits)));
        }
        // A test score is the method and its handover rule together: said beside it.
        line.push(row.tested.to_string());
        line.push(row.env_steps.map_or("-".into(), steps_count));
        line.push(
            row.updates_per_step
                .map_or("-".into(), |u| format!("{u:.2}")),
        );
        let ranks: Vec<String> = row.ranks.iter().map(ToString::to_string).collect();
        line.push(if ranks.is_empty() {
            "-".into()
        } else {
            ranks.join(" ")
        });
        line.push(lock_in::over_runs(
            row.lock_in_measured,
            row.lock_in_median,
            row.locked_runs,
            row.runs,
        ));
        if !tasks.is_empty() {
            let shares: Vec<String> = row
                .task_shares
                .iter()
                .map(|(_, s)| format!("{:.0}", s * 100.0))
                .collect();
            line.push(if shares.is_empty() {
                "-".into()
            } else {
                shares.join(" ")
            });
        }
        lines.push(line);
    }
    let widths: Vec<usize> = (0..lines[0].len())
        .map(|c| {
            lines
                .iter()
                .map(|l| l[c].chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    for line in &lines {
        let cells: Vec<String> = line
            .iter()
            .zip(&widths)
            .map(|(text, &w)| format!("{text:<w$}"))
            .collect();
        let _ = writeln!(out, "{}", cells.join("  ").trim_end());
    }
    if !tasks.is_empty() {
        let _ = writeln!(out, "% steps by task, in order: {}", tasks.join(", "));
    }
    if units == Units::Normalised {
        let _ = writeln!(
            out,
            "scores normalised to [0, 1] by each task's range of returns, pooled over tasks"
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranks_put_the_best_score_first_and_unscored_last() {
        let entry = |s: Option<f64>| LibraryEntry {
            name: String::new(),
            hidden: vec![],
            task: String::new(),
            activation: String::new(),
            final_score: s,
        };
        let library = [
            entry(Some(10.0)),
            entry(Some(500.0)),
            entry(None),
            entry(Some(10.0)),
        ];
        assert_eq!(library_ranks(&library), [2, 1, 4, 2]);
        // The definition, counted pair by pair, on a library with ties and unscored
        // sources: the sorted count agrees.
        let library: Vec<LibraryEntry> = (0..2_000_u32)
            .map(|i| entry((i % 7 != 0).then_some(f64::from((i * 7919) % 301))))
            .collect();
        let score = |e: &LibraryEntry| e.final_score.unwrap_or(f64::NEG_INFINITY);
        let by_pairs: Vec<usize> = library
            .iter()
            .map(|e| 1 + library.iter().filter(|o| score(o) > score(e)).count())
            .collect();
        assert_eq!(library_ranks(&library), by_pairs);
        assert_eq!(most_used(&[0, 5, 5]), Some(1));
        assert_eq!(most_used(&[0, 0]), None);
    }

    #[test]
    fn the_censored_median_counts_runs_that_never_reached_it_as_beyond_the_end() {
        let never = f64::INFINITY;
        // Reached at 100, 300, 200; two never: sorted 100, 200, 300, ∞, ∞ → 300.
        let t = reached(195.0, &[100.0, never, 300.0, 200.0, never], 1);
        assert_eq!(t.median_episode, Some(300.0));
        assert_eq!(t.reached, 3);
        assert_eq!(t.share.point, 0.6);
        // Dropping the runs that never reached it would have said 200.
        // Three of five never: the median is beyond the end.
        let t = reached(195.0, &[100.0, never, never, 200.0, never], 1);
        assert_eq!(t.median_episode, None);
        assert_eq!(t.median_hi, None);
        assert_eq!(t.reached, 2);
    }

    #[test]
    fn statistics_by_hand() {
        // mean 2, squares 1 + 0 + 1 → variance 2/2 = 1.
        assert_eq!(std_dev(&[1.0, 2.0, 3.0]), Some(1.0));
        assert_eq!(std_dev(&[5.0]), Some(0.0));
        assert_eq!(std_dev(&[]), None);
        assert_eq!(median(&[]), None);
    }
}
