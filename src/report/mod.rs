//! What a protocol's finished runs say, below both front ends. From the runs' records
//! ([`runs`]) come each run's scores ([`scores`]), the methods side by side with interval
//! estimates ([`comparison`]), the probability that one method beats another
//! ([`improvement`]) and the plots ([`plots`]). The headless protocol writes them into its
//! results folder, `sapnet plot` writes them again from the folder's files, `sweep merge`
//! per axis value and pooled over tasks, and the dashboard draws a finished protocol's
//! curves under the live ones.

pub mod comparison;
pub mod improvement;
pub mod metric;
pub mod plots;
pub mod runs;
pub mod sample_efficiency;
pub mod scored;
pub mod scores;
pub mod step_axis;

use std::path::Path;

use anyhow::{Context, Result};

use crate::config::Config;
use crate::reuse::{Method, MethodKind};
use crate::stats::{profile, Estimate, Scores};

pub use comparison::{Aggregates, MethodComparison, ThresholdReached};
pub use improvement::Improvement;
pub use plots::{write_all as write_plots, Curve, PlotData, SelectionHistory};
pub use runs::{moving_average, LibraryEntry, RunSummary, TrainingEpisodes, TrainingRuns};
pub use scores::RunScores;

/// Every file a report writes into a results folder (with the CSV files of the runs and
/// `summary.json`, what `--force` replaces).
pub const FILES: [&str; 14] = [
    "comparison.csv",
    "improvement.csv",
    "scores.csv",
    "intervals.png",
    "intervals.svg",
    "profiles.png",
    "profiles.svg",
    "improvement.png",
    "improvement.svg",
    "learning_curve.png",
    "learning_curve.svg",
    "tests.png",
    "activations.png",
    "selections.png",
];

/// The finished runs of one task: a protocol's results, or a sweep's cells on that task.
#[derive(Debug, Clone, Copy)]
pub struct TaskRuns<'a> {
    /// The task as results label it (`cartpole`, `cartpole(length=1.0)`).
    pub task: &'a str,
    pub config: &'a Config,
    pub library: &'a [LibraryEntry],
    pub runs: &'a [RunSummary],
    /// Each run's training episodes.
    pub episodes: &'a TrainingRuns,
}

/// What the aggregates of a report are in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    /// The task's own returns: a report on one task.
    Returns,
    /// Returns mapped to [0, 1] by each task's range: a report pooled over tasks.
    Normalised,
}

impl Units {
    /// As `comparison.csv`'s `units` column says it.
    pub fn name(self) -> &'static str {
        match self {
            Units::Returns => "return",
            Units::Normalised => "normalised",
        }
    }

    /// Decimals a table shows of an aggregate in these units: returns to a tenth,
    /// normalised scores (and optimality gaps, always normalised) to a thousandth.
    pub fn digits(self) -> usize {
        match self {
            Units::Returns => 1,
            Units::Normalised => 3,
        }
    }
}

/// What a report's `test` columns measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TestScore {
    /// The mean return of a run's greedy test episodes (sapnet's own runs).
    Greedy,
    /// The mean return of a run's last `k` training episodes (`sapnet compare`'s runs of
    /// other tools, which have no greedy test).
    LastEpisodes(usize),
}

impl TestScore {
    /// In a table's header: `test` or `final`.
    pub fn short(self) -> &'static str {
        match self {
            TestScore::Greedy => "test",
            TestScore::LastEpisodes(_) => "final",
        }
    }

    /// In a figure's title.
    pub fn long(self) -> String {
        match self {
            TestScore::Greedy => "greedy test score".into(),
            TestScore::LastEpisodes(k) => format!("final score (last {k} episodes)"),
        }
    }
}

/// A method's performance profile: the share of its runs whose normalised test score is
/// above each level ([`profile::levels`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    pub method: String,
    pub shares: Vec<Estimate>,
}

