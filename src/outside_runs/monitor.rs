//! Stable-Baselines3's `monitor.csv`, which its `Monitor` wrapper writes for one
//! environment:
//!
//! ```text
//! #{"t_start": 1733222400.1, "env_id": "CartPole-v1"}
//! r,l,t
//! 22.0,22,0.013
//! ```
//!
//! `r` is an episode's return, `l` its length, `t` the seconds since `t_start` when it
//! ended (not needed here); extra columns hold logged info keywords. An episode ends at the
//! environment step that is the sum of the lengths so far.

use std::fs::File;
use std::path::Path;

use super::table::{Comments, Table};
use super::{Axis, Format, Gathered, OutsideRun, OutsideRunError};

/// Reads the monitor file `file`, opened from `path`: at most
/// [`MAX_EPISODES`](crate::limits::MAX_EPISODES) rows.
pub fn read(file: File, path: &Path) -> Result<OutsideRun, OutsideRunError> {
    read_at_most(file, path, crate::limits::MAX_EPISODES as usize)
}

/// [`read`], at most `rows` rows (a test's bound scaled down).
pub(super) fn read_at_most(
    file: File,
    path: &Path,
    rows: usize,
) -> Result<OutsideRun, OutsideRunError> {
    let mut table = Table::read(file, path, Comments::Skipped)?
        .at_most(rows, "episodes a run may have (a row each)");
    let return_column = table.column(&["r"])?;
    let length_column = table.column(&["l"])?;
    let mut episodes = Gathered::new(Axis::Steps);
    let mut steps: i64 = 0;
    while let Some(row) = table.next_row() {
        let row = row?;
        let episode_return = table.cell(&row, return_column).episode_return()?;
        let length = table.cell(&row, length_column).length()?;
        steps = steps.saturating_add(i64::try_from(length).unwrap_or(i64::MAX));
        episodes.push(steps, episode_return, Some(length));
    }
    if episodes.is_empty() {
        return Err(OutsideRunError::NoEpisode {
            path: path.to_path_buf(),
            what: "the column \"r\"".to_string(),
        });
    }
    Ok(episodes.into_run(path, Format::Monitor, "r".to_string()))
}
