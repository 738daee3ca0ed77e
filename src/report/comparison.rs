//! The methods side by side: `comparison.csv` and the table printed at the end of a run.
//!
//! Per method, over its runs: episodes until the moving average of returns first reached
//! each threshold (median over the runs that reached it, and how many did), the mean
//! return over the whole run (the area under the learning curve per episode), the greedy
//! test mean ± std over runs (of each run's mean); and for methods that reuse the library:
//! each source's share of the acting steps, the library rank (1 = the best recorded score)
//! of each run's chosen or most-used source, and when one source first held P > 0.99.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;

use super::runs::{moving_average, LibraryEntry, RunSummary};
use crate::config::Config;
use crate::trainer::MethodId;

/// One method's measures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodComparison {
    pub method: String,
    pub runs: usize,
    /// Per threshold of the moving average: (threshold, median episode over the runs that
    /// reached it, runs that reached it).
    pub thresholds: Vec<ThresholdReached>,
    /// Mean training return per episode, mean over runs.
    pub mean_return: Option<f64>,
    /// Greedy test return: mean and standard deviation over the tested runs' means.
    pub test_mean: Option<f64>,
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

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThresholdReached {
    pub threshold: f64,
    pub median_episode: Option<f64>,
    pub reached: usize,
}

/// The measures of every method of `config`, from the finished runs and their returns.
pub fn compare(
    config: &Config,
    library: &[LibraryEntry],
    runs: &[RunSummary],
    rewards: &BTreeMap<(MethodId, u32), Vec<f64>>,
) -> Vec<MethodComparison> {
    let thresholds = config.protocol.thresholds(&config.env);
    let window = config.protocol.moving_average;
    let ranks = library_ranks(library);
    let tasks = library_tasks(library);
    let mut out = Vec::new();
    for method in crate::experiment::method_ids(config) {
        let mine: Vec<&RunSummary> = runs.iter().filter(|r| r.record.method == method).collect();
        if mine.is_empty() {
            continue;
        }
        let curves: Vec<&Vec<f64>> = mine
            .iter()
            .filter_map(|r| rewards.get(&(method.clone(), r.record.run)))
            .collect();
        let thresholds = thresholds
            .iter()
            .map(|&threshold| {
                let episodes: Vec<f64> = curves
                    .iter()
                    .filter_map(|returns| {
                        moving_average(returns, window)
                            .iter()
                            .position(|&a| a >= threshold)
                            .map(|i| (i + window) as f64)
                    })
                    .collect();
                ThresholdReached {
                    threshold,
                    median_episode: median(&episodes),
                    reached: episodes.len(),
                }
            })
            .collect();
        let run_means: Vec<f64> = curves
            .iter()
            .filter(|c| !c.is_empty())
            .map(|c| c.iter().sum::<f64>() / c.len() as f64)
            .collect();
        let tests: Vec<f64> = mine.iter().filter_map(|r| r.mean_test_return).collect();
        let steps: Vec<u64> = mine.iter().fold(Vec::new(), |mut total, r| {
            total.resize(r.record.source_steps.len().max(total.len()), 0);
            for (t, s) in total.iter_mut().zip(&r.record.source_steps) {
                *t += s;
            }
            total
        });
        let all: u64 = steps.iter().sum();
        let source_shares = if all == 0 {
            Vec::new()
        } else {
            steps.iter().map(|&s| s as f64 / all as f64).collect()
        };
        let task_shares = if tasks.len() > 1 && !source_shares.is_empty() {
            tasks
                .iter()
                .map(|task| {
                    let share = library
                        .iter()
                        .zip(&source_shares)
                        .filter(|(entry, _)| &entry.task == task)
                        .map(|(_, s)| s)
                        .sum::<f64>();
                    (task.clone(), share)
                })
                .collect()
        } else {
            Vec::new()
        };
        let ranks = mine
            .iter()
            .filter_map(|r| {
                let index = match &r.record.chosen {
                    Some(chosen) => chosen.index,
                    None => most_used(&r.record.source_steps)?,
                };
                ranks.get(index).copied()
            })
            .collect();
        let locks: Vec<f64> = mine
            .iter()
            .filter_map(|r| r.record.lock_in_step.map(|s| s as f64))
            .collect();
        out.push(MethodComparison {
            method: method.label().to_string(),
            runs: mine.len(),
            thresholds,
            mean_return: mean(&run_means),
            test_mean: mean(&tests),
            test_std: std_dev(&tests),
            source_shares,
            task_shares,
            ranks,
            lock_in_median: median(&locks),
            locked_runs: locks.len(),
            lock_in_measured: method.kind.picks_by_probability(),
        });
    }
    out
}

