//! `sapnet pool DIR… --out DIR`: finished protocols on different tasks as one comparison,
//! each a stratum: scores normalised by each task's range of returns, runs resampled
//! within their task ([`crate::report::Report::of`]).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::{read_results, Results, Status};
use crate::report::{Report, TaskRuns};

/// Reads every folder of `dirs`, refuses two on one task or one unfinished, and writes the
/// pooled report into `out`.
pub fn pool(dirs: &[PathBuf], out: &Path) -> Result<Report> {
    let mut folders: Vec<(String, Results)> = Vec::new();
    for dir in dirs {
        let header = super::read_header(dir)?;
        if header.status != Some(Status::Complete) {
            bail!(
                "{}: the protocol is not complete (summary.json: status {}); `sapnet --headless \
                 --resume --out {}` finishes it",
                dir.display(),
                header
                    .status
                    .map_or("absent".into(), |s| format!("{s:?}").to_lowercase()),
                dir.display()
            );
        }
        let results = read_results(dir).with_context(|| format!("reading {}", dir.display()))?;
        let task = results.config.env.label();
        if let Some((_, other)) = folders.iter().zip(dirs).find(|((t, _), _)| *t == task) {
            bail!(
                "{} and {} are both on {task}: pool protocols on different tasks (runs of one \
                 task are pooled by a sweep's merge)",
                other.display(),
                dir.display()
            );
        }
        folders.push((task, results));
    }
    if out.exists() && std::fs::read_dir(out)?.next().is_some() {
        bail!("--out {}: expected a new or empty directory", out.display());
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let tasks: Vec<TaskRuns> = folders
        .iter()
        .map(|(task, results)| TaskRuns {
            task,
            config: &results.config,
            library: results.library.as_deref().unwrap_or_default(),
            runs: &results.runs,
            episodes: &results.episodes,
        })
        .collect();
    let report = Report::of(&tasks);
    report.write(out)?;
    Ok(report)
}
