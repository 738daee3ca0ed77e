//! A results folder as it stands, read and never written, for `sapnet open`: finished,
//! stopped, or live and being written by another process. What each planned run has done
//! comes from the per-run files — a finished run's record in `runs/<run>/`, a running
//! run's `runs/.<run>.partial/episodes.csv` — since the top-level files are only put
//! together when the protocol ends. The comparison of the finished runs is the one
//! [`super::assemble`] writes into `comparison.csv` and `improvement.csv`: the same
//! [`Report::of`] over the same records.
//!
//! Nothing here takes the folder's lock or creates a file: the writer is found in
//! `/proc/locks` ([`folder_lock::holder`]), and every file is read as a file of a folder
//! from elsewhere ([`crate::safe_io`]: regular files only, no link followed).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result};
use serde::Deserialize;

use super::folder_changes::{self, Stat};
use super::records::{self, run_name, RunFolder};
use super::summary::{read_header, Status};
use crate::config::{Budget, Config};
use crate::folder_lock::{self, Holder};
use crate::report::{LibraryEntry, Report, RunSummary, TaskRuns, TrainingEpisodes, TrainingRuns};
use crate::safe_io::{self, Links};
use crate::trainer::MethodId;

/// Where one planned run stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunStatus {
    /// Not started yet; the protocol's process is alive and will get to it.
    Queued,
    /// Training now: its partial record grows.
    Running,
    /// Finished: its record is in `runs/`.
    Done,
    /// Stopped before its end (by the user, a signal, or a killed process); `--resume`
    /// runs it again.
    Stopped,
    /// Its protocol failed while it trained (`summary.json`'s `error` says why).
    Failed,
    /// Never started, and no live process will start it: `--resume` would.
    NotRun,
}

impl RunStatus {
    /// As the Runs view says it.
    pub fn name(self) -> &'static str {
        match self {
            RunStatus::Queued => "queued",
            RunStatus::Running => "running",
            RunStatus::Done => "done",
            RunStatus::Stopped => "stopped",
            RunStatus::Failed => "failed",
            RunStatus::NotRun => "not run",
        }
    }
}

/// One planned run of the protocol, as its files show it.
#[derive(Debug, Clone)]
pub struct RunProgress {
    pub method: MethodId,
    pub run: u32,
    pub status: RunStatus,
    /// Training episodes so far, episode 1 first (a finished run's shared with the
    /// report's).
    pub training: Arc<TrainingEpisodes>,
    /// The episodes or steps the protocol gives each run.
    pub planned: Budget,
    /// The source it handed over (a finished run's chosen one), else the one that acted
    /// in most of its episodes so far; `None` for a method that reuses no library.
    pub source: Option<String>,
    /// Seconds it has trained (a running run: as of its last episode).
    pub wall_s: Option<f64>,
}

impl RunProgress {
    pub fn episodes(&self) -> usize {
        self.training.len()
    }

    /// Its progress through its budget: episodes done, or steps of its ended episodes.
    pub fn done(&self) -> u64 {
        match self.planned {
            Budget::Episodes(_) => self.episodes() as u64,
            Budget::Steps(_) => self.training.lengths.iter().map(|&l| u64::from(l)).sum(),
        }
    }

    /// Its progress as a table shows it: `312/5000` episodes, or `52k/100k` steps.
    pub fn progress_text(&self) -> String {
        match self.planned {
            Budget::Episodes(n) => format!("{}/{n}", self.episodes()),
            Budget::Steps(n) => format!("{}/{}", short_count(self.done()), short_count(n)),
        }
    }

    /// Its progress text at its budget's end: the widest it will be.
    pub fn full_text(&self) -> String {
        match self.planned {
            Budget::Episodes(n) => format!("{n}/{n}"),
            Budget::Steps(n) => format!("{0}/{0}", short_count(n)),
        }
    }

    /// Its budget in the budget's unit.
    pub fn planned_amount(&self) -> u64 {
        match self.planned {
            Budget::Episodes(n) => u64::from(n),
            Budget::Steps(n) => n,
        }
    }

    /// Seconds until its budget is spent, at its pace so far (a running run only).
    pub fn eta_s(&self) -> Option<f64> {
        let done = self.done();
        let wall = self.wall_s?;
        (self.status == RunStatus::Running && done > 0)
            .then(|| wall / done as f64 * (self.planned_amount() as f64 - done as f64).max(0.0))
    }
}

