//! The results directory's top-level files, put together from the run records in `runs/`
//! in the protocol's order (method as listed, then run, then episode), so the same config
//! and seed give the same files whatever `--jobs` and however often the protocol was
//! stopped and resumed: `episodes.csv`, `tests.csv`, `activations.csv`, `trace.csv`,
//! `comparison.csv`, `summary.json` and the plots.

use std::collections::BTreeMap;
use std::fs::OpenOptions;
use std::io::{BufRead, BufReader, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result};
use serde::Deserialize;

use super::files;
use super::plot_data;
use super::records::{self, RunFolder};
use super::summary::{self, Status, Summary};
use crate::config::Config;
use crate::report::{plots, LibraryEntry, Report, TaskRuns, TrainingEpisodes, TrainingRuns};

/// How the protocol ended, for `summary.json`.
pub struct Ending {
    pub status: Status,
    pub error: Option<String>,
    pub wall_s: f64,
}

/// Writes every top-level file of `out` from its run records and returns the summary.
pub fn assemble(
    out: &Path,
    config: &Config,
    library: Option<Vec<LibraryEntry>>,
    trace: bool,
    ending: Ending,
) -> Result<Summary> {
    let folders = records::read(out, config)?;
    // A run's file or, kept compressed, its xz twin (read as `safe_io::open_csv` reads it).
    let parts = |file: &str| -> Vec<PathBuf> {
        folders
            .iter()
            .map(|f| f.dir.join(file))
            .filter(|p| crate::safe_io::csv_exists(p))
            .collect()
    };
    concatenate(&out.join("episodes.csv"), &parts("episodes.csv"), |p| {
        files::EpisodeWriter::create(p).map(drop)
    })?;
    concatenate(&out.join("tests.csv"), &parts("tests.csv"), |p| {
        files::TestsWriter::create(p).map(drop)
    })?;
    if let Some(library) = &library {
        let names: Vec<String> = library.iter().map(|e| e.name.clone()).collect();
        concatenate(
            &out.join("activations.csv"),
            &parts("activations.csv"),
            |p| files::ActivationsWriter::create(p, &names).map(drop),
        )?;
        if trace {
            concatenate(&out.join("trace.csv"), &parts("trace.csv"), |p| {
                files::TraceWriter::create(p, &names).map(drop)
            })?;
        }
    }

    crate::failpoint::point("csv-assembled");
    let episodes = training_episodes(&folders)?;
    let mut summary = Summary::new(config, trace);
    summary.status = ending.status;
    summary.error = ending.error;
    summary.wall_s = ending.wall_s;
    summary.unfinished = records::unfinished(config, &folders);
    summary.runs = folders.into_iter().map(|f| f.summary).collect();
    let library = library.unwrap_or_default();
    let task = config.env.label();
    let report = Report::of(&[TaskRuns {
        task: &task,
        config,
        library: &library,
        runs: &summary.runs,
        episodes: &episodes,
    }]);
    summary.comparison = report.comparison.clone();
    summary.pairs = report.improvement.clone();
    summary.library = (!library.is_empty()).then_some(library);
    // Everything the summary's status vouches for is on disk before it.
    if !summary.runs.is_empty() {
        report.write(out)?;
        crate::failpoint::point("report-written");
        // The plots read the returns again, from the top-level file: not beside these.
        drop(episodes);
        let data = plot_data::read_expecting(out, &plot_data::EpisodeCounts::of(&summary.runs))?;
        plots::write_all(out, &data)
            .with_context(|| format!("drawing the plots in {}", out.display()))?;
        crate::failpoint::point("plots-drawn");
    }
    summary::write_json(&out.join("summary.json"), &summary)?;
    crate::failpoint::point("summary-written");
    Ok(summary)
}

/// Writes `path` as a header (`create` makes an empty file with it) followed by the rows of
/// every part, in order, each part's own header skipped; through a temporary file renamed
/// into place, removed if a part is refused (a part's xz bomb left a gigabyte there).
fn concatenate(path: &Path, parts: &[PathBuf], create: impl Fn(&Path) -> Result<()>) -> Result<()> {
    let tmp = crate::safe_io::sibling(path, "tmp");
    let written = write_parts(path, &tmp, parts, create);
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// [`concatenate`]'s writing, into `tmp`.
fn write_parts(
    path: &Path,
    tmp: &Path,
    parts: &[PathBuf],
    create: impl Fn(&Path) -> Result<()>,
) -> Result<()> {
    create(tmp)?;
    // Opened again for appending, never through a link (create made a regular file).
    let mut file = OpenOptions::new()
        .append(true)
        .custom_flags(libc::O_NOFOLLOW)
        .open(tmp)
        .with_context(|| format!("writing {}", tmp.display()))?;
    for part in parts {
        let text = crate::safe_io::open_csv(part)
            .with_context(|| format!("reading {}", part.display()))?;
        let mut reader = BufReader::new(crate::safe_io::bounded_lines(text, part));
        let mut header = Vec::new();
        reader
            .read_until(b'\n', &mut header)
            .with_context(|| format!("reading {}", part.display()))?;
        std::io::copy(&mut reader, &mut file)
            .with_context(|| format!("copying {} into {}", part.display(), path.display()))?;
    }
    file.flush()
        .and_then(|()| file.sync_all())
        .and_then(|()| std::fs::rename(tmp, path))
        .with_context(|| format!("writing {}", path.display()))
}

/// Each run's training episodes, from its own `episodes.csv`, its rows numbered in order
/// ([`plot_data::in_order`]): kept in one block of the episodes its record counts (a
/// vector grown as rows come would hold one and a half times a large run's values while
/// it moves them), more rows than that in chunks.
pub fn training_episodes(folders: &[RunFolder]) -> Result<TrainingRuns> {
    #[derive(Deserialize)]
    struct Row {
        episode: u32,
        reward: f64,
        steps: u32,
    }
    let mut runs = BTreeMap::new();
    for folder in folders {
        let path = folder.dir.join("episodes.csv");
        let record = &folder.summary.record;
        let mut reader = crate::safe_io::csv_reader(&path)
            .with_context(|| format!("reading {}", path.display()))?;
        let expected = (record.episodes as usize).min(crate::limits::MAX_VALUES_KEPT);
        let mut returns = plot_data::Chunked::with_capacity(expected);
        let mut lengths = plot_data::Chunked::with_capacity(expected);
        let run = (record.method.label(), record.run);
        let mut last = None;
        for (i, row) in reader.deserialize::<Row>().enumerate() {
            let row = row.with_context(|| format!("{}: row {}", path.display(), i + 2))?;
            if let Some(last) = last {
                plot_data::in_order(&path, i + 2, "episode", run, last, row.episode)?;
            }
            last = Some(row.episode);
            returns.push(plot_data::a_kept_return(&path, i, row.reward)?);
            lengths.push(row.steps);
        }
        let episodes = TrainingEpisodes {
            returns: returns.into_vec(),
            lengths: lengths.into_vec(),
        };
        plot_data::some_returns(&path, record, episodes.len())?;
        runs.insert((record.method.clone(), record.run), Arc::new(episodes));
    }
    Ok(runs)
}
