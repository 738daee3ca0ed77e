//! A finished protocol's folder shipped with its top-level files only (`docs/`'s folders:
//! `summary.json`, `episodes.csv`, `tests.csv`, no run records): `sapnet plot` makes its
//! report and plots again from those files — every run's summary from `summary.json`, its
//! training returns from `episodes.csv`, its tests from `tests.csv` — so that a report
//! shipped by an older version can be read by today's rules. The data files are read, never
//! written; `activations.csv`, if it did not ship, leaves the figures drawn from it as they
//! were. `sapnet open` reads the same runs ([`runs`]) and writes nothing.

use std::path::Path;
use std::sync::Arc;

use anyhow::{bail, Context, Result};
use serde::Deserialize;

use super::plot_data;
use super::summary::{self, Status, Summary, SummaryHeader, MAX_SUMMARY_BYTES};
use crate::report::{plots, Report, RunSummary, TaskRuns, TrainingRuns};
use crate::safe_io::{self, Links};
use crate::trainer::MethodId;

/// The runs `summary.json` lists, as run summaries.
#[derive(Deserialize)]
struct ListedRuns {
    runs: Vec<RunSummary<String>>,
}

/// Whether `dir` is a shipped folder this module can make again: no run records, but the
/// episodes of the runs its summary lists.
pub fn can_replot(dir: &Path) -> bool {
    // Anything there (a link, a FIFO) counts: reading it then says what is wrong with it,
    // where "no episodes.csv" would send the user to the command that refuses it.
    let path = dir.join("episodes.csv");
    [safe_io::xz_twin(&path), path]
        .iter()
        .any(|p| std::fs::symlink_metadata(p).is_ok())
}

/// Every run `dir`'s `summary.json` lists, with its training returns from `episodes.csv`:
/// what its report is made of (`episodes.csv` or, as `docs/` ships it, `episodes.csv.xz`).
/// Refused for a protocol that did not finish.
pub fn runs(dir: &Path, header: &SummaryHeader) -> Result<ShippedRuns> {
    runs_reading(dir, header, episodes)
}

/// [`runs`], the training episodes read by `read` ([`episodes`]: the folder's
/// `episodes.csv`, the config's methods, the runs listed): a reader that holds them from a
/// read before hands them over instead of reading them again.
pub fn runs_reading(
    dir: &Path,
    header: &SummaryHeader,
    read: impl FnOnce(&Path, &[MethodId], &[RunSummary]) -> Result<TrainingRuns>,
) -> Result<ShippedRuns> {
    if !matches!(header.status, None | Some(Status::Complete)) {
        bail!(
            "{}: a protocol that did not finish (summary.json: status {:?}) and has no run \
             records: its top-level files may hold part of a run, and `--resume` needs the \
             records",
            dir.display(),
            header.status
        );
    }
    if !can_replot(dir) {
        bail!(
            "{}: summary.json lists {} runs, the folder holds none of their records \
             (runs/<run>/run.json) and no episodes.csv (nor episodes.csv.xz), whose \
             training returns the report is made of",
            dir.display(),
            header.listed_runs.len(),
        );
    }
    let path = dir.join("summary.json");
    let text = safe_io::read_text(&path, Links::Refuse, MAX_SUMMARY_BYTES)
        .with_context(|| format!("reading {}", path.display()))?;
    let listed: ListedRuns =
        serde_json::from_str(&text).with_context(|| format!("reading {}", path.display()))?;
    let methods = MethodId::all(&header.config.protocol.methods);
    let mut runs = Vec::new();
    for run in listed.runs {
        let Some(method) = methods.iter().find(|m| m.label() == run.record.method) else {
            bail!(
                "{}: run {} of method {:?}, which the config does not list",
                path.display(),
                run.record.run,
                run.record.method
            );
        };
        runs.push(run.with_method(method.clone()));
    }
    let episodes = read(&dir.join("episodes.csv"), &methods, &runs)?;
    for run in &runs {
        let key = (run.record.method.clone(), run.record.run);
        let count = episodes.get(&key).map_or(0, |e| e.len());
        plot_data::some_returns(&dir.join("episodes.csv"), &run.record, count)?;
    }
    Ok(ShippedRuns { runs, episodes })
}

/// A shipped folder's runs and their training episodes.
pub struct ShippedRuns {
    pub runs: Vec<RunSummary>,
    pub episodes: TrainingRuns,
}

/// Makes `dir`'s report, plots and `summary.json` again from its top-level files.
pub fn replot(dir: &Path, header: SummaryHeader) -> Result<Summary> {
    let ShippedRuns { runs, episodes } = runs(dir, &header)?;
    let config = header.config;
    let path = dir.join("summary.json");
    let library = header.library.unwrap_or_default();
    let task = config.env.label();
    let report = Report::of(&[TaskRuns {
        task: &task,
        config: &config,
        library: &library,
        runs: &runs,
        episodes: &episodes,
    }]);
    report.write(dir)?;
    // The plots read the returns again, as they read any folder's: not beside these.
    drop(episodes);
    let data = plot_data::read_expecting(dir, &plot_data::EpisodeCounts::of(&runs))?;
    plots::write_all(dir, &data)
        .with_context(|| format!("drawing the plots in {}", dir.display()))?;
    let mut summary = Summary::new(&config, header.trace);
    summary.status = Status::Complete;
    summary.wall_s = header.wall_s;
    summary.error = header.error;
    summary.runs = runs;
    summary.comparison = report.comparison.clone();
    summary.pairs = report.improvement.clone();
    summary.library = (!library.is_empty()).then_some(library);
    summary::write_json(&path, &summary)?;
    Ok(summary)
}

/// Each run's training episodes from the folder's `episodes.csv`, keyed by its method,
/// each kept in a block of the episodes `runs` says it has.
pub fn episodes(path: &Path, methods: &[MethodId], runs: &[RunSummary]) -> Result<TrainingRuns> {
    plot_data::training_episodes(path, &plot_data::EpisodeCounts::of(runs))?
        .into_iter()
        .map(|((label, run), episodes)| {
            let Some(method) = methods.iter().find(|m| m.label() == label) else {
                bail!(
                    "{}: runs of method {label:?}, which the config does not list",
                    path.display()
                );
            };
            Ok(((method.clone(), run), Arc::new(episodes)))
        })
        .collect()
}
