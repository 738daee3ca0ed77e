//! A sapnet results folder read as runs, so that its runs can join a comparison with runs
//! of other tools (`sapnet compare --method NAME=DIR`): each run of one method in the
//! folder's `episodes.csv` (columns `run`, `method`, `episode`, `reward`) is one run,
//! episode by episode. The folder may come from elsewhere: its file is read as a regular
//! file only, bounded in size, never through a link.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::table::{Comments, Table};
use super::{Axis, Format, Gathered, OutsideRun, OutsideRunError};
use crate::safe_io;

/// The file of a results folder that holds every episode of every run.
pub const EPISODES: &str = "episodes.csv";

/// Whether `dir` looks like a sapnet results folder: it has a `summary.json`. (A folder of
/// event files has none.)
pub fn is_results_folder(dir: &Path) -> bool {
    std::fs::symlink_metadata(dir.join("summary.json")).is_ok_and(|m| m.is_file())
}

/// The runs of the method labelled `method` in the results folder `dir`, in the order of
/// their run numbers; refused, listing the folder's methods, if it has none of them.
pub fn read_method(dir: &Path, method: &str) -> Result<Vec<OutsideRun>, OutsideRunError> {
    let path = dir.join(EPISODES);
    // The docs' folders ship their episodes compressed: read either.
    let file = safe_io::open_csv(&path).map_err(|error| OutsideRunError::Io {
        path: path.clone(),
        error,
    })?;
    let mut table = Table::read(file, &path, Comments::Data)?;
    let run_column = table.column(&["run"])?;
    let method_column = table.column(&["method"])?;
    let episode_column = table.column(&["episode"])?;
    let reward_column = table.column(&["reward"])?;
    let mut runs: BTreeMap<i64, Gathered> = BTreeMap::new();
    // The folder's other methods, in the order met, for the refusal: a set beside the list
    // keeps a file of 200,000 labels linear.
    let mut methods: Vec<String> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    while let Some(row) = table.next_row() {
        let row = row?;
        let label = table.cell(&row, method_column).text();
        if label != method {
            if !seen.contains(label) {
                seen.insert(label.to_string());
                methods.push(label.to_string());
            }
            continue;
        }
        let run = table.cell(&row, run_column).whole()?;
        let at = table.cell(&row, episode_column).whole()?;
        let episode_return = table.cell(&row, reward_column).episode_return()?;
        runs.entry(run)
            .or_insert_with(|| Gathered::new(Axis::Episodes))
            .push(at, episode_return, None);
    }
    if runs.is_empty() {
        return Err(OutsideRunError::NoSuchMethod {
            path,
            method: method.to_string(),
            found: methods,
        });
    }
    Ok(runs
        .into_iter()
        .map(|(run, episodes)| {
            episodes.into_run(
                &run_path(dir, method, run),
                Format::ResultsFolder,
                "reward".to_string(),
            )
        })
        .collect())
}

/// How a run of a results folder is named where a run's file would be: `DIR#method/run`.
fn run_path(dir: &Path, method: &str, run: i64) -> PathBuf {
    let mut name = dir.as_os_str().to_owned();
    name.push(format!("#{method}/{run}"));
    PathBuf::from(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(episodes: &str) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("summary.json"), "{}").unwrap();
        std::fs::write(dir.path().join(EPISODES), episodes).unwrap();
        dir
    }

    #[test]
    fn each_run_of_the_method_is_one_run_in_run_order() {
        let dir = folder(
            "run,method,episode,reward,steps,policy\n\
             1,ucb1,1,10.0,10,0\n\
             0,ucb1,1,20.0,20,0\n\
             0,\"dqn[100]\",1,9.0,9,\n\
             0,ucb1,2,30.0,30,1\n",
        );
        assert!(is_results_folder(dir.path()));
        let runs = read_method(dir.path(), "ucb1").unwrap();
        assert_eq!(runs.len(), 2);
        let returns: Vec<Vec<f64>> = runs.iter().map(|r| r.returns().collect()).collect();
        assert_eq!(returns, [vec![20.0, 30.0], vec![10.0]]);
        assert!(runs[1].path.to_string_lossy().ends_with("#ucb1/1"));
        let dqn = read_method(dir.path(), "dqn[100]").unwrap();
        assert_eq!(dqn[0].returns().collect::<Vec<_>>(), [9.0]);
    }

    #[test]
    fn a_method_the_folder_lacks_is_refused_naming_those_it_has() {
        let dir = folder("run,method,episode,reward\n0,ucb1,1,20.0\n0,random,1,5.0\n");
        let error = read_method(dir.path(), "sapnet").unwrap_err().to_string();
        assert!(error.contains("no run of method \"sapnet\""), "{error}");
        assert!(error.contains("\"ucb1\", \"random\""), "{error}");
    }

    #[test]
    fn episodes_shipped_compressed_are_read_as_they_are() {
        let dir = tempfile::tempdir().unwrap();
        let mut xz = Vec::new();
        lzma_rs::xz_compress(
            &mut &b"run,method,episode,reward\n0,ucb1,1,7.5\n0,ucb1,2,8.5\n"[..],
            &mut xz,
        )
        .unwrap();
        std::fs::write(dir.path().join("episodes.csv.xz"), xz).unwrap();
        let runs = read_method(dir.path(), "ucb1").unwrap();
        assert_eq!(runs[0].returns().collect::<Vec<_>>(), [7.5, 8.5]);
    }

    #[test]
    fn a_damaged_compressed_file_is_named() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("episodes.csv.xz"), b"\xfd7zXZ").unwrap();
        let error = read_method(dir.path(), "ucb1").unwrap_err().to_string();
        assert!(error.contains("episodes.csv.xz"), "{error}");
    }

    #[cfg(unix)]
    #[test]
    fn a_planted_link_is_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let elsewhere = dir.path().join("elsewhere.csv");
        std::fs::write(&elsewhere, "run,method,episode,reward\n0,ucb1,1,1.0\n").unwrap();
        let results = dir.path().join("results");
        std::fs::create_dir(&results).unwrap();
        std::os::unix::fs::symlink(&elsewhere, results.join(EPISODES)).unwrap();
        let error = read_method(&results, "ucb1").unwrap_err().to_string();
        assert!(error.contains("symbolic link"), "{error}");
    }
}
