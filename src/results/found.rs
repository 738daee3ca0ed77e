//! The folders sapnet wrote under a parent folder, found recursively (TensorBoard's
//! `--logdir`): a protocol's results folder (its `summary.json`), a sweep folder (its
//! `sweep.ron`), a `sapnet compare` folder (its `comparison.csv` and `runs.csv`), each with
//! what a list of them says — its task, its methods, its runs, where it stands.
//!
//! The parent is untrusted input like every folder sapnet reads: the walk goes at most
//! [`MAX_DEPTH`] folders down, reads at most [`MAX_ENTRIES`] directory entries in all and
//! lists at most [`MAX_FOUND`] folders, never follows a symbolic link (a link to a folder
//! is neither listed nor entered: `DirEntry::file_type` does not follow it), never enters
//! a folder it found (a results folder's `runs/` and `policies/` are its own) nor a hidden
//! one (`.replaced/`), and reads each summary through [`crate::safe_io`]'s bounded,
//! link-refusing readers. A folder that cannot be read is listed with why.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use crate::folder_lock;

use super::Status;

/// How many folders below the parent the walk goes (the parent's children are 1).
pub const MAX_DEPTH: usize = 4;
/// Directory entries read in all before the walk stops (and says so).
pub const MAX_ENTRIES: usize = 50_000;
/// Folders listed before the walk stops (and says so).
pub const MAX_FOUND: usize = 1_000;

/// What a folder found holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A protocol's results (`sapnet --out`, a shipped report).
    Protocol,
    /// A sweep (`sapnet sweep plan --out`).
    Sweep,
    /// A comparison of existing runs (`sapnet compare --out`).
    Compare,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Protocol => "protocol",
            Kind::Sweep => "sweep",
            Kind::Compare => "compare",
        }
    }
}

/// A folder found, as the list says it.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    pub dir: PathBuf,
    pub kind: Kind,
    /// The task (`CartPole-v1`), or `-` where the folder does not say.
    pub task: String,
    /// Its methods' labels, in its order.
    pub methods: Vec<String>,
    /// Its planned runs (a sweep's: its cells).
    pub runs: usize,
    /// Where it stands: `complete`, `stopped`, `written by PID 1234 since 10:02 UTC`, or
    /// why it cannot be read.
    pub state: String,
}

/// What the walk found, and why it stopped early if it did.
#[derive(Debug, Clone, Default)]
pub struct Search {
    pub found: Vec<Found>,
    pub cut: Option<String>,
}

/// What `dir` is, by the files that mark it, if sapnet wrote it.
pub fn kind(dir: &Path) -> Option<Kind> {
    let file = |name: &str| std::fs::symlink_metadata(dir.join(name)).is_ok_and(|m| m.is_file());
    // Any entry named summary.json: a link there is the results reader's to refuse, by name.
    if std::fs::symlink_metadata(dir.join("summary.json")).is_ok() {
        Some(Kind::Protocol)
    } else if file("sweep.ron") {
        Some(Kind::Sweep)
    } else if file("comparison.csv") && file("runs.csv") {
        Some(Kind::Compare)
    } else {
        None
    }
}

/// The folders sapnet wrote under `parent` (itself included, if it is one), breadth
/// first, each level's in name order.
pub fn find(parent: &Path) -> Search {
    let mut search = Search::default();
    let mut entries = 0usize;
    let mut queue: VecDeque<(PathBuf, usize)> = VecDeque::from([(parent.to_path_buf(), 0)]);
    while let Some((dir, depth)) = queue.pop_front() {
        if let Some(kind) = kind(&dir) {
            if search.found.len() == MAX_FOUND {
                search.cut = Some(format!("the first {MAX_FOUND} folders found are listed"));
                break;
            }
            search.found.push(describe(&dir, kind));
            continue;
        }
        if depth == MAX_DEPTH {
            continue;
        }
        let Ok(read) = std::fs::read_dir(&dir) else {
            continue;
        };
        let mut children = Vec::new();
        for entry in read.flatten() {
            entries += 1;
            if entries > MAX_ENTRIES {
                search.cut = Some(format!(
                    "the walk stopped after {MAX_ENTRIES} entries: open a folder nearer them"
                ));
                break;
            }
            // Not followed: a link is its own type here, neither a folder nor entered.
            let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
            let hidden = entry.file_name().to_string_lossy().starts_with('.');
            if is_dir && !hidden {
                children.push(entry.path());
            }
        }
        children.sort();
        queue.extend(children.into_iter().map(|c| (c, depth + 1)));
        if search.cut.is_some() {
            break;
        }
    }
    search
}

