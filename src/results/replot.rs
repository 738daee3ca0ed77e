//! `sapnet plot DIR`: a results directory's report and plots made again from its files —
//! `summary.json` (the config: task, methods, moving-average window) and the run records
//! — exactly as the run that wrote them made them: for a run stopped before its plots, a
//! folder of an older version, or one whose process was killed (`summary.json` still says
//! `running`: its finished runs are put together and it is marked `interrupted`); for a
//! finished protocol shipped without its run records, from its top-level files
//! ([`super::shipped`]).

use std::path::Path;

use anyhow::{bail, Result};

use super::assemble::{assemble, Ending};
use super::summary::{read_header, Status, Summary};

/// Puts `dir`'s files together again from its run records — the CSV files, the report
/// (`comparison.csv`, `improvement.csv`, `scores.csv`), every plot and `summary.json` —
/// replacing those there, and returns the summary. A protocol whose process was killed
/// (`summary.json` still `running`) is marked `interrupted`.
pub fn replot(dir: &Path) -> Result<Summary> {
    read_header(dir)?;
    // A folder whose protocol still runs is that process's to write: refused, naming it,
    // before anything is taken or written there. The lock taken next closes the gap of a
    // protocol starting in between.
    if let Some(holder) = crate::folder_lock::holder(dir)? {
        bail!("{}", refused_while_written(dir, &holder));
    }
    let _lock = crate::folder_lock::FolderLock::acquire(dir, "sapnet plot")?;
    let header = read_header(dir)?;
    if !header.listed_runs.is_empty()
        && !super::records::any(dir)?
        && super::shipped::can_replot(dir)
    {
        return super::shipped::replot(dir, header);
    }
    super::require_records(dir, &header)?;
    let status = match header.status {
        Some(Status::Running) => Status::Interrupted,
        Some(status) => status,
        None => Status::Complete,
    };
    let summary = assemble(
        dir,
        &header.config,
        header.library,
        header.trace,
        Ending {
            status,
            error: header.error,
            wall_s: header.wall_s,
        },
    )?;
    if header.status == Some(Status::Running) {
        eprintln!(
            "{}: the protocol was interrupted; its {} finished runs are put together (`sapnet \
             --headless --resume --out {}` runs the other {})",
            dir.display(),
            summary.runs.len(),
            dir.display(),
            summary.unfinished.len()
        );
    }
    Ok(summary)
}

/// Why `sapnet plot` leaves a folder another process writes: who writes it (its lock line,
/// `PID 1234 on host since 10:02:07 UTC (a protocol)`, once), and how to read it meanwhile.
fn refused_while_written(dir: &Path, holder: &crate::folder_lock::Holder) -> String {
    let who = match holder.says.strip_prefix("running as ") {
        Some(line) => line.to_string(),
        None if holder.says.is_empty() => holder.describe(),
        None => format!("{} ({})", holder.describe(), holder.says),
    };
    format!(
        "{dir} is being written by the sapnet process {who}: `sapnet plot` would rewrite its \
         report under it, so it changes nothing there; watch it with `sapnet open {dir}`, and \
         plot it once that process has ended",
        dir = dir.display(),
    )
}