/// Everything a report says of a set of finished runs.
#[derive(Debug, Clone)]
pub struct Report {
    pub units: Units,
    /// The tasks pooled, in order.
    pub tasks: Vec<String>,
    /// The same tasks as the figures' titles name them ([`plots::task_title`]).
    pub task_titles: Vec<String>,
    pub comparison: Vec<MethodComparison>,
    /// What the comparison's and the pairs' `test` score is.
    pub test_score: TestScore,
    pub improvement: Vec<Improvement>,
    pub scores: Vec<RunScores>,
    pub profiles: Vec<Profile>,
    /// The method the probability-of-improvement plot compares the others with: SAP-Net
    /// as the paper specifies it when it ran, else the first method.
    pub reference: Option<String>,
    /// Methods left out of a pooled report because they did not run on every task.
    pub left_out: Vec<String>,
    /// What the report is about beyond its tasks, first in its plots' titles: a sweep's
    /// axis value. None from [`Report::of`].
    pub subject: Option<String>,
}

/// A method's runs gathered from every task: the scores the statistics take.
#[derive(Debug)]
pub(crate) struct MethodRuns {
    pub label: String,
    pub kind: MethodKind,
    pub runs: usize,
    /// Test scores, training returns and (step budgets) final returns per task, as (shown,
    /// normalised): shown in the task's returns on one task, normalised when pooled.
    pub test: Option<(Scores, Scores)>,
    pub training: Option<(Scores, Scores)>,
    pub final_return: Option<(Scores, Scores)>,
    /// What `reached` counts: `episode` or `step` (one task only).
    pub unit: &'static str,
    /// Per threshold (one task only): each run's episode (or step) of first reaching it,
    /// ∞ if never.
    pub reached: Vec<(f64, Vec<f64>)>,
    /// Each run's environment steps and gradient updates of training; empty for runs of
    /// other tools, whose updates are not known.
    pub steps: Vec<u64>,
    pub updates: Vec<u64>,
    /// Per run of a method with a learner of its own, the share of its steps whose action
    /// was not that learner's greedy action.
    pub non_greedy: Vec<f64>,
    pub source_shares: Vec<f64>,
    pub task_shares: Vec<(String, f64)>,
    pub ranks: Vec<usize>,
    pub lock_in_steps: Vec<f64>,
}

impl Report {
    /// The report of `tasks`' runs: in returns for one task, normalised and stratified by
    /// task for several.
    pub fn of(tasks: &[TaskRuns<'_>]) -> Self {
        let units = if tasks.len() == 1 {
            Units::Returns
        } else {
            Units::Normalised
        };
        let mut labels: Vec<(String, Method)> = Vec::new();
        for task in tasks {
            for method in &task.config.protocol.methods {
                if !labels.iter().any(|(l, _)| *l == method.label()) {
                    labels.push((method.label(), method.clone()));
                }
            }
        }
        let mut scores = Vec::new();
        let mut methods = Vec::new();
        let mut left_out = Vec::new();
        for (label, method) in &labels {
            let per_task: Vec<Vec<(&RunSummary, RunScores)>> =
                tasks.iter().map(|t| run_scores(t, label)).collect();
            if per_task.iter().any(Vec::is_empty) {
                left_out.push(label.clone());
                continue;
            }
            scores.extend(per_task.iter().flatten().map(|(_, s)| s.clone()));
            methods.push(method_runs(label, method.kind(), tasks, &per_task, units));
        }
        let titles = tasks
            .iter()
            .map(|t| plots::task_title(&t.config.env))
            .collect();
        let tasks: Vec<String> = tasks.iter().map(|t| t.task.to_string()).collect();
        Self::of_methods(units, (tasks, titles), &methods, scores, left_out)
    }

    /// The report of `methods`' runs on `tasks` (as results and as titles name them):
    /// every measure, pair and profile.
    pub(crate) fn of_methods(
        units: Units,
        (tasks, task_titles): (Vec<String>, Vec<String>),
        methods: &[MethodRuns],
        scores: Vec<RunScores>,
        left_out: Vec<String>,
    ) -> Self {
        let comparison = comparison::compare(methods, units);
        let improvement = improvement::every_pair(methods, &tasks);
        let levels = profile::levels();
        let profiles = methods
            .iter()
            .filter_map(|m| {
                let (_, normalised) = m.test.as_ref()?;
                let seed = crate::seeds::derive(
                    0,
                    &[
                        crate::seeds::Part::Name("profile"),
                        crate::seeds::Part::Name(&m.label),
                    ],
                );
                Some(Profile {
                    method: m.label.clone(),
                    shares: profile::profile(normalised, &levels, seed),
                })
            })
            .collect();
        let reference = methods
            .iter()
            .find(|m| m.label == Method::the_papers().label())
            .or_else(|| methods.first())
            .map(|m| m.label.clone());
        Self {
            units,
            tasks,
            task_titles,
            comparison,
            test_score: TestScore::Greedy,
            improvement,
            scores,
            profiles,
            reference,
            left_out,
            subject: None,
        }
    }

    /// Writes `comparison.csv`, `improvement.csv`, `scores.csv` and the interval plots
    /// (`intervals.png`, `profiles.png`, `improvement.png`, each with an `.svg`) into `dir`.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let (header, records) = comparison::csv_records(&self.comparison, self.units);
        write_rows(&dir.join("comparison.csv"), &header, &records)?;
        let (header, records) = improvement::records(&self.improvement, &self.tasks);
        write_rows(&dir.join("improvement.csv"), &header, &records)?;
        write_scores(&dir.join("scores.csv"), &self.scores)?;
        plots::write_intervals(dir, self)
    }

