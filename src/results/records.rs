//! `runs/<method>-run<r>/`: each run's own record, written while it trains into a hidden
//! `runs/.<method>-run<r>.partial/` and renamed into place when it ends, so a folder in
//! `runs/` is always whole: `episodes.csv`, `tests.csv`, `activations.csv` (a run that
//! reuses the library), `trace.csv` (traced SAP-Net runs) and `run.json` (its summary).
//! The top-level files are put together from these ([`super::assemble`]); `--resume` keeps
//! the finished ones and runs the rest again.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::files;
use super::summary::{self, RunKey};
use crate::config::Config;
use crate::report::RunSummary;
use crate::trainer::{self, EpisodeRecord, MethodId, RunRecord, TraceRecord};

/// The folder of all run records in a results directory.
pub const RUNS: &str = "runs";

/// The largest `run.json`: a run's totals and test returns take a few kilobytes.
const MAX_RECORD_BYTES: u64 = 16 << 20;

/// `dqn[100,100]`, run 0 → `dqn-100-100-run0`: a plain file name, of the run's folder and
/// of its trained policy. A label too long for a file name (a deep network's) is cut and
/// told apart by a hash of the whole.
pub fn run_name(method: &str, run: u32) -> String {
    const LONGEST: usize = 120;
    let plain: String = method
        .chars()
        .filter(|&c| c != ']')
        .map(|c| if c == '[' || c == ',' { '-' } else { c })
        .collect();
    if plain.len() <= LONGEST {
        return format!("{plain}-run{run}");
    }
    let cut: String = plain.chars().take(LONGEST).collect();
    let hash = &crate::policy_store::sha256_hex(method.as_bytes())[..12];
    format!("{cut}-{hash}-run{run}")
}

fn finished_dir(out: &Path, name: &str) -> PathBuf {
    out.join(RUNS).join(name)
}

/// Where a run's record is written while it trains.
pub(super) fn partial_dir(out: &Path, name: &str) -> PathBuf {
    out.join(RUNS).join(format!(".{name}.partial"))
}

/// One run's files while it trains.
pub struct RunWriter {
    name: String,
    partial: PathBuf,
    episodes: files::EpisodeWriter,
    activations: Option<files::ActivationsWriter>,
    trace: Option<files::TraceWriter>,
    /// The library's sources, by which episodes and traces name policies.
    names: Vec<String>,
    /// Training returns so far, for the run's moving averages.
    pub rewards: Vec<f64>,
    /// The latest selector snapshot, and the selections counted before this episode.
    snapshot: Option<(trainer::ActivationSnapshot, Vec<u64>)>,
}

impl RunWriter {
    /// Opens the record of `method`'s run `run` in `out`, replacing any partial one a
    /// killed process left. `names` are the library's sources, for a reusing run.
    pub fn create(out: &Path, method: &MethodId, run: u32, names: &[String]) -> Result<Self> {
        let name = run_name(method.label(), run);
        let partial = partial_dir(out, &name);
        let runs = out.join(RUNS);
        crate::safe_io::real_dir(&runs).with_context(|| format!("{}", runs.display()))?;
        // remove_dir_all removes a planted link itself, never what it points to.
        if std::fs::symlink_metadata(&partial).is_ok() {
            std::fs::remove_dir_all(&partial)
                .or_else(|_| std::fs::remove_file(&partial))
                .with_context(|| format!("removing the partial record {}", partial.display()))?;
        }
        std::fs::create_dir(&partial).with_context(|| format!("creating {}", partial.display()))?;
        let activations = if method.kind.reuses && !names.is_empty() {
            Some(files::ActivationsWriter::create(
                &partial.join("activations.csv"),
                names,
            )?)
        } else {
            None
        };
        Ok(Self {
            name,
            episodes: files::EpisodeWriter::create(&partial.join("episodes.csv"))?,
            activations,
            trace: None,
            names: names.to_vec(),
            rewards: Vec::new(),
            snapshot: None,
            partial,
        })
    }

    /// Keeps the selector's latest state, for the row of the episode it ends.
    pub fn snapshot(&mut self, snapshot: trainer::ActivationSnapshot) {
        let counted = self
            .snapshot
            .take()
            .map_or_else(|| vec![0; snapshot.selections.len()], |(_, c)| c);
        self.snapshot = Some((snapshot, counted));
    }

