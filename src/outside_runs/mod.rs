//! Runs made by other tools, read as their episodes so that sapnet can score them beside
//! its own (issue 38). Each file is one run:
//!
//! - a Stable-Baselines3 `monitor.csv` (`monitor.rs`): a `#{…}` comment line, then
//!   `r,l,t`: each episode's return, length and wall time;
//! - a CSV with a header (`exported_csv.rs`): CleanRL's or openrlbenchmark's exports, an
//!   episodic-return column beside a step or episode column, named by the caller or found
//!   among common names ([`RETURN_COLUMNS`], [`STEP_COLUMNS`], [`EPISODE_COLUMNS`]);
//! - a TensorBoard event file, or a folder of them (`event_files.rs`): the scalars of one
//!   tag, [`RETURN_TAG`] unless the caller names another.
//!
//! - a sapnet results folder (`results_folder.rs`): the runs of one of its methods, each
//!   run one run;
//! - a `sapnet compare` folder's own record of the runs it compared (`compare_folder.rs`),
//!   which compare writes and `sapnet open` reads back.
//!
//! The format is told from the file's content (`detect.rs`), never from its name. Files are
//! read through [`crate::safe_io`]: regular files only, bounded in size; the path given
//! is the user's and may be a link, files found inside a folder may not.
//!
//! What a run scores is in `scores.rs`: [`OutsideRun::training_return`] and
//! [`OutsideRun::final_score`].

pub mod compare_folder;
mod detect;
mod error;
mod event_files;
mod exported_csv;
mod monitor;
pub mod results_folder;
mod scores;
mod table;

use std::io::{Read, Seek};
use std::path::{Path, PathBuf};

use crate::safe_io::{self, Links};
use crate::stats::episodes::TrainingEpisodes;
use crate::tensorboard::MAX_EVENT_FILE_BYTES;

pub use error::{Location, OutsideRunError};

/// Episodic-return columns tried in order when the caller names none: CleanRL's tag as
/// exported, then plainer names, then a monitor file's.
pub const RETURN_COLUMNS: [&str; 4] = ["charts/episodic_return", "episodic_return", "return", "r"];

/// Step columns tried in order when the caller names none: CleanRL's, then W&B's (`_step`
/// counts log calls, not environment steps: the caller who knows better names a column).
pub const STEP_COLUMNS: [&str; 3] = ["global_step", "step", "_step"];

/// Episode columns tried when no step column is found.
pub const EPISODE_COLUMNS: [&str; 1] = ["episode"];

/// Episode-length columns used if present (a run without one has no lengths).
pub const LENGTH_COLUMNS: [&str; 4] = ["charts/episodic_length", "episodic_length", "length", "l"];

/// The tag of episodic returns in event files unless the caller names one: CleanRL's.
pub const RETURN_TAG: &str = "charts/episodic_return";

/// The tag CleanRL logs each episode's length under, at the same step as its return.
pub const LENGTH_TAG: &str = "charts/episodic_length";

/// Stable-Baselines3's tag: the mean return of the last 100 episodes, logged every few
/// rollouts. Not one episode's return, so read only if [`ReadOptions::rollout_mean`] asks.
pub const ROLLOUT_MEAN_TAG: &str = "rollout/ep_rew_mean";

/// Which kind of file a run came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Stable-Baselines3's `monitor.csv`.
    Monitor,
    /// A CSV with a header.
    Csv,
    /// A TensorBoard event file, or a folder of them.
    EventFiles,
    /// A sapnet results folder's `episodes.csv`: one run of one method in it.
    ResultsFolder,
}

/// What a file places its episodes by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Environment steps since the run began, at the episode's end.
    Steps,
    /// Episodes, as the file numbers them.
    Episodes,
}

/// A run made by another tool: its episodes in the file's order, never none, each kept
/// as sapnet keeps its own (a return and a length, 12 bytes, whatever the file spent on
/// the row), so that a file of millions of rows costs about what its numbers do.
#[derive(Debug, Clone, PartialEq)]
pub struct OutsideRun {
    /// The file or folder it was read from.
    pub path: PathBuf,
    pub format: Format,
    /// The column or tag its returns were read from.
    pub series: String,
    /// What placed its episodes in the file.
    pub axis: Axis,
    /// Each episode's return, finite, and its length in steps (cut at `u32::MAX`): on the
    /// [`Axis::Steps`] the steps from the furthest end before it to its own (0 for an
    /// episode placed before one already read); on the [`Axis::Episodes`] the file's
    /// length, 0 where it gives none.
    pub episodes: TrainingEpisodes,
    /// Whether the lengths above are every episode's: always on the step axis, on the
    /// episode axis only when the file gives each episode's length.
    pub lengths_known: bool,
    /// The environment steps the run took by its last episode's end, when its file places
    /// episodes by step (the last one's step) or gives every length (their sum).
    steps: Option<u64>,
}

/// An [`OutsideRun`]'s episodes gathered row by row, keeping only what it scores by.
pub(crate) struct Gathered {
    axis: Axis,
    episodes: TrainingEpisodes,
    /// The furthest step an episode ended at so far, and the last episode's.
    furthest: i64,
    last: i64,
    /// The sum of the lengths so far, while every episode has one.
    length_sum: Option<u64>,
}

