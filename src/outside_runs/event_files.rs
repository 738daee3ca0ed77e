//! A run's TensorBoard event files: one file, or every file of a folder whose name holds
//! `tfevents` (TensorBoard's own rule), in the order of their names (TensorBoard's order,
//! which is the order a run resumed in one folder wrote them). Each scalar logged under the
//! return tag is one episode, at its event's step.

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

/// Reads the event files of the folder `dir`. A link among them is refused, as any link
/// inside a folder is (see [`crate::safe_io`]); sub-folders are not looked in.
pub fn read_folder(dir: &Path, options: &ReadOptions) -> Result<OutsideRun, OutsideRunError> {
    let io_error = |error| OutsideRunError::Io {
        path: dir.to_path_buf(),
        error,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io_error)? {
        let entry = entry.map_err(io_error)?;
        let is_dir = entry.file_type().map_err(io_error)?.is_dir();
        if !is_dir && entry.file_name().to_string_lossy().contains("tfevents") {
            files.push(entry.path());
        }
    }
    if files.is_empty() {
        return Err(OutsideRunError::UnknownFormat {
            path: dir.to_path_buf(),
            why: "a folder without event files (no file name in it holds \"tfevents\")",
        });
    }
    files.sort();
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