    /// The comparison as a table, for stdout, then the pairs of the training return (the
    /// headline score: test scores are not ranked) by the separation rule.
    pub fn table(&self) -> String {
        let mut text = comparison::table(&self.comparison, self.units, self.test_score);
        let pairs = improvement::verdicts(&self.improvement, "return");
        if !pairs.is_empty() {
            text.push('\n');
            text.push_str(&pairs);
        }
        text
    }
}

/// Each finished run of method `label` on `task`, with its scores. A run stopped before its
/// end is left out: its mean return is over fewer episodes and it has no test, so beside
/// finished runs it would be a different measurement (the closing table lists it apart).
fn run_scores<'a>(task: &TaskRuns<'a>, label: &str) -> Vec<(&'a RunSummary, RunScores)> {
    let protocol = &task.config.protocol;
    let thresholds = protocol.thresholds(&task.config.env);
    let none = TrainingEpisodes::default();
    task.runs
        .iter()
        .filter(|r| r.record.method.label() == label && !r.record.stopped)
        .map(|r| {
            let episodes = task
                .episodes
                .get(&(r.record.method.clone(), r.record.run))
                .map_or(&none, |e| e.as_ref());
            let scores = RunScores::of(
                r,
                task.task,
                episodes,
                &thresholds,
                protocol.moving_average,
                protocol.budget,
            );
            (r, scores)
        })
        .collect()
}