/// A results folder as read at one moment.
#[derive(Debug)]
pub struct FolderState {
    pub dir: PathBuf,
    /// `summary.json`'s status (absent in folders older than the field).
    pub status: Option<Status>,
    /// The live process writing the folder, if any.
    pub writer: Option<Holder>,
    /// Why the protocol failed, if it did.
    pub error: Option<String>,
    pub config: Config,
    pub library: Vec<LibraryEntry>,
    /// Every planned run, by method as the protocol lists them, then run.
    pub runs: Vec<RunProgress>,
    /// The finished (and stopped) runs' records and training episodes: what the report
    /// is computed from.
    finished: Vec<RunSummary>,
    episodes: TrainingRuns,
}

impl FolderState {
    /// The task as results label it (`cartpole`).
    pub fn task(&self) -> String {
        self.config.env.label()
    }

    /// Runs finished to their end (stopped ones are not in the comparison).
    pub fn finished_runs(&self) -> usize {
        self.runs
            .iter()
            .filter(|r| r.status == RunStatus::Done)
            .count()
    }

    /// The record of run `run` of `method`, if it finished (or was stopped).
    pub fn finished(&self, method: &MethodId, run: u32) -> Option<&RunSummary> {
        self.finished
            .iter()
            .find(|r| r.record.method == *method && r.record.run == run)
    }

    /// What identifies the finished runs: the report changes only when this does.
    pub fn finished_key(&self) -> BTreeSet<(String, u32)> {
        self.finished
            .iter()
            .filter(|r| !r.record.stopped)
            .map(|r| (r.record.method.label().to_string(), r.record.run))
            .collect()
    }

    /// The comparison of the finished runs, computed as `comparison.csv` and
    /// `improvement.csv` are ([`super::assemble`]): on a finished folder, their numbers.
    pub fn report(&self) -> Report {
        let task = self.task();
        Report::of(&[TaskRuns {
            task: &task,
            config: &self.config,
            library: &self.library,
            runs: &self.finished,
            episodes: &self.episodes,
        }])
    }
}

/// Reads a folder again and again (`sapnet open` refreshes), reading each finished run's
/// returns once: a record in `runs/` never changes while its folder is there. A shipped
/// folder's returns are read again only when its files changed: its first read again (the
/// one that makes the report, right after the screen opens) would otherwise hold a second
/// copy of every return beside the one shown, twice the data of a large folder.
pub struct FolderReader {
    dir: PathBuf,
    finished_returns: BTreeMap<(String, u32), Arc<TrainingEpisodes>>,
    /// A shipped folder's returns, with what was seen of its files before they were read.
    shipped: Option<(Vec<Option<Stat>>, TrainingRuns)>,
}

/// The files a shipped folder's returns are read from ([`super::shipped::runs`]): its
/// config and methods, and its episodes.
const SHIPPED_FILES: [&str; 3] = ["summary.json", "episodes.csv", "episodes.csv.xz"];

impl FolderReader {
    pub fn new(dir: &Path) -> Self {
        Self {
            dir: dir.to_path_buf(),
            finished_returns: BTreeMap::new(),
            shipped: None,
        }
    }

    /// The folder it reads.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The folder as it stands now.
    pub fn read(&mut self) -> Result<FolderState> {
        let dir = &self.dir.clone();
        let header = read_header(dir)?;
        if !header.listed_runs.is_empty() && !records::any(dir)? {
            return self.shipped(dir, header);
        }
        let writer = folder_lock::holder(dir)?;
        let config = header.config;
        let library = header.library.unwrap_or_default();
        let names: Vec<&str> = library.iter().map(|e| e.name.as_str()).collect();
        let folders = records::read(dir, &config)?;
        let live = writer.is_some();
        let failed = header.status == Some(Status::Failed);
        let mut runs = Vec::new();
        let mut episodes = TrainingRuns::new();
        for method in MethodId::all(&config.protocol.methods) {
            for run in 0..config.protocol.runs {
                let record = folders
                    .iter()
                    .find(|f| f.summary.record.method == method && f.summary.record.run == run);
                let progress = match record {
                    Some(folder) => {
                        let returns = self.finished_returns(folder)?;
                        episodes.insert((method.clone(), run), returns.clone());
                        finished_run(&folder.summary, returns, &names, config.protocol.budget)
                    }
                    None => {
                        let partial = records::partial_dir(dir, &run_name(method.label(), run));
                        let (status, partial) = match read_partial(&partial)? {
                            Some(partial) if live => (RunStatus::Running, partial),
                            Some(partial) if failed => (RunStatus::Failed, partial),
                            Some(partial) => (RunStatus::Stopped, partial),
                            None if live => (RunStatus::Queued, PartialEpisodes::default()),
                            None => (RunStatus::NotRun, PartialEpisodes::default()),
                        };
                        RunProgress {
                            method: method.clone(),
                            run,
                            status,
                            source: partial.most_acting(),
                            wall_s: partial.wall_s,
                            training: Arc::new(partial.training),
                            planned: config.protocol.budget,
                        }
                    }
                };
                runs.push(progress);
            }
        }
        Ok(FolderState {
            dir: dir.to_path_buf(),
            status: header.status,
            writer,
            error: header.error,
            config,
            library,
            runs,
            finished: folders.into_iter().map(|f| f.summary).collect(),
            episodes,
        })
    }

