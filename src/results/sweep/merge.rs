//! `sapnet sweep merge`: the finished cells as one report in `SWEEP/merged/`.
//!
//! - `comparison.csv`: per axis and value, the comparison of the methods (the measures of
//!   [`crate::report::comparison`], with their intervals) over the runs of every cell with
//!   that value: in returns when the cells share one task, normalised and stratified by
//!   task when they span several; and, for a sweep over tasks, the rows of axis `*`,
//!   every cell pooled (its report in `across-tasks/`);
//! - `improvement.csv`: the probability of improvement of every method over every other,
//!   per axis value (`axis, value, score, method, over, p, lo, hi`);
//! - `sweep.png` / `.svg`: each method's IQM of both scores, with its interval, against
//!   each axis value ([`report::plots::write_sweep`]);
//! - `episodes.csv`: every episode of every cell, long format, the cell and its axis values
//!   as leading columns (ready for pandas or R);
//! - `<axis>=<value>/`: that value's report (`comparison.csv`, `improvement.csv`,
//!   `scores.csv`, the interval plots) and its learning curves (`learning_curve.png`,
//!   `.svg`, `tests.png`; with several tasks, in `task=<task>/` each).
//!
//! Cells not done are named and left out.

use std::path::Path;
use std::sync::Arc;

use anyhow::{Context, Result};

use super::{cell_name, cell_results, Manifest};
use crate::config::Config;
use crate::report::plots::SweepAxis;
use crate::report::{
    self, comparison, improvement, Curve, PlotData, Report, RunSummary, TaskRuns, TrainingEpisodes,
    TrainingRuns,
};
use crate::results::{self, Results};
use crate::reuse::Method;
use crate::trainer::MethodId;

/// What a merge found.
pub struct MergeReport {
    pub merged: usize,
    /// Cells without results, left out.
    pub missing: Vec<usize>,
    /// The comparison table of each axis value, for stdout.
    pub tables: Vec<(String, String)>,
}