impl Gathered {
    pub fn new(axis: Axis) -> Self {
        Self {
            axis,
            episodes: TrainingEpisodes::default(),
            furthest: 0,
            last: 0,
            length_sum: Some(0),
        }
    }

    /// An episode that ended at `at` on the axis (a step, or an episode number), with
    /// its return and, if the file says, its length.
    pub fn push(&mut self, at: i64, episode_return: f64, length: Option<u64>) {
        let cut = |steps: u64| u32::try_from(steps).unwrap_or(u32::MAX);
        let kept = match self.axis {
            Axis::Steps => {
                let since = at.saturating_sub(self.furthest).max(0);
                self.furthest = self.furthest.max(at);
                self.last = at;
                cut(since as u64)
            }
            Axis::Episodes => {
                self.length_sum = self
                    .length_sum
                    .and_then(|sum| length.map(|l| sum.saturating_add(l)));
                length.map_or(0, cut)
            }
        };
        self.episodes.push(episode_return, kept);
    }

    pub fn is_empty(&self) -> bool {
        self.episodes.is_empty()
    }

    /// The run read from `path`'s `series`.
    pub fn into_run(self, path: &Path, format: Format, series: String) -> OutsideRun {
        let (steps, lengths_known) = match self.axis {
            Axis::Steps => (Some(self.last.max(0) as u64), true),
            Axis::Episodes => (self.length_sum, self.length_sum.is_some()),
        };
        OutsideRun {
            path: path.to_path_buf(),
            format,
            series,
            axis: self.axis,
            episodes: self.episodes,
            lengths_known,
            steps,
        }
    }
}

/// A CSV column that places each episode: by steps or by episode number.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PositionColumn {
    Step(String),
    Episode(String),
}

/// What to read from a run's file; every `None` means the defaults listed above.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// A CSV's return column; else the first of [`RETURN_COLUMNS`] it has.
    pub return_column: Option<String>,
    /// A CSV's step or episode column; else the first of [`STEP_COLUMNS`], then of
    /// [`EPISODE_COLUMNS`], it has.
    pub position_column: Option<PositionColumn>,
    /// A CSV's episode-length column; else the first of [`LENGTH_COLUMNS`] it has, if any.
    pub length_column: Option<String>,
    /// The tag of returns in event files; else [`RETURN_TAG`].
    pub tag: Option<String>,
    /// Whether event files without the tag are read from [`ROLLOUT_MEAN_TAG`] instead:
    /// Stable-Baselines3's moving mean, for runs that logged nothing else.
    pub rollout_mean: bool,
}

/// The largest file read: a results folder's CSV bound, or an event file's.
const MAX_FILE_BYTES: u64 = if safe_io::MAX_CSV_BYTES > MAX_EVENT_FILE_BYTES {
    safe_io::MAX_CSV_BYTES
} else {
    MAX_EVENT_FILE_BYTES
};

/// Every run `path` holds: a file is one run; a folder is one run if it holds event files,
/// else each folder of event files under it is (TensorBoard's logdir, Stable-Baselines3's
/// `tensorboard_log` layout `tb/DQN_1/events…`).
pub fn read_runs(path: &Path, options: &ReadOptions) -> Result<Vec<OutsideRun>, OutsideRunError> {
    let is_dir = std::fs::metadata(path)
        .map_err(|error| OutsideRunError::Io {
            path: path.to_path_buf(),
            error,
        })?
        .is_dir();
    if !is_dir {
        return Ok(vec![read_run(path, options)?]);
    }
    event_files::run_folders(path)?
        .iter()
        .map(|dir| event_files::read_folder(dir, options))
        .collect()
}

/// Reads the run in `path`, a file (its format told from its content) or a folder of
/// event files. `path` is the user's: it may be a link; files inside a folder may not.
pub fn read_run(path: &Path, options: &ReadOptions) -> Result<OutsideRun, OutsideRunError> {
    let io_error = |error| OutsideRunError::Io {
        path: path.to_path_buf(),
        error,
    };
    if std::fs::metadata(path).map_err(io_error)?.is_dir() {
        return event_files::read_folder(path, options);
    }
    let mut file = safe_io::open(path, Links::Follow, MAX_FILE_BYTES).map_err(io_error)?;
    let mut prefix = Vec::new();
    (&mut file)
        .take(detect::PREFIX_BYTES)
        .read_to_end(&mut prefix)
        .and_then(|_| file.rewind())
        .map_err(io_error)?;
    match detect::format(&prefix) {
        Ok(detect::Format::Monitor) => monitor::read(file, path),
        Ok(detect::Format::Csv) => exported_csv::read(file, path, options),
        Ok(detect::Format::EventFiles) => event_files::read_file(file, path, options),
        Err(why) => Err(OutsideRunError::UnknownFormat {
            path: path.to_path_buf(),
            why,
        }),
    }
}

#[cfg(test)]
mod tests;
