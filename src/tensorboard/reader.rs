//! Reading an event file back, event by event, every record's two CRCs checked.

use std::fs::File;
use std::io::{self, BufReader, Seek};
use std::path::{Path, PathBuf};

use super::event::{self, Event};
use super::protobuf::DecodeError;
use super::record::{Corruption, RecordError, Records};
use crate::safe_io::{self, Links};

/// The largest event file read: a long run's scalars take megabytes, with images and
/// histograms gigabytes; this bounds what a doctored file can make the reader go through.
pub const MAX_EVENT_FILE_BYTES: u64 = 16 << 30;

/// Why an event file could not be read to its end. Each names the file; a malformed
/// record names the byte where it starts.
#[derive(Debug, thiserror::Error)]
pub enum EventFileError {
    // Not `source`s: the message says them, and an error chain would print them twice.
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: io::Error },
    #[error("{}: the record at byte {offset}: {what}", path.display())]
    Corrupt {
        path: PathBuf,
        offset: u64,
        what: Corruption,
    },
    #[error("{}: the record at byte {offset} is not a TensorBoard event: {what}", path.display())]
    NotAnEvent {
        path: PathBuf,
        offset: u64,
        what: DecodeError,
    },
}

/// The events of one file, in order. The iteration ends at the first error: a file that
/// is still being written may end inside its last record, which is an error too
/// ([`Corruption::TooLong`] or [`Corruption::TruncatedHeader`] at its offset).
#[derive(Debug)]
pub struct EventFile {
    path: PathBuf,
    records: Records<BufReader<File>>,
    failed: bool,
}

impl EventFile {
    /// Opens `path` (see [`safe_io::open`]: a regular file of at most
    /// [`MAX_EVENT_FILE_BYTES`]; a link followed only if `links` says so).
    pub fn open(path: &Path, links: Links) -> Result<Self, EventFileError> {
        let file = safe_io::open(path, links, MAX_EVENT_FILE_BYTES)
            .map_err(|error| io_error(path, error))?;
        Self::from_file(file, path)
    }

    /// Reads `file`, opened from `path` as [`open`](Self::open) does (a caller that has
    /// already looked at its first bytes), from its start.
    pub fn from_file(mut file: File, path: &Path) -> Result<Self, EventFileError> {
        let len = file
            .rewind()
            .and_then(|()| file.metadata())
            .map_err(|error| io_error(path, error))?
            .len();
        Ok(Self {
            path: path.to_path_buf(),
            records: Records::new(BufReader::new(file), len),
            failed: false,
        })
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn next_event(&mut self) -> Result<Option<Event>, EventFileError> {
        let offset = self.records.offset();
        let record = self.records.next_record().map_err(|e| match e {
            RecordError::Io(error) => io_error(&self.path, error),
            RecordError::Corrupt(what) => EventFileError::Corrupt {
                path: self.path.clone(),
                offset,
                what,
            },
        })?;
        let Some((offset, data)) = record else {
            return Ok(None);
        };
        event::decode(offset, data)
            .map(Some)
            .map_err(|what| EventFileError::NotAnEvent {
                path: self.path.clone(),
                offset,
                what,
            })
    }
}

impl Iterator for EventFile {
    type Item = Result<Event, EventFileError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let next = self.next_event();
        self.failed = next.is_err();
        next.transpose()
    }
}

fn io_error(path: &Path, error: io::Error) -> EventFileError {
    EventFileError::Io {
        path: path.to_path_buf(),
        error,
    }
}

/// Every event of `path` (see [`EventFile::open`]).
pub fn read_events(path: &Path, links: Links) -> Result<Vec<Event>, EventFileError> {
    EventFile::open(path, links)?.collect()
}

#[cfg(test)]
mod tests {
    use super::super::record;
    use super::*;

    #[test]
    fn a_bad_crc_names_the_file_and_the_records_offset() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("events.out.tfevents.1.test");
        let mut bytes = Vec::new();
        record::write(&mut bytes, &event::encode_file_version(1.0)).unwrap();
        let second = bytes.len();
        let summary = event::encode_summary(2.0, 7, &[event::scalar_value("r", 1.0)]);
        record::write(&mut bytes, &summary).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 0x40;
        std::fs::write(&path, &bytes).unwrap();

        let mut events = EventFile::open(&path, Links::Refuse).unwrap();
        assert_eq!(
            events.next().unwrap().unwrap().file_version.as_deref(),
            Some(event::FILE_VERSION)
        );
        let err = events.next().unwrap().unwrap_err();
        assert!(
            matches!(err, EventFileError::Corrupt { offset, what: Corruption::DataCrc, .. } if offset == second as u64),
            "{err:?}"
        );
        let message = err.to_string();
        assert!(
            message.starts_with(&path.display().to_string()),
            "{message}"
        );
        assert!(message.contains(&format!("byte {second}")), "{message}");
        assert!(events.next().is_none(), "the walk ends at the first error");
    }

    #[test]
    fn a_record_that_is_not_an_event_is_refused_with_its_offset() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("not-events");
        let mut bytes = Vec::new();
        // Field 1, wire type 3: a group, which no event holds.
        record::write(&mut bytes, &[0x0b]).unwrap();
        std::fs::write(&path, &bytes).unwrap();
        let err = read_events(&path, Links::Refuse).unwrap_err();
        assert!(
            matches!(
                err,
                EventFileError::NotAnEvent {
                    offset: 0,
                    what: DecodeError::WireType(3),
                    ..
                }
            ),
            "{err:?}"
        );
    }
}