/// Merges the finished cells of `sweep` into `sweep/merged/`.
pub fn merge(sweep: &Path) -> Result<MergeReport> {
    let manifest = Manifest::read(sweep)?;
    let mut done = Vec::new();
    let mut missing = Vec::new();
    for cell in &manifest.cells {
        let dir = cell_results(sweep, cell.id);
        if super::status::state(sweep, cell.id) == super::status::CellState::Done {
            let results = results::read_results(&dir)
                .with_context(|| format!("reading cell {}", cell_name(cell.id)))?;
            done.push((cell, results));
        } else {
            missing.push(cell.id);
        }
    }
    anyhow::ensure!(
        !done.is_empty(),
        "no cell of {} has finished: nothing to merge (`sapnet sweep status {}` says where \
         they are)",
        sweep.display(),
        sweep.display()
    );
    let _lock = crate::folder_lock::FolderLock::acquire(sweep, "a sweep merge")?;
    // Written whole into a hidden folder, renamed over `merged/` last: a killed merge
    // leaves the previous merge or none, never a part that looks finished.
    let merged = sweep.join("merged");
    let out = sweep.join(".merged.partial");
    if std::fs::symlink_metadata(&out).is_ok() {
        std::fs::remove_dir_all(&out).with_context(|| format!("removing {}", out.display()))?;
    }
    std::fs::create_dir(&out).with_context(|| format!("creating {}", out.display()))?;
    let axes: Vec<String> = manifest
        .cells
        .first()
        .map(|c| c.axes.iter().map(|(p, _)| p.clone()).collect())
        .unwrap_or_default();

    // Every episode, long format.
    let episodes = out.join("episodes.csv");
    let mut writer = csv::Writer::from_writer(
        crate::safe_io::create(&episodes)
            .with_context(|| format!("creating {}", episodes.display()))?,
    );
    let mut header_written = false;
    for (cell, _) in &done {
        let path = cell_results(sweep, cell.id).join("episodes.csv");
        let mut reader = crate::safe_io::csv_reader(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        if !header_written {
            let mut header = vec!["cell".to_string()];
            header.extend(axes.iter().cloned());
            header.extend(reader.headers()?.iter().map(String::from));
            writer.write_record(&header)?;
            header_written = true;
        }
        for row in reader.records() {
            let row = row.with_context(|| format!("reading {}", path.display()))?;
            let mut record = vec![cell.id.to_string()];
            record.extend(cell.axes.iter().map(|(_, v)| v.clone()));
            record.extend(row.iter().map(String::from));
            writer.write_record(&record)?;
        }
    }
    writer
        .flush()
        .with_context(|| format!("writing {}", episodes.display()))?;

    // The comparison per axis value (pooled over its tasks when its cells have several),
    // and over every cell when the sweep spans several tasks.
    let mut comparisons = Table::default();
    let mut improvements = Table::default();
    let mut tables = Vec::new();
    // Per axis (the pooled rows of `*` aside), each value's comparison: `sweep.png`.
    let mut plotted: Vec<SweepAxis> = Vec::new();
    let mut task_titles: Vec<String> = Vec::new();
    let done_refs: Vec<(&super::CellEntry, &Results)> = done.iter().map(|(c, r)| (*c, r)).collect();
    let groups = groups(&axes, &done_refs);
    for (axis, value, group) in &groups {
        let (report, strata) = value_report(axis, value, group);
        for title in &report.task_titles {
            if !task_titles.contains(title) {
                task_titles.push(title.clone());
            }
        }
        if axis != ACROSS_TASKS {
            let at = match plotted.iter().position(|p| &p.axis == axis) {
                Some(at) => at,
                None => {
                    plotted.push(SweepAxis {
                        axis: axis.clone(),
                        values: Vec::new(),
                        comparisons: Vec::new(),
                    });
                    plotted.len() - 1
                }
            };
            plotted[at].values.push(value.clone());
            plotted[at]
                .comparisons
                .push((report.comparison.clone(), report.units));
        }
        let lead = [axis.clone(), value.clone(), group.len().to_string()];
        let (header, records) = comparison::csv_records(&report.comparison, report.units);
        comparisons.extend(&["axis", "value", "cells"], &lead, &header, records);
        let (header, records) = improvement::records(&report.improvement, &report.tasks);
        improvements.extend(&["axis", "value"], &lead[..2], &header, records);
        let dir = if axis == ACROSS_TASKS {
            out.join(ACROSS_TASKS_FOLDER)
        } else {
            out.join(folder_name(axis, value))
        };
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        report
            .write(&dir)
            .with_context(|| format!("writing the report in {}", dir.display()))?;
        for (task, pooled) in &strata {
            // One task's curves in the value's folder; several tasks' each in its own.
            let curves = if strata.len() == 1 {
                dir.clone()
            } else {
                dir.join(folder_name("task", task))
            };
            std::fs::create_dir_all(&curves)
                .with_context(|| format!("creating {}", curves.display()))?;
            report::write_plots(&curves, &plot_data(pooled, report.subject.clone()))
                .with_context(|| format!("drawing the plots in {}", curves.display()))?;
        }
        let mut title = format!("{axis} = {value}");
        if !report.left_out.is_empty() {
            title.push_str(&format!(
                " (left out, not run on every task: {})",
                report.left_out.join(", ")
            ));
        }
        tables.push((title, report.table()));
    }
    comparisons.write(&out.join("comparison.csv"))?;
    improvements.write(&out.join("improvement.csv"))?;
    report::plots::write_sweep(&out, &task_titles, &plotted).context("drawing sweep.png")?;
    crate::failpoint::point("merge-written");
    if std::fs::symlink_metadata(&merged).is_ok() {
        std::fs::remove_dir_all(&merged)
            .or_else(|_| std::fs::remove_file(&merged))
            .with_context(|| format!("replacing {}", merged.display()))?;
    }
    std::fs::rename(&out, &merged)
        .with_context(|| format!("renaming {} into place", out.display()))?;
    Ok(MergeReport {
        merged: done.len(),
        missing,
        tables,
    })
}

/// The finished cells grouped as the merge reports them: per axis, each value's cells (in
/// the order first met), then, for a sweep over several tasks, every cell under
/// [`ACROSS_TASKS`]. The workbench's Sweep view groups them the same way.
pub fn groups<'a>(
    axes: &[String],
    done: &[(&super::CellEntry, &'a Results)],
) -> Vec<(String, String, Vec<&'a Results>)> {
    let mut groups: Vec<(String, String, Vec<&Results>)> = Vec::new();
    for (a, axis) in axes.iter().enumerate() {
        let mut values: Vec<&String> = Vec::new();
        for (cell, _) in done {
            if !values.contains(&&cell.axes[a].1) {
                values.push(&cell.axes[a].1);
            }
        }
        for value in values {
            let group: Vec<&Results> = done
                .iter()
                .filter(|(cell, _)| &cell.axes[a].1 == value)
                .map(|(_, r)| *r)
                .collect();
            groups.push((axis.clone(), value.clone(), group));
        }
    }
    let all: Vec<&Results> = done.iter().map(|(_, r)| *r).collect();
    if by_task(&all).len() > 1 {
        groups.push((ACROSS_TASKS.into(), "every cell".into(), all));
    }
    groups
}

/// The report of one axis value's cells, their runs pooled per task (stratified by task
/// over several), as `merged/comparison.csv` holds it; with the pooled runs per task.
pub fn value_report(
    axis: &str,
    value: &str,
    group: &[&Results],
) -> (Report, Vec<(String, Results)>) {
    let strata: Vec<(String, Results)> = by_task(group)
        .into_iter()
        .map(|(task, cells)| (task, pool(&cells)))
        .collect();
    let tasks: Vec<TaskRuns> = strata
        .iter()
        .map(|(task, pooled)| TaskRuns {
            task,
            config: &pooled.config,
            library: pooled.library.as_deref().unwrap_or_default(),
            runs: &pooled.runs,
            episodes: &pooled.episodes,
        })
        .collect();
    let mut report = Report::of(&tasks);
    report.subject = Some(if axis == ACROSS_TASKS {
        value.to_string()
    } else {
        format!("{axis} = {value}")
    });
    (report, strata)
}

/// The axis of the rows pooled over every cell of a sweep that spans several tasks.
pub const ACROSS_TASKS: &str = "*";
/// Their folder in `merged/`.
const ACROSS_TASKS_FOLDER: &str = "across-tasks";

/// The cells of `group` by task (its target task's label), tasks in the order first met.
fn by_task<'a>(group: &[&'a Results]) -> Vec<(String, Vec<&'a Results>)> {
    let mut tasks: Vec<(String, Vec<&Results>)> = Vec::new();
    for results in group {
        let task = results.config.env.label();
        match tasks.iter_mut().find(|(t, _)| *t == task) {
            Some((_, cells)) => cells.push(results),
            None => tasks.push((task, vec![results])),
        }
    }
    tasks
}