/// What the list says of the folder `dir` of `kind`.
fn describe(dir: &Path, kind: Kind) -> Found {
    let mut found = Found {
        dir: dir.to_path_buf(),
        kind,
        task: "-".into(),
        methods: Vec::new(),
        runs: 0,
        state: String::new(),
    };
    let read = match kind {
        Kind::Protocol => protocol(dir, &mut found),
        Kind::Sweep => sweep(dir, &mut found),
        Kind::Compare => compare(dir, &mut found),
    };
    if let Err(error) = read {
        found.state = format!(
            "unreadable: {}",
            crate::shown_text::cut(&format!("{error:#}"), 200)
        );
    }
    found
}

fn protocol(dir: &Path, found: &mut Found) -> anyhow::Result<()> {
    let header = super::read_header(dir)?;
    let config = &header.config;
    found.task = config.env.gym_id();
    found.methods = config.protocol.methods.iter().map(|m| m.label()).collect();
    found.runs = config.protocol.methods.len() * config.protocol.runs as usize;
    found.state = match folder_lock::holder(dir)? {
        Some(writer) => format!("written by {}", writer.describe()),
        None => match header.status {
            // `running` with no process holding the lock: the process was killed.
            Some(Status::Running) => "interrupted".into(),
            Some(status) => format!("{status:?}").to_lowercase(),
            None => "complete".into(),
        },
    };
    Ok(())
}

fn sweep(dir: &Path, found: &mut Found) -> anyhow::Result<()> {
    let manifest = super::sweep::Manifest::read(dir)?;
    found.runs = manifest.cells.len();
    found.methods = vec![format!("{} cells", manifest.cells.len())];
    found.state = "sweep".into();
    Ok(())
}

fn compare(dir: &Path, found: &mut Found) -> anyhow::Result<()> {
    let path = dir.join("runs.csv");
    let mut reader = crate::safe_io::csv_reader(&path)
        .map_err(|e| anyhow::anyhow!("reading {}: {e}", path.display()))?;
    for record in reader.records() {
        let record = record.map_err(|e| anyhow::anyhow!("reading {}: {e}", path.display()))?;
        let method = crate::shown_text::cut(record.get(0).unwrap_or(""), 60);
        if !found.methods.contains(&method) {
            found.methods.push(method);
        }
        found.runs += 1;
    }
    found.state = "compared".into();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn links_hidden_folders_and_depth_bound_the_walk() {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path();
        let mark = |dir: &Path| {
            std::fs::create_dir_all(dir).unwrap();
            std::fs::write(dir.join("comparison.csv"), "method\n").unwrap();
            std::fs::write(dir.join("runs.csv"), "method,run\nppo,0\ndqn,0\nppo,1\n").unwrap();
        };
        mark(&root.join("a/cmp"));
        mark(&root.join("a/cmp/inner")); // inside a folder found: not entered
        mark(&root.join(".hidden/cmp"));
        mark(&root.join("1/2/3/4/deep")); // 5 levels down
        mark(&root.join("1/2/3/ok"));
        std::os::unix::fs::symlink(root.join("a"), root.join("link")).unwrap();
        let search = find(root);
        let dirs: Vec<&Path> = search.found.iter().map(|f| f.dir.as_path()).collect();
        assert_eq!(dirs, [root.join("a/cmp"), root.join("1/2/3/ok")]);
        let cmp = &search.found[0];
        assert_eq!(cmp.kind, Kind::Compare);
        assert_eq!(cmp.methods, ["ppo", "dqn"]);
        assert_eq!(cmp.runs, 3);
        assert!(search.cut.is_none());
    }
}