    /// An episode's row, and for a reusing run its row of `activations.csv` from the
    /// snapshot the trainer sends right before `EpisodeEnded`.
    pub fn episode(&mut self, record: &EpisodeRecord) -> Result<()> {
        self.episodes.write(record, &self.names)?;
        self.rewards.push(record.reward);
        if let (Some(writer), Some((snapshot, counted))) =
            (&mut self.activations, &mut self.snapshot)
        {
            let selected: Vec<u64> = snapshot
                .selections
                .iter()
                .zip(counted.iter())
                .map(|(now, before)| now - before)
                .collect();
            writer.write(
                record.run,
                &record.method,
                record.episode,
                &snapshot.activations,
                &snapshot.probabilities,
                &selected,
            )?;
            counted.clone_from(&snapshot.selections);
        }
        if let Some(trace) = &mut self.trace {
            trace.flush()?;
        }
        Ok(())
    }

    /// One positive activation's spread calls.
    pub fn trace(&mut self, record: &TraceRecord) -> Result<()> {
        if self.trace.is_none() {
            self.trace = Some(files::TraceWriter::create(
                &self.partial.join("trace.csv"),
                &self.names,
            )?);
        }
        match &mut self.trace {
            Some(trace) => trace.write(record),
            None => Ok(()),
        }
    }

    /// Writes the run's tests and summary and renames its folder into place.
    pub fn finish(mut self, out: &Path, summary: &RunSummary) -> Result<()> {
        let mut tests = files::TestsWriter::create(&self.partial.join("tests.csv"))?;
        tests.write(&summary.record)?;
        if let Some(trace) = &mut self.trace {
            trace.flush()?;
        }
        summary::write_json(&self.partial.join("run.json"), summary)?;
        let finished = finished_dir(out, &self.name);
        if std::fs::symlink_metadata(&finished).is_ok() {
            std::fs::remove_dir_all(&finished)
                .or_else(|_| std::fs::remove_file(&finished))
                .with_context(|| format!("replacing {}", finished.display()))?;
        }
        std::fs::rename(&self.partial, &finished)
            .with_context(|| format!("renaming {} into place", self.partial.display()))
    }
}

/// `out/runs`, if there: a real directory. `O_NOFOLLOW` guards only a path's last
/// component, so a `runs` planted as a link would have every record read, and partial
/// ones deleted, wherever it points.
fn runs_dir(out: &Path) -> Result<Option<PathBuf>> {
    let dir = out.join(RUNS);
    match std::fs::symlink_metadata(&dir) {
        Ok(m) if m.is_dir() => Ok(Some(dir)),
        Ok(m) if m.file_type().is_symlink() => bail!(
            "{}: a symbolic link where the run records belong: a results folder's records are \
             its own directories, never links to elsewhere",
            dir.display()
        ),
        Ok(_) => bail!(
            "{}: a file where the run records' directory belongs",
            dir.display()
        ),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(e).with_context(|| format!("reading {}", dir.display())),
    }
}

/// A run's record on disk.
pub struct RunFolder {
    pub dir: PathBuf,
    pub summary: RunSummary,
}

/// Whether `out` holds a run record as [`read`] counts one (a directory of `runs/`, not a
/// link nor a hidden partial folder, with its `run.json`), found without reading one.
pub fn any(out: &Path) -> Result<bool> {
    let Some(dir) = runs_dir(out)? else {
        return Ok(false);
    };
    let entries = std::fs::read_dir(&dir).with_context(|| format!("reading {}", dir.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("reading {}", dir.display()))?;
        let hidden = entry
            .file_name()
            .to_str()
            .is_none_or(|n| n.starts_with('.'));
        let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
        if !hidden && is_dir && std::fs::symlink_metadata(entry.path().join("run.json")).is_ok() {
            return Ok(true);
        }
    }
    Ok(false)
}