    fn finished_returns(&mut self, folder: &RunFolder) -> Result<Arc<TrainingEpisodes>> {
        let record = &folder.summary.record;
        let key = (record.method.label().to_string(), record.run);
        if let Some(returns) = self.finished_returns.get(&key) {
            return Ok(returns.clone());
        }
        let returns = super::assemble::training_episodes(std::slice::from_ref(folder))?
            .into_values()
            .next()
            .unwrap_or_default();
        self.finished_returns.insert(key, returns.clone());
        Ok(returns)
    }

    /// A folder shipped with its top-level files only (`docs/`'s: no run records), read
    /// from `summary.json` and `episodes.csv` as `sapnet plot` reads it
    /// ([`super::shipped::runs`]), its returns those of the last read while its files are
    /// unchanged.
    fn shipped(&mut self, dir: &Path, header: super::SummaryHeader) -> Result<FolderState> {
        // Seen before the read: a change during it is a change at the next.
        let seen = folder_changes::files(dir, &SHIPPED_FILES);
        let cache = &mut self.shipped;
        let shipped = super::shipped::runs_reading(dir, &header, |path, methods, runs| {
            if let Some((_, episodes)) = cache.as_ref().filter(|(before, _)| *before == seen) {
                return Ok(episodes.clone());
            }
            // What this reader held goes before the read, not after it.
            *cache = None;
            let episodes = super::shipped::episodes(path, methods, runs)?;
            *cache = Some((seen, episodes.clone()));
            Ok(episodes)
        })?;
        shipped_state(dir, header, shipped)
    }
}

/// A shipped folder's state: a finished protocol, every run it lists done (or stopped),
/// the others not run.
fn shipped_state(
    dir: &Path,
    header: super::SummaryHeader,
    shipped: super::shipped::ShippedRuns,
) -> Result<FolderState> {
    let writer = folder_lock::holder(dir)?;
    let config = header.config;
    let library = header.library.unwrap_or_default();
    let names: Vec<&str> = library.iter().map(|e| e.name.as_str()).collect();
    let mut runs = Vec::new();
    for method in MethodId::all(&config.protocol.methods) {
        for run in 0..config.protocol.runs {
            let listed = shipped
                .runs
                .iter()
                .find(|r| r.record.method == method && r.record.run == run);
            runs.push(match listed {
                Some(summary) => {
                    let returns = shipped
                        .episodes
                        .get(&(method.clone(), run))
                        .cloned()
                        .unwrap_or_default();
                    finished_run(summary, returns, &names, config.protocol.budget)
                }
                None => RunProgress {
                    method: method.clone(),
                    run,
                    status: RunStatus::NotRun,
                    training: Arc::default(),
                    planned: config.protocol.budget,
                    source: None,
                    wall_s: None,
                },
            });
        }
    }
    let status = header.status;
    Ok(FolderState {
        dir: dir.to_path_buf(),
        status,
        writer,
        error: header.error,
        config,
        library,
        runs,
        finished: shipped.runs,
        episodes: shipped.episodes,
    })
}

/// A count as a narrow column shows it: `950`, `52k`, `1.5M`.
pub fn short_count(n: u64) -> String {
    match n {
        0..=9_999 => n.to_string(),
        10_000..=999_999 => format!("{}k", n / 1000),
        _ => format!("{:.1}M", n as f64 / 1e6),
    }
}

fn finished_run(
    summary: &RunSummary,
    training: Arc<TrainingEpisodes>,
    names: &[&str],
    planned: Budget,
) -> RunProgress {
    let record = &summary.record;
    let source = match &record.chosen {
        Some(chosen) => Some(chosen.name.clone()),
        None => crate::report::comparison::most_used(&record.source_steps)
            .and_then(|i| names.get(i))
            .map(|n| n.to_string()),
    };
    RunProgress {
        method: record.method.clone(),
        run: record.run,
        status: if record.stopped {
            RunStatus::Stopped
        } else {
            RunStatus::Done
        },
        training,
        planned,
        source,
        wall_s: Some(record.wall_s),
    }
}

