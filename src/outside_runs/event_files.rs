//! A run's TensorBoard event files: one file, or every file of a folder whose name holds
//! `tfevents` (TensorBoard's own rule), in the order of their names (TensorBoard's order,
//! which is the order a run resumed in one folder wrote them). Each scalar logged under the
//! return tag is one episode, at its event's step.
//!
//! A folder without event files holds runs as TensorBoard's logdir does: each folder of
//! event files under it is one run. Stable-Baselines3's `tensorboard_log=tb/dqn-0` writes
//! `tb/dqn-0/DQN_1/events…`, so its folders are looked for [`RUN_FOLDER_DEPTH`] levels down.

use std::collections::BTreeSet;
use std::fs::File;
use std::path::{Path, PathBuf};

use super::error::Location;
use super::{
    Axis, Format, Gathered, OutsideRun, OutsideRunError, ReadOptions, RETURN_TAG, ROLLOUT_MEAN_TAG,
};
use crate::safe_io::Links;
use crate::tensorboard::EventFile;

/// Reads the event file `file`, opened from `path`.
pub fn read_file(
    file: File,
    path: &Path,
    options: &ReadOptions,
) -> Result<OutsideRun, OutsideRunError> {
    let mut scan = Scan::new(options);
    scan.file(path, EventFile::from_file(file, path)?)?;
    scan.into_run(path)
}

/// How many levels under a folder without event files its runs' folders are looked for:
/// a folder of Stable-Baselines3 seeds' logs (`tb/dqn-0/DQN_1/`) is two above its files.
pub const RUN_FOLDER_DEPTH: usize = 2;

/// How many entries the search for run folders reads before it refuses: a folder named by
/// mistake (a home directory) is refused at once, not walked.
const MAX_ENTRIES_SEARCHED: usize = 100_000;

/// A folder's event files (by TensorBoard's rule, a name holding `tfevents`) and its
/// sub-folders, each sorted. A link is neither: a linked event file is listed, to be
/// refused when opened; a linked folder is never entered.
struct Listing {
    files: Vec<PathBuf>,
    folders: Vec<PathBuf>,
    entries: usize,
}

fn list(dir: &Path) -> Result<Listing, OutsideRunError> {
    let io_error = |error| OutsideRunError::Io {
        path: dir.to_path_buf(),
        error,
    };
    let mut listing = Listing {
        files: Vec::new(),
        folders: Vec::new(),
        entries: 0,
    };
    for entry in std::fs::read_dir(dir).map_err(io_error)? {
        let entry = entry.map_err(io_error)?;
        listing.entries += 1;
        if listing.entries > MAX_ENTRIES_SEARCHED {
            break;
        }
        let kind = entry.file_type().map_err(io_error)?;
        if kind.is_dir() {
            listing.folders.push(entry.path());
        } else if entry.file_name().to_string_lossy().contains("tfevents") {
            listing.files.push(entry.path());
        }
    }
    listing.files.sort();
    listing.folders.sort();
    Ok(listing)
}

/// The runs under the folder `dir`: `dir` itself if it holds event files, else every folder
/// that does within [`RUN_FOLDER_DEPTH`] levels under it, in the order of their paths.
pub fn run_folders(dir: &Path) -> Result<Vec<PathBuf>, OutsideRunError> {
    let mut runs = Vec::new();
    let mut level = vec![dir.to_path_buf()];
    let mut searched = 0;
    for depth in 0..=RUN_FOLDER_DEPTH {
        let mut next = Vec::new();
        for folder in level {
            let listing = list(&folder)?;
            searched += listing.entries;
            if searched > MAX_ENTRIES_SEARCHED {
                return Err(OutsideRunError::UnknownFormat {
                    path: dir.to_path_buf(),
                    why: "more than 100,000 entries searched for folders of event files: \
                          name the run folders themselves",
                });
            }
            if !listing.files.is_empty() {
                runs.push(folder);
            } else if depth < RUN_FOLDER_DEPTH {
                next.extend(listing.folders);
            }
        }
        level = next;
    }
    if runs.is_empty() {
        return Err(OutsideRunError::UnknownFormat {
            path: dir.to_path_buf(),
            why: "a folder without event files (no file name in it, or in the folders two \
                  levels under it, holds \"tfevents\")",
        });
    }
    if runs.len() > crate::limits::MAX_RUNS as usize {
        return Err(OutsideRunError::UnknownFormat {
            path: dir.to_path_buf(),
            why: "more than 10,000 folders of event files, each a run (at most 10,000 a method)",
        });
    }
    runs.sort();
    Ok(runs)
}