/// Rows gathered under one header: reports of one task and of several have different
/// columns (thresholds, units), so a column is found by its name and left empty in rows
/// that lack it.
#[derive(Default)]
struct Table {
    header: Vec<String>,
    rows: Vec<Vec<(String, String)>>,
}

impl Table {
    fn extend(
        &mut self,
        lead_names: &[&str],
        lead: &[String],
        header: &[String],
        records: Vec<Vec<String>>,
    ) {
        let names: Vec<String> = lead_names
            .iter()
            .map(|n| n.to_string())
            .chain(header.iter().cloned())
            .collect();
        for name in &names {
            if !self.header.contains(name) {
                self.header.push(name.clone());
            }
        }
        for record in records {
            let values = lead.iter().cloned().chain(record);
            self.rows.push(names.iter().cloned().zip(values).collect());
        }
    }

    fn write(&self, path: &Path) -> Result<()> {
        let records: Vec<Vec<String>> = self
            .rows
            .iter()
            .map(|row| {
                self.header
                    .iter()
                    .map(|h| {
                        row.iter()
                            .find(|(n, _)| n == h)
                            .map_or(String::new(), |(_, v)| v.clone())
                    })
                    .collect()
            })
            .collect();
        report::write_rows(path, &self.header, &records)
    }
}

