//! The `Event` message of an event file, written and read (from
//! `tensorboard/compat/proto/event.proto` and `summary.proto`):
//!
//! ```text
//! Event         { double wall_time = 1; int64 step = 2;
//!                 oneof what { string file_version = 3; Summary summary = 5; … } }
//! Summary       { repeated Value value = 1; }
//! Summary.Value { string tag = 1; SummaryMetadata metadata = 9;
//!                 oneof value { float simple_value = 2; TensorProto tensor = 8; … } }
//! ```

use super::protobuf::{self, DecodeError, Fields, Message};
use super::tensor;

/// What the first event of every file says: the version of the format it holds.
pub const FILE_VERSION: &str = "brain.Event:2";

/// The event that opens a file.
pub fn encode_file_version(wall_time: f64) -> Vec<u8> {
    Message::new()
        .double(1, wall_time)
        .string(3, FILE_VERSION)
        .into_bytes()
}

/// An event holding a summary of `values` (each an encoded `Summary.Value`).
pub fn encode_summary(wall_time: f64, step: i64, values: &[Message]) -> Vec<u8> {
    let summary = values
        .iter()
        .fold(Message::new(), |summary, value| summary.message(1, value));
    let event = Message::new().double(1, wall_time);
    // proto3 leaves a zero step out; readers take its absence as 0.
    let event = if step == 0 {
        event
    } else {
        event.int64(2, step)
    };
    event.message(5, &summary).into_bytes()
}

/// A `Summary.Value` holding a scalar the way torch's `SummaryWriter` writes one, which
/// every TensorBoard reads: a `simple_value`.
pub fn scalar_value(tag: &str, value: f32) -> Message {
    Message::new().string(1, tag).float(2, value)
}

/// An event read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// Where its record starts in the file, in bytes: for messages about it.
    pub offset: u64,
    /// When it was written, in seconds since the Unix epoch.
    pub wall_time: f64,
    /// The training step it was logged at.
    pub step: i64,
    /// `brain.Event:2` on a file's first event.
    pub file_version: Option<String>,
    /// The scalars of its summary, in order: `simple_value`s and one-value float tensors.
    /// Its other values (images, histograms, text, plugin data) are not kept.
    pub scalars: Vec<Scalar>,
}

/// One scalar of a summary.
#[derive(Debug, Clone, PartialEq)]
pub struct Scalar {
    pub tag: String,
    /// Widened from `f32` when the file stored a `float`.
    pub value: f64,
}

/// Decodes the `Event` at `offset`. Fields this reader does not use are skipped, as
/// protobuf readers do.
pub fn decode(offset: u64, data: &[u8]) -> Result<Event, DecodeError> {
    let mut event = Event {
        offset,
        wall_time: 0.0,
        step: 0,
        file_version: None,
        scalars: Vec::new(),
    };
    for field in Fields::new(data) {
        match field? {
            (1, payload) => event.wall_time = payload.as_f64().ok_or(DecodeError::WrongType)?,
            (2, payload) => event.step = payload.as_i64().ok_or(DecodeError::WrongType)?,
            (3, payload) => {
                let text = protobuf::text(payload.as_bytes().ok_or(DecodeError::WrongType)?)?;
                event.file_version = Some(text.to_string());
            }
            (5, payload) => {
                let summary = payload.as_bytes().ok_or(DecodeError::WrongType)?;
                for value in Fields::new(summary) {
                    if let (1, value) = value? {
                        let value = value.as_bytes().ok_or(DecodeError::WrongType)?;
                        event.scalars.extend(decode_scalar(value)?);
                    }
                }
            }
            _ => {}
        }
    }
    Ok(event)
}

/// The scalar a `Summary.Value` holds, if it holds one.
fn decode_scalar(value: &[u8]) -> Result<Option<Scalar>, DecodeError> {
    let mut tag = "";
    let mut number = None;
    for field in Fields::new(value) {
        match field? {
            (1, payload) => {
                tag = protobuf::text(payload.as_bytes().ok_or(DecodeError::WrongType)?)?;
            }
            (2, payload) => {
                let simple = payload.as_f32().ok_or(DecodeError::WrongType)?;
                number = Some(f64::from(simple));
            }
            (8, payload) => {
                number = tensor::scalar(payload.as_bytes().ok_or(DecodeError::WrongType)?)?;
            }
            _ => {}
        }
    }
    Ok(number.map(|value| Scalar {
        tag: tag.to_string(),
        value,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scalar_event_reads_back_as_written() {
        let values = [
            scalar_value("charts/episodic_return", 21.5),
            scalar_value("losses/td_loss", 0.0),
        ];
        let bytes = encode_summary(1_700_000_000.25, 4096, &values);
        let event = decode(12, &bytes).unwrap();
        assert_eq!(event.offset, 12);
        assert_eq!(event.wall_time, 1_700_000_000.25);
        assert_eq!(event.step, 4096);
        assert_eq!(event.file_version, None);
        let tags: Vec<_> = event
            .scalars
            .iter()
            .map(|s| (s.tag.as_str(), s.value))
            .collect();
        // A simple_value of 0.0 sits in a oneof and is written, so it reads back.
        assert_eq!(
            tags,
            [("charts/episodic_return", 21.5), ("losses/td_loss", 0.0)]
        );
        let first = decode(0, &encode_file_version(3.0)).unwrap();
        assert_eq!(first.file_version.as_deref(), Some(FILE_VERSION));
        assert_eq!((first.step, first.wall_time), (0, 3.0));
    }

    #[test]
    fn the_bytes_are_those_torch_summary_writer_writes() {
        // TensorBoard's own protos (tensorboard 2.21, tensorboard.compat.proto):
        //   e = event_pb2.Event(wall_time=1.5, step=3, summary=summary_pb2.Summary(
        //       value=[summary_pb2.Summary.Value(tag="a", simple_value=2.0)]))
        //   e.SerializeToString().hex()
        let expected = "09000000000000f83f10032a0a0a080a01611500000040";
        let bytes = encode_summary(1.5, 3, &[scalar_value("a", 2.0)]);
        let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(hex, expected);
    }
}