/// What a run's partial `episodes.csv` says so far.
#[derive(Debug, Default)]
struct PartialEpisodes {
    training: TrainingEpisodes,
    /// Per source that acted most in an episode (none in the warm-up, or for a method
    /// without a library): in how many episodes it did, and the row it first did.
    acting: std::collections::HashMap<String, (usize, usize)>,
    wall_s: Option<f64>,
}

impl PartialEpisodes {
    /// The source that acted most in the most episodes (the first named, on a tie).
    fn most_acting(&self) -> Option<String> {
        self.acting
            .iter()
            .max_by(|(_, (a, a_first)), (_, (b, b_first))| a.cmp(b).then(b_first.cmp(a_first)))
            .map(|(name, _)| name.clone())
    }
}

#[derive(Deserialize)]
struct PartialRow<'a> {
    reward: f64,
    steps: u32,
    policy: Option<&'a str>,
    wall_s: f64,
}

/// The episodes of a run in progress, from `runs/.<run>.partial/episodes.csv`; `None`
/// when the run has no partial record (not started, or renamed into place since the
/// folder was listed). The writer appends row by row: a last line not ended yet is
/// not read. Read as a stream up to the last line break found when it was opened (a line
/// at most `safe_io::MAX_CSV_LINE_BYTES`), keeping a number per episode.
fn read_partial(partial: &Path) -> Result<Option<PartialEpisodes>> {
    use std::io::{Read, Seek, SeekFrom};
    if std::fs::symlink_metadata(partial).is_err() {
        return Ok(None);
    }
    let path = partial.join("episodes.csv");
    let mut file = match safe_io::open(&path, Links::Refuse, safe_io::MAX_CSV_BYTES) {
        Ok(file) => file,
        // Created but not yet written, or renamed into place between the two looks.
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(Some(PartialEpisodes::default()))
        }
        Err(e) => return Err(e).with_context(|| format!("reading {}", path.display())),
    };
    let reading = || format!("reading {}", path.display());
    // The last line break, looked for in the file's last line's bound only: a longer line
    // is refused by the reader below anyway.
    let length = file.metadata().with_context(reading)?.len();
    let tail = length.min(safe_io::MAX_CSV_LINE_BYTES + 1);
    file.seek(SeekFrom::Start(length - tail))
        .with_context(reading)?;
    let mut end = Vec::new();
    (&mut file)
        .take(tail)
        .read_to_end(&mut end)
        .with_context(reading)?;
    let whole = match end.iter().rposition(|&b| b == b'\n') {
        Some(at) => length - tail + at as u64 + 1,
        None if length > safe_io::MAX_CSV_LINE_BYTES => {
            anyhow::bail!(
                "{}: its last line is longer than the {} bytes a row may hold: not a run's \
                 episodes",
                path.display(),
                safe_io::MAX_CSV_LINE_BYTES
            )
        }
        None => 0,
    };
    drop(end);
    file.rewind().with_context(reading)?;
    let mut reader = csv::Reader::from_reader(safe_io::bounded_lines(file.take(whole), &path));
    let headers = reader.byte_headers().with_context(reading)?.clone();
    let mut record = csv::ByteRecord::new();
    let mut episodes = PartialEpisodes::default();
    for at in 2.. {
        let expected = || {
            format!(
                "{}: row {at}: expected the columns {}",
                path.display(),
                super::files::EPISODES_HEADER.join(", ")
            )
        };
        if !reader
            .read_byte_record(&mut record)
            .with_context(expected)?
        {
            break;
        }
        let row: PartialRow = record.deserialize(Some(&headers)).with_context(expected)?;
        if !row.reward.is_finite() {
            anyhow::bail!(
                "{}: row {at}, column reward: the return {} is not finite",
                path.display(),
                row.reward
            );
        }
        if episodes.training.len() >= crate::limits::MAX_VALUES_KEPT {
            anyhow::bail!(
                "{}: row {at}: more than the {} episodes sapnet keeps from one file",
                path.display(),
                crate::limits::MAX_VALUES_KEPT
            );
        }
        if let Some(name) = row.policy.filter(|p| !p.is_empty()) {
            let distinct = episodes.acting.len();
            match episodes.acting.get_mut(name) {
                Some((count, _)) => *count += 1,
                None if distinct >= crate::limits::MAX_SOURCES => anyhow::bail!(
                    "{}: row {at}: more than the {} sources a library may hold act in it",
                    path.display(),
                    crate::limits::MAX_SOURCES
                ),
                None => {
                    episodes.acting.insert(name.to_string(), (1, at));
                }
            }
        }
        episodes.training.push(row.reward, row.steps);
        episodes.wall_s = Some(row.wall_s);
    }
    Ok(Some(episodes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_partial_record_is_read_up_to_its_last_whole_line() {
        let tmp = tempfile::tempdir().unwrap();
        let partial = tmp.path().join(".dqn-16-run0.partial");
        std::fs::create_dir(&partial).unwrap();
        std::fs::write(
            partial.join("episodes.csv"),
            "run,method,episode,reward,steps,loss,statistic_loss,epsilon,policy,wall_s\n\
             0,sapnet,1,12.0,12,,0.0,0.03,,0.5\n\
             0,sapnet,2,20.0,20,0.1,0.01,0.03,source-3,1.0\n\
             0,sapnet,3,31.0,31,0.1,0.01,0.03,source-1,1.5\n\
             0,sapnet,4,40.0,40,0.1,0.01,0.03,source-3,2.0\n\
             0,sapnet,5,4",
        )
        .unwrap();
        let episodes = read_partial(&partial).unwrap().unwrap();
        assert_eq!(
            episodes.training.returns,
            [12.0, 20.0, 31.0, 40.0],
            "the cut row waits"
        );
        assert_eq!(episodes.most_acting().as_deref(), Some("source-3"));
        assert_eq!(episodes.wall_s, Some(2.0));
        assert!(read_partial(&tmp.path().join("absent")).unwrap().is_none());
        // Four episodes in 2 s, 6 more planned: 3 s.
        let progress = RunProgress {
            method: MethodId::new(0, &crate::reuse::Method::the_papers()),
            run: 0,
            status: RunStatus::Running,
            training: Arc::new(episodes.training),
            planned: Budget::Episodes(10),
            source: None,
            wall_s: episodes.wall_s,
        };
        assert_eq!(progress.eta_s(), Some(3.0));
    }

    #[test]
    fn a_sparse_partial_record_is_refused_at_its_line_not_read_whole() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("episodes.csv");
        std::fs::write(
            &path,
            "run,method,episode,reward,steps,loss,statistic_loss,epsilon,policy,wall_s\n",
        )
        .unwrap();
        // A 3 GiB hole, then a line break: one endless line.
        let file = std::fs::OpenOptions::new().write(true).open(&path).unwrap();
        file.set_len(3 << 30).unwrap();
        let mut file = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap();
        std::io::Write::write_all(&mut file, b"\n").unwrap();
        let err = format!("{:#}", read_partial(tmp.path()).unwrap_err());
        assert!(
            err.contains("episodes.csv: line 2 is longer than the 4194304 bytes"),
            "{err}"
        );
        // Without the line break, the last line itself is past the bound.
        file.set_len(3 << 30).unwrap();
        let err = format!("{:#}", read_partial(tmp.path()).unwrap_err());
        assert!(err.contains("its last line is longer than"), "{err}");
    }

    #[test]
    fn the_most_acting_source_is_counted_in_one_pass_first_named_on_a_tie() {
        let tmp = tempfile::tempdir().unwrap();
        let mut text = String::from(
            "run,method,episode,reward,steps,loss,statistic_loss,epsilon,policy,wall_s\n",
        );
        for (i, policy) in ["b", "a", "", "a", "b", "c"].iter().enumerate() {
            text.push_str(&format!("0,sapnet,{i},1.0,1,,0.0,0.03,{policy},0.5\n"));
        }
        std::fs::write(tmp.path().join("episodes.csv"), text).unwrap();
        let episodes = read_partial(tmp.path()).unwrap().unwrap();
        assert_eq!(episodes.most_acting().as_deref(), Some("b"));
        assert_eq!(episodes.training.len(), 6);
    }

    #[test]
    fn a_bad_row_is_refused_naming_the_file_its_row_and_the_columns() {
        let tmp = tempfile::tempdir().unwrap();
        std::fs::write(
            tmp.path().join("episodes.csv"),
            "run,method,episode,reward,steps,loss,statistic_loss,epsilon,policy,wall_s\n\
             0,sapnet,1,many,12,,0.0,0.03,,0.5\n",
        )
        .unwrap();
        let err = format!("{:#}", read_partial(tmp.path()).unwrap_err());
        assert!(
            err.contains("episodes.csv: row 2: expected the columns run, method"),
            "{err}"
        );
        assert!(err.contains("reward"), "{err}");
    }
}