/// `sapnet.temperature=0.5`, with anything but letters, digits, `.`, `=`, `-` made `_`.
fn folder_name(axis: &str, value: &str) -> String {
    format!("{axis}={value}")
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || ".=-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// What makes two pooled runs one: the method's label, the run's seed, its training
/// returns and its test returns.
type SameRun<'a> = (String, u64, Option<&'a Arc<TrainingEpisodes>>, &'a Vec<f64>);

/// The runs of several cells as one protocol: the methods of all (matched by label, in the
/// order first met), the runs numbered on from cell to cell.
fn pool(group: &[&Results]) -> Results {
    let mut methods: Vec<Method> = Vec::new();
    for results in group {
        for method in &results.config.protocol.methods {
            if !methods.iter().any(|m| m.label() == method.label()) {
                methods.push(method.clone());
            }
        }
    }
    let mut config: Config = group[0].config.clone();
    config.protocol.methods = methods;
    let ids = MethodId::all(&config.protocol.methods);
    let id_of = |label: &str| ids.iter().find(|id| id.label() == label).cloned();
    let mut runs = Vec::new();
    let mut episodes = TrainingRuns::new();
    let mut offset = 0;
    // A method the other axes do not touch (DQN in a sweep over `sapnet.temperature`) runs
    // the same in every cell of one seed: one run, counted once, or the pooled runs would
    // be inflated and their spread too small.
    let mut seen: Vec<SameRun> = Vec::new();
    for results in group {
        for summary in &results.runs {
            let Some(id) = id_of(summary.record.method.label()) else {
                continue;
            };
            let returns = results
                .episodes
                .get(&(summary.record.method.clone(), summary.record.run));
            let key = (
                id.label().to_string(),
                summary.record.seed,
                returns,
                &summary.record.test_returns,
            );
            if seen.contains(&key) {
                continue;
            }
            seen.push(key);
            let mut pooled: RunSummary = summary.clone();
            pooled.record.method = id.clone();
            pooled.record.run += offset;
            if let Some(returns) = returns {
                episodes.insert((id, pooled.record.run), returns.clone());
            }
            runs.push(pooled);
        }
        offset += results.config.protocol.runs;
    }
    config.protocol.runs = offset;
    Results {
        config,
        library: group[0].library.clone(),
        runs,
        episodes,
    }
}

/// Learning curves and tests of the pooled runs, titled with `subject` (the axis value).
fn plot_data(pooled: &Results, subject: Option<String>) -> PlotData {
    let curves = MethodId::all(&pooled.config.protocol.methods)
        .into_iter()
        .filter_map(|id| {
            let mine: Vec<&RunSummary> = pooled
                .runs
                .iter()
                .filter(|r| r.record.method == id)
                .collect();
            let runs: Vec<TrainingEpisodes> = mine
                .iter()
                .filter_map(|r| pooled.episodes.get(&(id.clone(), r.record.run)))
                .map(|e| TrainingEpisodes::clone(e))
                .collect();
            (!runs.is_empty()).then(|| Curve {
                label: id.label().to_string(),
                kind: id.kind,
                runs,
                tests: mine.iter().map(|r| r.record.test_returns.clone()).collect(),
            })
        })
        .collect();
    PlotData {
        task: report::plots::task_title(&pooled.config.env),
        subject,
        return_range: report::plots::return_bounds(&pooled.config.env),
        window: pooled.config.protocol.moving_average,
        budget: pooled.config.protocol.budget,
        curves,
        policy_names: Vec::new(),
        activations: Vec::new(),
        acted: Vec::new(),
    }
}