fn method_runs(
    label: &str,
    kind: MethodKind,
    tasks: &[TaskRuns<'_>],
    per_task: &[Vec<(&RunSummary, RunScores)>],
    units: Units,
) -> MethodRuns {
    let gather = |pick: &dyn Fn(&RunScores) -> Option<f64>| -> Option<(Scores, Scores)> {
        let mut shown = Vec::new();
        let mut normalised = Vec::new();
        for (task, runs) in tasks.iter().zip(per_task) {
            let range = task.config.env.return_range();
            let values: Vec<f64> = runs.iter().filter_map(|(_, s)| pick(s)).collect();
            normalised.push(
                values
                    .iter()
                    .map(|&x| scores::normalise(x, range))
                    .collect(),
            );
            shown.push(values);
        }
        let shown = match units {
            Units::Returns => Scores::per_task(shown)?,
            Units::Normalised => Scores::per_task(normalised.clone())?,
        };
        Some((shown, Scores::per_task(normalised)?))
    };
    let one_task = tasks.len() == 1;
    let unit = tasks[0].config.protocol.budget.unit();
    let reached = if one_task {
        let thresholds = tasks[0].config.protocol.thresholds(&tasks[0].config.env);
        thresholds
            .iter()
            .enumerate()
            .map(|(k, &t)| {
                let episodes = per_task[0]
                    .iter()
                    .map(|(_, s)| s.reached[k].1.map_or(f64::INFINITY, |at| at as f64))
                    .collect();
                (t, episodes)
            })
            .collect()
    } else {
        Vec::new()
    };
    let runs: Vec<&RunSummary> = per_task.iter().flatten().map(|(r, _)| *r).collect();
    let (source_shares, task_shares) = if one_task {
        shares(tasks[0].library, &runs)
    } else {
        (Vec::new(), Vec::new())
    };
    let ranks = tasks
        .iter()
        .zip(per_task)
        .flat_map(|(task, runs)| {
            let ranks = comparison::library_ranks(task.library);
            runs.iter()
                .filter_map(|(r, _)| {
                    let index = match &r.record.chosen {
                        Some(chosen) => chosen.index,
                        None => comparison::most_used(&r.record.source_steps)?,
                    };
                    ranks.get(index).copied()
                })
                .collect::<Vec<_>>()
        })
        .collect();
    MethodRuns {
        label: label.to_string(),
        kind,
        runs: runs.len(),
        test: gather(&|s| s.test),
        training: gather(&|s| s.training_return),
        final_return: gather(&|s| s.final_return),
        unit: if one_task { unit } else { "episode" },
        reached,
        steps: runs.iter().map(|r| r.record.steps).collect(),
        updates: runs.iter().map(|r| r.record.updates).collect(),
        non_greedy: runs
            .iter()
            .filter_map(|r| {
                let steps = r.record.steps.max(1) as f64;
                r.record.non_greedy_steps.map(|n| n as f64 / steps)
            })
            .collect(),
        source_shares,
        task_shares,
        ranks,
        lock_in_steps: runs
            .iter()
            .filter_map(|r| r.record.lock_in_step.map(|s| s as f64))
            .collect(),
    }
}

/// Each source's share of the runs' acting steps, and those shares summed per source task
/// for a library over several tasks.
fn shares(library: &[LibraryEntry], runs: &[&RunSummary]) -> (Vec<f64>, Vec<(String, f64)>) {
    let mut steps: Vec<u64> = Vec::new();
    for r in runs {
        steps.resize(r.record.source_steps.len().max(steps.len()), 0);
        for (t, s) in steps.iter_mut().zip(&r.record.source_steps) {
            *t += s;
        }
    }
    let all: u64 = steps.iter().sum();
    if all == 0 {
        return (Vec::new(), Vec::new());
    }
    let source_shares: Vec<f64> = steps.iter().map(|&s| s as f64 / all as f64).collect();
    let tasks = comparison::library_tasks(library);
    let task_shares = if tasks.len() > 1 {
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
    (source_shares, task_shares)
}

/// Writes a CSV file of `header` and `records` atomically: a kill or a full disk leaves
/// the old file or none, never a part of the new one.
pub fn write_rows(path: &Path, header: &[String], records: &[Vec<String>]) -> Result<()> {
    crate::safe_io::write_atomically(path, |out| {
        let mut csv = csv::Writer::from_writer(out);
        csv.write_record(header)?;
        for record in records {
            csv.write_record(record)?;
        }
        csv.flush()
    })
    .with_context(|| format!("writing {}", path.display()))
}

/// `scores.csv`: one row per run, `method, run, task, test, return, episodes` and, when
/// every task has the same thresholds, `episodes_to_<t>` per threshold (the episode whose
/// moving average first reached it; empty if none did: censored at `episodes`). Under a
/// step budget `return` is the step curve's area, `final` its last point, `steps` and
/// `updates` what the run was given, and the thresholds are `steps_to_<t>`.
fn write_scores(path: &Path, scores: &[RunScores]) -> Result<()> {
    let levels = |s: &RunScores| s.reached.iter().map(|(t, _)| *t).collect::<Vec<f64>>();
    let thresholds = match scores.first() {
        Some(first) if scores.iter().all(|s| levels(s) == levels(first)) => levels(first),
        _ => Vec::new(),
    };
    let steps = scores.iter().any(|s| s.unit == "step");
    let mut header: Vec<String> = ["method", "run", "task", "test", "return", "episodes"]
        .map(String::from)
        .to_vec();
    if steps {
        header.extend(["final", "steps", "updates"].map(String::from));
    }
    let unit = if steps { "steps" } else { "episodes" };
    header.extend(thresholds.iter().map(|t| format!("{unit}_to_{t}")));
    let records: Vec<Vec<String>> = scores
        .iter()
        .map(|s| {
            let number = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:?}"));
            let mut record = vec![
                s.method.clone(),
                s.run.to_string(),
                s.task.clone(),
                number(s.test),
                number(s.training_return),
                s.episodes.to_string(),
            ];
            if steps {
                record.push(number(s.final_return));
                record.push(s.steps.to_string());
                record.push(s.updates.to_string());
            }
            if !thresholds.is_empty() {
                record.extend(
                    s.reached
                        .iter()
                        .map(|(_, e)| e.map_or(String::new(), |e| e.to_string())),
                );
            }
            record
        })
        .collect();
    write_rows(path, &header, &records)
}