/// The library's task labels, each once, in the order the sources list them.
fn library_tasks(library: &[LibraryEntry]) -> Vec<String> {
    let mut tasks: Vec<String> = Vec::new();
    for entry in library {
        if !tasks.contains(&entry.task) {
            tasks.push(entry.task.clone());
        }
    }
    tasks
}

/// Rank of each source by recorded score, 1 for the best (ties share the better rank;
/// unscored sources rank last).
fn library_ranks(library: &[LibraryEntry]) -> Vec<usize> {
    let score = |e: &LibraryEntry| e.final_score.unwrap_or(f64::NEG_INFINITY);
    library
        .iter()
        .map(|e| 1 + library.iter().filter(|o| score(o) > score(e)).count())
        .collect()
}

fn most_used(steps: &[u64]) -> Option<usize> {
    let most = *steps.iter().max()?;
    (most > 0).then(|| steps.iter().position(|&s| s == most).unwrap_or(0))
}

fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// The sample standard deviation (n − 1); 0 for one value.
fn std_dev(values: &[f64]) -> Option<f64> {
    let m = mean(values)?;
    if values.len() < 2 {
        return Some(0.0);
    }
    let ss: f64 = values.iter().map(|v| (v - m).powi(2)).sum();
    Some((ss / (values.len() - 1) as f64).sqrt())
}

