//! `sapnet sweep merge`: the finished cells as one report in `SWEEP/merged/`.
//!
//! - `comparison.csv`: per axis and value, the comparison of the methods (the measures of
//!   [`crate::report::comparison`]) over the runs of every cell with that value;
//! - `episodes.csv`: every episode of every cell, long format, the cell and its axis values
//!   as leading columns (ready for pandas or R);
//! - `<axis>=<value>/learning_curve.png` (and `.svg`, `tests.png`): the learning curves
//!   of that value's runs, mean and band across runs (seeds).
//!
//! Cells not done are named and left out.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};

use super::{cell_name, cell_results, Manifest};
use crate::config::{Config, Method};
use crate::experiment::method_ids;
use crate::report::{self, comparison, Curve, PlotData, RunSummary};
use crate::results::{self, Results};
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
        if dir.is_dir() {
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
    let out = sweep.join("merged");
    if out.exists() {
        std::fs::remove_dir_all(&out).with_context(|| format!("replacing {}", out.display()))?;
    }
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let axes: Vec<String> = manifest
        .cells
        .first()
        .map(|c| c.axes.iter().map(|(p, _)| p.clone()).collect())
        .unwrap_or_default();

    // Every episode, long format.
    let episodes = out.join("episodes.csv");
    let mut writer = csv::Writer::from_path(&episodes)
        .with_context(|| format!("creating {}", episodes.display()))?;
    let mut header_written = false;
    for (cell, _) in &done {
        let path = cell_results(sweep, cell.id).join("episodes.csv");
        let mut reader =
            csv::Reader::from_path(&path).with_context(|| format!("reading {}", path.display()))?;
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

    // The comparison per axis value, and its plots.
    let comparison_path = out.join("comparison.csv");
    let mut comparisons = csv::Writer::from_path(&comparison_path)
        .with_context(|| format!("creating {}", comparison_path.display()))?;
    let mut header_written = false;
    let mut tables = Vec::new();
    for (a, axis) in axes.iter().enumerate() {
        let mut values: Vec<&String> = Vec::new();
        for (cell, _) in &done {
            if !values.contains(&&cell.axes[a].1) {
                values.push(&cell.axes[a].1);
            }
        }
        for value in values {
            let group: Vec<&Results> = done
                .iter()
                .filter(|(cell, _)| &cell.axes[a].1 == value)
                .map(|(_, r)| r)
                .collect();
            let pooled = pool(&group);
            let rows = comparison::compare(
                &pooled.config,
                pooled.library.as_deref().unwrap_or_default(),
                &pooled.runs,
                &pooled.rewards,
            );
            let (header, records) = comparison::csv_records(&rows);
            if !header_written {
                let mut full = vec!["axis".to_string(), "value".to_string(), "cells".to_string()];
                full.extend(header);
                comparisons.write_record(&full)?;
                header_written = true;
            }
            for record in records {
                let mut full = vec![axis.clone(), value.clone(), group.len().to_string()];
                full.extend(record);
                comparisons.write_record(&full)?;
            }
            let dir = out.join(folder_name(axis, value));
            std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
            report::write_plots(&dir, &plot_data(&pooled))
                .with_context(|| format!("drawing the plots in {}", dir.display()))?;
            tables.push((format!("{axis} = {value}"), comparison::table(&rows)));
        }
    }
    comparisons
        .flush()
        .with_context(|| format!("writing {}", comparison_path.display()))?;
    Ok(MergeReport {
        merged: done.len(),
        missing,
        tables,
    })
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
type SameRun<'a> = (String, u64, Option<&'a Vec<f64>>, &'a Vec<f64>);

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
    let ids = method_ids(&config);
    let id_of = |label: &str| ids.iter().find(|id| id.label() == label).cloned();
    let mut runs = Vec::new();
    let mut rewards: BTreeMap<(MethodId, u32), Vec<f64>> = BTreeMap::new();
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
                .rewards
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
                rewards.insert((id, pooled.record.run), returns.clone());
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
        rewards,
    }
}

/// Learning curves and tests of the pooled runs.
fn plot_data(pooled: &Results) -> PlotData {
    let curves = method_ids(&pooled.config)
        .into_iter()
        .filter_map(|id| {
            let mine: Vec<&RunSummary> = pooled
                .runs
                .iter()
                .filter(|r| r.record.method == id)
                .collect();
            let returns: Vec<Vec<f64>> = mine
                .iter()
                .filter_map(|r| pooled.rewards.get(&(id.clone(), r.record.run)).cloned())
                .collect();
            (!returns.is_empty()).then(|| Curve {
                label: id.label().to_string(),
                sapnet: id.kind == crate::config::MethodKind::SapNet,
                returns,
                tests: mine.iter().map(|r| r.record.test_returns.clone()).collect(),
            })
        })
        .collect();
    PlotData {
        task: crate::env::make(&pooled.config.env).id().to_string(),
        window: pooled.config.protocol.moving_average,
        curves,
        policy_names: Vec::new(),
        activations: Vec::new(),
        acted: Vec::new(),
    }
}