/// Reads the event files of the folder `dir` as one run. A link among them is refused, as
/// any link inside a folder is (see [`crate::safe_io`]); sub-folders are not looked in.
pub fn read_folder(dir: &Path, options: &ReadOptions) -> Result<OutsideRun, OutsideRunError> {
    let files = list(dir)?.files;
    if files.is_empty() {
        return Err(OutsideRunError::UnknownFormat {
            path: dir.to_path_buf(),
            why: "a folder without event files (no file name in it holds \"tfevents\")",
        });
    }
    let mut scan = Scan::new(options);
    for path in &files {
        scan.file(path, EventFile::open(path, Links::Refuse)?)?;
    }
    scan.into_run(dir)
}

/// A scalar kept while the files are read: which file, where in it, its step and value.
struct Point {
    file: usize,
    offset: u64,
    step: i64,
    value: f64,
}

/// The scalars of the tags a run may be read from, gathered file after file, and every
/// tag seen (for the message if none of them is there).
struct Scan {
    /// The return tags to try, in order.
    tags: Vec<String>,
    returns: Vec<Vec<Point>>,
    files: Vec<PathBuf>,
    seen: BTreeSet<String>,
}

impl Scan {
    fn new(options: &ReadOptions) -> Self {
        let mut tags = vec![options
            .tag
            .clone()
            .unwrap_or_else(|| RETURN_TAG.to_string())];
        if options.rollout_mean {
            tags.push(ROLLOUT_MEAN_TAG.to_string());
        }
        Self {
            returns: tags.iter().map(|_| Vec::new()).collect(),
            tags,
            files: Vec::new(),
            seen: BTreeSet::new(),
        }
    }

    fn file(&mut self, path: &Path, events: EventFile) -> Result<(), OutsideRunError> {
        let file = self.files.len();
        self.files.push(path.to_path_buf());
        for event in events {
            let event = event?;
            for scalar in event.scalars {
                let point = Point {
                    file,
                    offset: event.offset,
                    step: event.step,
                    value: scalar.value,
                };
                if let Some(i) = self.tags.iter().position(|t| *t == scalar.tag) {
                    self.returns[i].push(point);
                }
                self.seen.insert(scalar.tag);
            }
        }
        Ok(())
    }

    /// The run from the first tag that has scalars.
    fn into_run(self, path: &Path) -> Result<OutsideRun, OutsideRunError> {
        let Some(chosen) = self.returns.iter().position(|points| !points.is_empty()) else {
            return Err(OutsideRunError::MissingTag {
                path: path.to_path_buf(),
                tried: self.tags,
                found: self.seen.into_iter().collect(),
            });
        };
        let tag = &self.tags[chosen];
        let returns = &self.returns[chosen];
        let mut episodes = Gathered::new(Axis::Steps);
        for point in returns {
            if !point.value.is_finite() {
                return Err(OutsideRunError::NonFiniteReturn {
                    path: self.files[point.file].clone(),
                    at: Location::Event {
                        offset: point.offset,
                        tag: tag.clone(),
                    },
                    value: point.value,
                });
            }
            // Placed by their steps, episodes need no length (CleanRL's length tag).
            episodes.push(point.step, point.value, None);
        }
        Ok(episodes.into_run(path, Format::EventFiles, tag.clone()))
    }
}