fn median(values: &[f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    Some(if n % 2 == 1 {
        sorted[n / 2]
    } else {
        (sorted[n / 2 - 1] + sorted[n / 2]) / 2.0
    })
}

fn cell(x: Option<f64>) -> String {
    x.map_or(String::new(), |v| format!("{v:?}"))
}

/// Writes `comparison.csv`: one row per method; the columns named by threshold and source.
pub fn write_csv(path: &Path, rows: &[MethodComparison]) -> Result<()> {
    let mut csv =
        csv::Writer::from_path(path).with_context(|| format!("creating {}", path.display()))?;
    let (header, records) = csv_records(rows);
    csv.write_record(&header)
        .with_context(|| format!("writing {}", path.display()))?;
    for record in records {
        csv.write_record(&record)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    csv.flush()
        .with_context(|| format!("writing {}", path.display()))
}

/// The header and the rows of `comparison.csv`.
pub fn csv_records(rows: &[MethodComparison]) -> (Vec<String>, Vec<Vec<String>>) {
    let mut header: Vec<String> = vec!["method".into(), "runs".into()];
    if let Some(first) = rows.first() {
        for t in &first.thresholds {
            header.push(format!("episodes_to_{}", t.threshold));
            header.push(format!("reached_{}", t.threshold));
        }
    }
    header.extend(
        [
            "mean_return",
            "test_mean",
            "test_std",
            "ranks",
            "lock_in_median_step",
            "locked_runs",
            "source_shares",
        ]
        .map(String::from),
    );
    let tasks: Vec<String> = rows
        .iter()
        .find(|r| !r.task_shares.is_empty())
        .map(|r| r.task_shares.iter().map(|(t, _)| t.clone()).collect())
        .unwrap_or_default();
    header.extend(tasks.iter().map(|t| format!("share_{t}")));
    let mut records = Vec::new();
    for row in rows {
        let mut record = vec![row.method.clone(), row.runs.to_string()];
        for t in &row.thresholds {
            record.push(cell(t.median_episode));
            record.push(t.reached.to_string());
        }
        let ranks: Vec<String> = row.ranks.iter().map(ToString::to_string).collect();
        let shares: Vec<String> = row
            .source_shares
            .iter()
            .map(|s| format!("{s:.4}"))
            .collect();
        record.extend([
            cell(row.mean_return),
            cell(row.test_mean),
            cell(row.test_std),
            ranks.join(" "),
            cell(row.lock_in_median),
            row.locked_runs.to_string(),
            shares.join(" "),
        ]);
        for task in &tasks {
            let share = row.task_shares.iter().find(|(t, _)| t == task);
            record.push(share.map_or(String::new(), |(_, s)| format!("{s:.4}")));
        }
        records.push(record);
    }
    (header, records)
}

/// The comparison as a plain-text table, for stdout.
pub fn table(rows: &[MethodComparison]) -> String {
    let mut header = vec!["method".to_string(), "runs".to_string()];
    if let Some(first) = rows.first() {
        for t in &first.thresholds {
            header.push(format!("ep→{}", t.threshold));
        }
    }
    header.extend(["mean return", "test mean ± std", "ranks", "lock-in step"].map(String::from));
    let tasks: Vec<String> = rows
        .iter()
        .find(|r| !r.task_shares.is_empty())
        .map(|r| r.task_shares.iter().map(|(t, _)| t.clone()).collect())
        .unwrap_or_default();
    if !tasks.is_empty() {
        header.push("% steps by task".into());
    }
    let mut lines = vec![header];
    for row in rows {
        let mut line = vec![row.method.clone(), row.runs.to_string()];
        for t in &row.thresholds {
            line.push(match t.median_episode {
                Some(e) => format!("{e:.0} ({}/{})", t.reached, row.runs),
                None => format!("- (0/{})", row.runs),
            });
        }
        line.push(row.mean_return.map_or("-".into(), |m| format!("{m:.1}")));
        line.push(match (row.test_mean, row.test_std) {
            (Some(m), Some(s)) => format!("{m:.1} ± {s:.1}"),
            _ => "-".into(),
        });
        let ranks: Vec<String> = row.ranks.iter().map(ToString::to_string).collect();
        line.push(if ranks.is_empty() {
            "-".into()
        } else {
            ranks.join(" ")
        });
        line.push(match row.lock_in_median {
            Some(s) => format!("{s:.0} ({}/{})", row.locked_runs, row.runs),
            None if !row.lock_in_measured => "-".into(),
            None => format!("never (0/{})", row.runs),
        });
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
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_by_hand() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        // mean 2, squares 1 + 0 + 1 → variance 2/2 = 1.
        assert_eq!(std_dev(&[1.0, 2.0, 3.0]), Some(1.0));
        assert_eq!(std_dev(&[5.0]), Some(0.0));
    }

    #[test]
    fn ranks_put_the_best_score_first_and_unscored_last() {
        let entry = |s: Option<f64>| LibraryEntry {
            name: String::new(),
            hidden: vec![],
            task: String::new(),
            final_score: s,
        };
        let library = [
            entry(Some(10.0)),
            entry(Some(500.0)),
            entry(None),
            entry(Some(10.0)),
        ];
        assert_eq!(library_ranks(&library), [2, 1, 4, 2]);
        assert_eq!(most_used(&[0, 5, 5]), Some(1));
        assert_eq!(most_used(&[0, 0]), None);
    }

    #[test]
    fn steps_are_summed_per_source_task_in_the_librarys_order() {
        let entry = |task: &str| LibraryEntry {
            name: String::new(),
            hidden: vec![4],
            task: task.into(),
            final_score: Some(1.0),
        };
        let library = [entry("long"), entry("mirrored"), entry("long")];
        let config = Config::from_ron("(protocol: (methods: [Ucb1], runs: 1))", "t.ron").unwrap();
        let method = crate::experiment::method_ids(&config)[0].clone();
        let record = crate::trainer::RunRecord {
            run: 0,
            method: method.clone(),
            seed: 0,
            episodes: 1,
            steps: 10,
            updates: 0,
            chosen: None,
            // 2 + 6 steps on the long poles, 2 mirrored.
            source_steps: vec![2, 2, 6],
            lock_in_step: None,
            test_returns: vec![],
            stopped: false,
            wall_s: 0.0,
        };
        let runs = [RunSummary::new(record, &[1.0], 1)];
        let rewards = BTreeMap::from([((method, 0), vec![1.0])]);
        let rows = compare(&config, &library, &runs, &rewards);
        assert_eq!(
            rows[0].task_shares,
            [("long".to_string(), 0.8), ("mirrored".to_string(), 0.2)]
        );
        let table = table(&rows);
        assert!(table.contains("% steps by task"), "{table}");
        assert!(table.contains("80 20"), "{table}");
        assert!(
            table.ends_with("% steps by task, in order: long, mirrored\n"),
            "{table}"
        );
    }
}
