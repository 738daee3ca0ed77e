//! The results directory before a protocol writes to it: created, locked for this
//! process, and refused if it holds results, unless they are to be replaced (`--force`:
//! moved aside, deleted last); what a killed protocol or `--force` left is finished or
//! cleared first.

use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use anyhow::{bail, Context, Result};

use crate::folder_lock::FolderLock;
use crate::report;
use crate::results::{self, records, Status};

/// Where results go and whether old ones may be replaced.
#[derive(Debug, Clone)]
pub struct OutputOptions {
    pub dir: PathBuf,
    /// Replace results already in `dir`.
    pub force: bool,
}

/// Entries that mark a directory as holding results already.
const RESULT_FILES: [&str; 7] = [
    "episodes.csv",
    "tests.csv",
    "activations.csv",
    "trace.csv",
    "summary.json",
    "policies",
    records::RUNS,
];

/// Where `--force` moves the results it replaces until the new ones are written.
const REPLACED: &str = ".replaced";

/// In `.replaced/` once every old result is in it: without it, a `--force` was killed
/// while moving them, and they are put back first.
const MOVED: &str = ".moved";

/// The output directory, created and locked for this process ([`FolderLock`]: a second
/// process into the same `--out` is refused naming the first), holding no results but
/// those `--force` replaces: moved into `<dir>/.replaced/` (returned), to be deleted once
/// the new ones are written, so that a directory where nothing can be written loses
/// nothing.
pub(super) fn open_output(output: &OutputOptions) -> Result<(FolderLock, Option<PathBuf>)> {
    let dir = &output.dir;
    if dir.exists() && !dir.is_dir() {
        bail!(
            "--out {}: expected a directory for the results, and it is a file",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("creating the output directory {}", dir.display()))?;
    let lock = FolderLock::acquire(dir, "a protocol")?;
    let replaced = dir.join(REPLACED);
    if replaced.exists() {
        finish_interrupted_replacement(dir, &replaced)?;
    }
    if replaced.exists() {
        // Kept: the results an earlier --force was replacing when it was killed; the top
        // level holds a partial replacement.
        if !output.force {
            bail!(
                "{} holds results an interrupted --force was replacing (kept in {}); pass \
                 --force to replace them, or move them back by hand",
                dir.display(),
                replaced.display()
            );
        }
        remove_results(dir)?;
        return Ok((lock, Some(replaced)));
    }
    clear_killed_start(dir)?;
    let existing: Vec<&str> = RESULT_FILES
        .into_iter()
        .chain(["comparison.csv"])
        .filter(|f| std::fs::symlink_metadata(dir.join(f)).is_ok())
        .collect();
    if existing.is_empty() {
        return Ok((lock, None));
    }
    if !output.force {
        bail!(
            "the output directory {} already holds results ({}); {}",
            dir.display(),
            existing.join(", "),
            held_advice(dir)
        );
    }
    std::fs::create_dir(&replaced).with_context(|| {
        format!(
            "cannot replace the results in {}: creating {}",
            dir.display(),
            replaced.display()
        )
    })?;
    let mut moved = Vec::new();
    for name in RESULT_FILES.iter().chain(report::FILES.iter()) {
        let (from, to) = (dir.join(name), replaced.join(name));
        if std::fs::symlink_metadata(&from).is_err() {
            continue;
        }
        if let Err(err) = std::fs::rename(&from, &to) {
            // Put back what moved: the old results stay as they were.
            for (from, to) in moved.iter().rev() {
                let _ = std::fs::rename(to, from);
            }
            let _ = std::fs::remove_dir(&replaced);
            return Err(err).with_context(|| {
                format!(
                    "cannot replace the results in {}: moving {} aside; nothing was changed",
                    dir.display(),
                    from.display()
                )
            });
        }
        moved.push((from, to));
        crate::failpoint::point("force-moving");
    }
    std::fs::write(replaced.join(MOVED), "")
        .with_context(|| format!("writing {}", replaced.join(MOVED).display()))?;
    crate::failpoint::point("force-moved");
    Ok((lock, Some(replaced)))
}

/// What to type for a folder that holds results, by what its summary.json says they are:
/// every command named here is one that works on such a folder (tests/it/resume_cli.rs
/// follows each).
fn held_advice(dir: &Path) -> String {
    let at = dir.display();
    let other = "choose another --out, or pass --force to replace them";
    match results::read_header(dir).map(|h| h.status) {
        Ok(Some(Status::Complete)) => {
            format!("they are a complete protocol: `sapnet open {at}` shows them; {other}")
        }
        Ok(Some(status)) => format!(
            "they are an unfinished protocol (status {}): `sapnet --resume --out {at}` \
             finishes it in the UI, `sapnet --headless --resume --out {at}` without it; or \
             {other}",
            format!("{status:?}").to_lowercase()
        ),
        Ok(None) | Err(_) => other.to_string(),
    }
}

/// What a killed `--force` left, finished before and after a `--resume`: the resumed
/// protocol is that `--force`'s replacement, so once it is complete the results it
/// replaces go, as they would have.
pub(super) fn finish_replacement(dir: &Path) -> Result<()> {
    let replaced = dir.join(REPLACED);
    if std::fs::symlink_metadata(&replaced).is_ok() {
        finish_interrupted_replacement(dir, &replaced)?;
    }
    Ok(())
}

/// An earlier `--force` was killed. Killed while moving the old results aside (no
/// [`MOVED`] mark), they are put back; killed after deleting them had begun — the new
/// results complete — the rest of `.replaced` goes. Otherwise `.replaced` holds the old
/// results whole and the folder's top level a partial replacement: `.replaced` is kept.
fn finish_interrupted_replacement(dir: &Path, replaced: &Path) -> Result<()> {
    if std::fs::symlink_metadata(replaced.join(MOVED)).is_err() {
        for name in RESULT_FILES.iter().chain(report::FILES.iter()) {
            let (from, to) = (replaced.join(name), dir.join(name));
            if std::fs::symlink_metadata(&from).is_ok() && std::fs::symlink_metadata(&to).is_err() {
                std::fs::rename(&from, &to)
                    .with_context(|| format!("putting {} back", to.display()))?;
            }
        }
        return std::fs::remove_dir_all(replaced)
            .with_context(|| format!("removing {}", replaced.display()));
    }
    let complete = results::read_header(dir).is_ok_and(|h| h.status == Some(Status::Complete));
    if complete {
        std::fs::remove_dir_all(replaced)
            .with_context(|| format!("removing {}", replaced.display()))?;
    }
    Ok(())
}

/// A protocol killed in its first instants leaves `runs/` with no finished record and no
/// `summary.json` (or only its temporary): nothing to resume, nothing to keep.
fn clear_killed_start(dir: &Path) -> Result<()> {
    let runs = dir.join(records::RUNS);
    if std::fs::symlink_metadata(dir.join("summary.json")).is_ok() || !runs.is_dir() {
        return Ok(());
    }
    let recorded = std::fs::read_dir(&runs)
        .with_context(|| format!("reading {}", runs.display()))?
        .flatten()
        .any(|e| e.path().join("run.json").exists());
    if !recorded {
        std::fs::remove_dir_all(&runs).with_context(|| format!("removing {}", runs.display()))?;
    }
    Ok(())
}

/// Removes every result from the folder's top level (a partial replacement's).
fn remove_results(dir: &Path) -> Result<()> {
    for name in RESULT_FILES.iter().chain(report::FILES.iter()) {
        let path = dir.join(name);
        match std::fs::symlink_metadata(&path) {
            Ok(m) if m.is_dir() => std::fs::remove_dir_all(&path),
            Ok(_) => std::fs::remove_file(&path),
            Err(_) => continue,
        }
        .with_context(|| format!("removing {}", path.display()))?;
    }
    Ok(())
}

/// `out/<config stem>-<unix seconds>`: a new directory per run, so the default never
/// collides with earlier results.
pub fn default_out_dir(config: Option<&Path>) -> PathBuf {
    let stem = config
        .and_then(|p| p.file_stem())
        .map_or("cartpole".into(), |s| s.to_string_lossy().into_owned());
    let seconds = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    PathBuf::from("out").join(format!("{stem}-{seconds}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forced_results_move_aside_until_the_new_ones_are_written() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().to_path_buf();
        std::fs::write(dir.join("episodes.csv"), "old").unwrap();
        std::fs::create_dir(dir.join("policies")).unwrap();
        std::fs::write(dir.join("policies/p.ron"), "old").unwrap();
        let refused = open_output(&OutputOptions {
            dir: dir.clone(),
            force: false,
        });
        assert!(format!("{:#}", refused.unwrap_err()).contains("--force"));

        let (_lock, replaced) = open_output(&OutputOptions {
            dir: dir.clone(),
            force: true,
        })
        .unwrap();
        let replaced = replaced.unwrap();
        assert!(!dir.join("episodes.csv").exists());
        assert_eq!(
            std::fs::read_to_string(replaced.join("policies/p.ron")).unwrap(),
            "old"
        );
    }
}