/// The finished (and stopped) runs recorded in `out`, by the protocol's order: method as
/// `config` lists them, then run. Partial folders are not records.
pub fn read(out: &Path, config: &Config) -> Result<Vec<RunFolder>> {
    let Some(dir) = runs_dir(out)? else {
        return Ok(Vec::new());
    };
    let entries = std::fs::read_dir(&dir).with_context(|| format!("reading {}", dir.display()))?;
    let ids: BTreeMap<String, MethodId> = crate::trainer::MethodId::all(&config.protocol.methods)
        .into_iter()
        .map(|id| (id.label().to_string(), id))
        .collect();
    let mut folders: Vec<RunFolder> = Vec::new();
    for entry in entries {
        let entry = entry.with_context(|| format!("reading {}", dir.display()))?;
        let path = entry.path();
        let hidden = path
            .file_name()
            .and_then(|n| n.to_str())
            .is_none_or(|n| n.starts_with('.'));
        let kind = entry
            .file_type()
            .with_context(|| format!("reading {}", path.display()))?;
        if hidden {
            continue;
        }
        if kind.is_symlink() {
            bail!(
                "{}: a symbolic link among the run records: a results folder's records are \
                 its own directories, never links to elsewhere",
                path.display()
            );
        }
        let json = path.join("run.json");
        // A folder without its record is what a failed removal or a kill between its
        // creation and its rename leaves: not a run, run again by a resume.
        if !kind.is_dir() || std::fs::symlink_metadata(&json).is_err() {
            continue;
        }
        let text =
            crate::safe_io::read_text(&json, crate::safe_io::Links::Refuse, MAX_RECORD_BYTES)
                .with_context(|| format!("reading the run record {}", json.display()))?;
        let stored: RunSummary<String> = serde_json::from_str(&text)
            .with_context(|| format!("reading the run record {}", json.display()))?;
        let Some(id) = ids.get(&stored.record.method) else {
            bail!(
                "{}: method {:?} is not in the protocol of this results directory",
                json.display(),
                stored.record.method
            );
        };
        // A record is where its method and run put it, once, within the protocol.
        let expected = run_name(id.label(), stored.record.run);
        if stored.record.run >= config.protocol.runs
            || path.file_name().and_then(|n| n.to_str()) != Some(expected.as_str())
        {
            bail!(
                "{}: the record of {} run {} belongs in {} (runs 0 to {} of this protocol)",
                json.display(),
                stored.record.method,
                stored.record.run,
                dir.join(&expected).display(),
                config.protocol.runs.saturating_sub(1)
            );
        }
        folders.push(RunFolder {
            summary: stored.with_method(id.clone()),
            dir: path,
        });
    }
    folders.sort_by_key(|f| (f.summary.record.method.index, f.summary.record.run));
    Ok(folders)
}

/// The planned runs of `config` that `finished` does not hold as finished (not stopped).
pub fn unfinished(config: &Config, finished: &[RunFolder]) -> Vec<RunKey> {
    let done = |method: &MethodId, run: u32| {
        finished.iter().any(|f| {
            let r: &RunRecord = &f.summary.record;
            &r.method == method && r.run == run && !r.stopped
        })
    };
    let ids = crate::trainer::MethodId::all(&config.protocol.methods);
    let mut keys = Vec::new();
    for id in &ids {
        for run in 0..config.protocol.runs {
            if !done(id, run) {
                keys.push(RunKey {
                    method: id.label().to_string(),
                    run,
                });
            }
        }
    }
    keys
}

/// Removes what a resumed protocol runs again: partial records and half-saved policies (a
/// killed process's) and the records of stopped runs.
pub fn clear_unfinished(out: &Path, finished: &[RunFolder]) -> Result<()> {
    let policies = out.join("policies");
    if policies.is_dir() {
        crate::policy_store::remove_temporaries(&policies).with_context(|| {
            format!(
                "removing a killed save's leftovers from {}",
                policies.display()
            )
        })?;
    }
    if let Some(entries) = runs_dir(out)?.and_then(|dir| std::fs::read_dir(dir).ok()) {
        for entry in entries.flatten() {
            let path = entry.path();
            let partial = path
                .file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with('.') && n.ends_with(".partial"));
            let unrecorded = entry.file_type().is_ok_and(|t| t.is_dir())
                && std::fs::symlink_metadata(path.join("run.json")).is_err();
            if partial || unrecorded {
                std::fs::remove_dir_all(&path)
                    .with_context(|| format!("removing {}", path.display()))?;
            }
        }
    }
    for folder in finished.iter().filter(|f| f.summary.record.stopped) {
        std::fs::remove_dir_all(&folder.dir)
            .with_context(|| format!("removing {}", folder.dir.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_resume_removes_a_killed_saves_leftovers_and_keeps_the_policies() {
        let out = tempfile::tempdir().unwrap();
        let policies = out.path().join("policies");
        std::fs::create_dir(&policies).unwrap();
        let leftovers = [
            ".sapnet-run0.ron.4242.tmp",
            ".sapnet-run0.safetensors.4242.tmp",
        ];
        for name in leftovers {
            std::fs::write(policies.join(name), "half").unwrap();
        }
        std::fs::write(policies.join("dqn-16-run0.ron"), "kept").unwrap();
        clear_unfinished(out.path(), &[]).unwrap();
        for name in leftovers {
            assert!(!policies.join(name).exists(), "{name}");
        }
        assert!(policies.join("dqn-16-run0.ron").exists());
    }

    #[test]
    fn run_names_are_plain() {
        assert_eq!(run_name("dqn[100,100]", 0), "dqn-100-100-run0");
        assert_eq!(run_name("dqn[16]", 3), "dqn-16-run3");
        assert_eq!(run_name("sapnet", 1), "sapnet-run1");
        let deep = format!("dqn[{}]", vec!["100"; 60].join(","));
        let name = run_name(&deep, 0);
        assert!(name.len() < 160, "{name}");
        assert!(name.ends_with("-run0"));
        assert_ne!(name, run_name(&deep.replace("[100,", "[101,"), 0));
    }
}
