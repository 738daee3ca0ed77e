//! Whether a results folder changed since it was last read, told from a few `stat`s: what
//! `sapnet open` looks at every second before reading the folder again. A finished folder
//! is then read once (its `episodes.csv.xz` decompressed once), a live one as its writer
//! adds episodes and records.
//!
//! A writer changes what this sees: it holds the folder's lock (its PID is part of the
//! look, so a writer that starts or dies is a change), renames each finished run into
//! `runs/` (the directory's times change), appends to the partial records of the runs it
//! trains (looked at only while a writer holds the lock) and rewrites `summary.json`.

use std::os::unix::fs::MetadataExt;
use std::path::Path;

use super::records::RUNS;

/// What was seen of a folder's files: equal looks mean nothing was written between them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Look {
    writer: Option<u32>,
    files: Vec<Option<Stat>>,
}

/// A file's identity, size and times.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Stat {
    dev: u64,
    ino: u64,
    len: u64,
    mtime: (i64, i64),
    ctime: (i64, i64),
}

/// What is seen of the files `names` of `dir`: equal when none was written between.
pub(super) fn files(dir: &Path, names: &[&str]) -> Vec<Option<Stat>> {
    names.iter().map(|name| stat(&dir.join(name))).collect()
}

fn stat(path: &Path) -> Option<Stat> {
    let m = std::fs::symlink_metadata(path).ok()?;
    Some(Stat {
        dev: m.dev(),
        ino: m.ino(),
        len: m.len(),
        mtime: (m.mtime(), m.mtime_nsec()),
        ctime: (m.ctime(), m.ctime_nsec()),
    })
}

/// Looks at `dir` now.
pub fn look(dir: &Path) -> Look {
    let writer = crate::folder_lock::holder(dir)
        .ok()
        .flatten()
        .map(|h| h.pid);
    let runs = dir.join(RUNS);
    let mut files = files(
        dir,
        &[
            "summary.json",
            "episodes.csv",
            "episodes.csv.xz",
            "activations.csv",
            "activations.csv.xz",
        ],
    );
    files.push(stat(&runs));
    // A run in training grows its partial record without renaming anything; only a
    // writer does that, so only then are they looked at.
    if writer.is_some() {
        if let Ok(entries) = std::fs::read_dir(&runs) {
            let mut partial: Vec<_> = entries
                .flatten()
                .map(|e| e.file_name())
                .filter(|n| n.to_string_lossy().ends_with(".partial"))
                .collect();
            partial.sort();
            files.extend(
                partial
                    .iter()
                    .map(|n| stat(&runs.join(n).join("episodes.csv"))),
            );
        }
    }
    Look { writer, files }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_look_changes_when_a_file_is_written_and_not_otherwise() {
        let tmp = tempfile::tempdir().unwrap();
        std::fs::write(tmp.path().join("summary.json"), "{}").unwrap();
        let first = look(tmp.path());
        assert_eq!(look(tmp.path()), first);
        std::fs::create_dir(tmp.path().join(RUNS)).unwrap();
        let second = look(tmp.path());
        assert_ne!(second, first);
        std::fs::write(tmp.path().join("summary.json"), "{\"status\":1}").unwrap();
        assert_ne!(look(tmp.path()), second);
    }
}
