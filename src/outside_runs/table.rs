//! A CSV file read by its header's column names, each cell turned into a number with an
//! error that names the file, the line and the column.

use std::io::Read;
use std::path::{Path, PathBuf};

use super::error::{Location, OutsideRunError};

/// A CSV's header, and the rows after it.
pub struct Table {
    path: PathBuf,
    names: Vec<String>,
    rows: csv::StringRecordsIntoIter<Box<dyn Read>>,
    /// Rows read so far, and the most that may be ([`Table::at_most`]).
    read: usize,
    limit: (usize, &'static str),
}

/// Whether lines starting with `#` are comments (a monitor file's first line is one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Comments {
    Skipped,
    Data,
}

impl Table {
    /// Reads the header of `file`, opened from `path`. Cells are trimmed: exports pad them.
    pub fn read(
        file: impl Read + 'static,
        path: &Path,
        comments: Comments,
    ) -> Result<Self, OutsideRunError> {
        let mut reader = csv::ReaderBuilder::new()
            .comment((comments == Comments::Skipped).then_some(b'#'))
            .trim(csv::Trim::All)
            // A row is held whole: its length is bounded, whatever the file holds.
            .from_reader(Box::new(crate::safe_io::bounded_lines(file, path)) as Box<dyn Read>);
        let names = reader
            .headers()
            .map_err(|error| csv_error(path, error))?
            .iter()
            .map(str::to_string)
            .collect();
        Ok(Self {
            path: path.to_path_buf(),
            names,
            rows: reader.into_records(),
            read: 0,
            limit: (
                crate::limits::MAX_VALUES_KEPT,
                "rows sapnet reads from one file",
            ),
        })
    }

    /// At most `rows` rows are read (`what` says what they are), a row past them refused
    /// naming the file, its line and the bound.
    pub fn at_most(mut self, rows: usize, what: &'static str) -> Self {
        self.limit = (rows, what);
        self
    }

    /// The index of the first of `candidates` the header holds.
    pub fn find(&self, candidates: &[&str]) -> Option<usize> {
        candidates
            .iter()
            .find_map(|c| self.names.iter().position(|n| n == c))
    }

    /// The index of the first of `candidates` the header holds; if none, an error listing
    /// the columns there are.
    pub fn column(&self, candidates: &[&str]) -> Result<usize, OutsideRunError> {
        self.find(candidates)
            .ok_or_else(|| OutsideRunError::MissingColumn {
                path: self.path.clone(),
                tried: candidates.iter().map(|c| c.to_string()).collect(),
                found: self.names.clone(),
            })
    }

    /// The column's name.
    pub fn name(&self, column: usize) -> &str {
        &self.names[column]
    }

    /// The next row, or `None` after the last.
    pub fn next_row(&mut self) -> Option<Result<Row, OutsideRunError>> {
        let record = self.rows.next()?;
        self.read += 1;
        if self.read > self.limit.0 {
            let line = record
                .as_ref()
                .ok()
                .and_then(|r| r.position())
                .map_or(0, csv::Position::line);
            return Some(Err(OutsideRunError::TooManyRows {
                path: self.path.clone(),
                line,
                limit: self.limit.0,
                what: self.limit.1,
            }));
        }
        Some(
            record
                .map(|record| Row {
                    line: record.position().map_or(0, csv::Position::line),
                    record,
                })
                .map_err(|error| csv_error(&self.path, error)),
        )
    }

    /// The cell of `row` in `column` (a row shorter than the header is a CSV error before
    /// it gets here).
    pub fn cell<'a>(&'a self, row: &'a Row, column: usize) -> Cell<'a> {
        Cell {
            table: self,
            text: row.record.get(column).unwrap_or(""),
            line: row.line,
            column,
        }
    }
}

/// A row of the table.
pub struct Row {
    record: csv::StringRecord,
    /// 1-based, counting the header and comment lines.
    line: u64,
}

impl Row {
    /// Its line in the file, 1-based, counting the header and comment lines.
    pub fn line(&self) -> u64 {
        self.line
    }
}

/// One cell, with what it takes to say where it is.
pub struct Cell<'a> {
    table: &'a Table,
    text: &'a str,
    line: u64,
    column: usize,
}

impl<'a> Cell<'a> {
    /// Whether it holds nothing: in an export of several series, a row where this one was
    /// not logged.
    pub fn is_empty(&self) -> bool {
        self.text.is_empty()
    }

    /// Its text, trimmed.
    pub fn text(&self) -> &'a str {
        self.text
    }

    /// A finite episodic return.
    pub fn episode_return(&self) -> Result<f64, OutsideRunError> {
        let value = self.number()?;
        if !value.is_finite() {
            return Err(OutsideRunError::NonFiniteReturn {
                path: self.table.path.clone(),
                at: self.location(),
                value,
            });
        }
        Ok(value)
    }

    /// A whole number: a step or an episode number. `1000.0` and `1e3` are whole (some
    /// exports write every number as a float).
    pub fn whole(&self) -> Result<i64, OutsideRunError> {
        if let Ok(n) = self.text.parse::<i64>() {
            return Ok(n);
        }
        // 2^63, exact in f64: within ±2^63 the cast to i64 is exact.
        const BOUND: f64 = 9_223_372_036_854_775_808.0;
        match self.text.parse::<f64>() {
            Ok(x) if x.fract() == 0.0 && (-BOUND..BOUND).contains(&x) => Ok(x as i64),
            _ => Err(self.not("a whole number")),
        }
    }

    /// An episode's length: a whole number, not negative.
    pub fn length(&self) -> Result<u64, OutsideRunError> {
        self.whole()
            .ok()
            .and_then(|n| u64::try_from(n).ok())
            .ok_or_else(|| self.not("a whole number of steps"))
    }

    fn number(&self) -> Result<f64, OutsideRunError> {
        self.text.parse::<f64>().map_err(|_| self.not("a number"))
    }

    fn not(&self, expected: &'static str) -> OutsideRunError {
        OutsideRunError::NotANumber {
            path: self.table.path.clone(),
            at: self.location(),
            text: self.text.to_string(),
            expected,
        }
    }

    fn location(&self) -> Location {
        Location::Cell {
            line: self.line,
            column: self.column + 1,
            name: self.table.name(self.column).to_string(),
        }
    }
}

fn csv_error(path: &Path, error: csv::Error) -> OutsideRunError {
    OutsideRunError::Csv {
        path: path.to_path_buf(),
        error,
    }
}
