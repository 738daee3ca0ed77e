//! A CSV with a header exported from another tool's logs (CleanRL's runs through W&B,
//! openrlbenchmark's tables): a column of episodic returns beside one of steps or episode
//! numbers, and perhaps one of episode lengths.
//!
//! Such exports hold several series in one table: a row where the return column is empty
//! logged something else (a loss, the steps per second), and is no episode. Every other
//! row is one episode, in the file's order.

use std::fs::File;
use std::path::Path;

use super::table::{Comments, Table};
use super::{
    Axis, Format, Gathered, OutsideRun, OutsideRunError, PositionColumn, ReadOptions,
    EPISODE_COLUMNS, LENGTH_COLUMNS, RETURN_COLUMNS, STEP_COLUMNS,
};

/// Reads the CSV `file`, opened from `path`, with the columns `options` names.
pub fn read(file: File, path: &Path, options: &ReadOptions) -> Result<OutsideRun, OutsideRunError> {
    let mut table = Table::read(file, path, Comments::Data)?;
    let return_column = match &options.return_column {
        Some(name) => table.column(&[name])?,
        None => table.column(&RETURN_COLUMNS)?,
    };
    let (position_column, axis) = position(&table, options.position_column.as_ref())?;
    let length_column = match &options.length_column {
        Some(name) => Some(table.column(&[name])?),
        None => table.find(&LENGTH_COLUMNS),
    };
    let mut episodes = Gathered::new(axis);
    while let Some(row) = table.next_row() {
        let row = row?;
        let return_cell = table.cell(&row, return_column);
        if return_cell.is_empty() {
            continue;
        }
        let length = match length_column.map(|c| table.cell(&row, c)) {
            Some(cell) if !cell.is_empty() => Some(cell.length()?),
            _ => None,
        };
        let at = table.cell(&row, position_column).whole()?;
        episodes.push(at, return_cell.episode_return()?, length);
    }
    let series = table.name(return_column).to_string();
    if episodes.is_empty() {
        return Err(OutsideRunError::NoEpisode {
            path: path.to_path_buf(),
            what: format!("the column {series:?}"),
        });
    }
    Ok(episodes.into_run(path, Format::Csv, series))
}

/// The column that places episodes, and what it counts: the one the caller named, else
/// the first step column, else the first episode column.
fn position(
    table: &Table,
    named: Option<&PositionColumn>,
) -> Result<(usize, Axis), OutsideRunError> {
    match named {
        Some(PositionColumn::Step(name)) => Ok((table.column(&[name])?, Axis::Steps)),
        Some(PositionColumn::Episode(name)) => Ok((table.column(&[name])?, Axis::Episodes)),
        None => match table.find(&STEP_COLUMNS) {
            Some(column) => Ok((column, Axis::Steps)),
            None => {
                let either: Vec<&str> = STEP_COLUMNS
                    .iter()
                    .chain(&EPISODE_COLUMNS)
                    .copied()
                    .collect();
                Ok((table.column(&either)?, Axis::Episodes))
            }
        },
    }
}
