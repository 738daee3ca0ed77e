//! Why a run made by another tool could not be read: each names the file and, where it
//! applies, the place in it.

use std::fmt;
use std::io;
use std::path::PathBuf;

use crate::tensorboard::EventFileError;

/// A place in a file: a CSV cell or an event.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    /// A CSV cell: its 1-based line in the file, its 1-based column and the column's name.
    Cell {
        line: u64,
        column: usize,
        name: String,
    },
    /// A scalar of the event whose record starts at byte `offset`.
    Event { offset: u64, tag: String },
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Cell { line, column, name } => {
                write!(f, "line {line}, column {column} ({name})")
            }
            Location::Event { offset, tag } => write!(f, "the event at byte {offset} ({tag})"),
        }
    }
}

/// Why a run could not be read.
#[derive(Debug, thiserror::Error)]
pub enum OutsideRunError {
    // `error`s are not `source`s: the message says them, and an error chain would print
    // them twice.
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: io::Error },
    #[error("{}: not a run sapnet can read ({why}): a run is a Stable-Baselines3 monitor.csv, \
             a CSV with a header, or a TensorBoard event file or folder of them", path.display())]
    UnknownFormat { path: PathBuf, why: &'static str },
    #[error("{}: line {line}: more than the {limit} {what}", path.display())]
    TooManyRows {
        path: PathBuf,
        line: u64,
        limit: usize,
        what: &'static str,
    },
    #[error("{}: no episode: {what} holds no value", path.display())]
    NoEpisode { path: PathBuf, what: String },
    #[error("{}: {at}: {text:?} is not {expected}", path.display())]
    NotANumber {
        path: PathBuf,
        at: Location,
        text: String,
        expected: &'static str,
    },
    #[error("{}: {at}: the return {value} is not finite", path.display())]
    NonFiniteReturn {
        path: PathBuf,
        at: Location,
        value: f64,
    },
    #[error("{}: no column {} (the columns are {})", path.display(), either(tried), listed(found))]
    MissingColumn {
        path: PathBuf,
        tried: Vec<String>,
        found: Vec<String>,
    },
    #[error("{}: no scalar tagged {} (the tags are {}){}", path.display(), either(tried), listed(found), rollout_mean_hint(tried, found))]
    MissingTag {
        path: PathBuf,
        tried: Vec<String>,
        found: Vec<String>,
    },
    #[error("{}: no run of method {method:?} (its methods are {})", path.display(), listed(found))]
    NoSuchMethod {
        path: PathBuf,
        method: String,
        found: Vec<String>,
    },
    #[error("{}: {error}", path.display())]
    Csv { path: PathBuf, error: csv::Error },
    #[error(transparent)]
    EventFile(#[from] EventFileError),
}

/// Stable-Baselines3 logs no episode's return to TensorBoard, only the mean of its recent
/// episodes: where that is the tag there, say how to read it (and what it is).
fn rollout_mean_hint(tried: &[String], found: &[String]) -> String {
    let tag = super::ROLLOUT_MEAN_TAG;
    if found.iter().any(|t| t == tag) && !tried.iter().any(|t| t == tag) {
        format!(
            "; {tag:?} is Stable-Baselines3's mean return of its recent episodes, not each \
             episode's: `--rollout-mean` reads it, each logged mean taken as one episode (its \
             monitor.csv, where it wrote one, has every episode)"
        )
    } else {
        String::new()
    }
}

/// `"a", "b" or "c"`.
fn either(names: &[String]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("{n:?}")).collect();
    if quoted.len() > LISTED {
        return crate::shown_text::cut_list(quoted, LISTED);
    }
    match quoted.split_last() {
        None => String::new(),
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
    }
}

/// `"a", "b", "c"`, or `none`.
fn listed(names: &[String]) -> String {
    if names.is_empty() {
        return "none".to_string();
    }
    // A file may hold hundreds of thousands of them: the refusal stays a line.
    crate::shown_text::cut_list(names.iter().map(|n| format!("{n:?}")), LISTED)
}

/// The most names a refusal lists.
const LISTED: usize = 20;
