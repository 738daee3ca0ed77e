//! TensorBoard's event files, written and read without TensorFlow: a run's scalars and
//! hyper-parameters for TensorBoard to show ([`EventWriter`]), and the scalars of event
//! files other tools wrote ([`EventFile`]: torch's `SummaryWriter`, which Stable-Baselines3
//! and CleanRL log through, and TensorFlow 2's `tf.summary`).
//!
//! An event file is a sequence of TFRecords (`record.rs`), each holding one `Event`
//! protocol buffer (`event.rs`); the first event names the format's version. The few
//! protobuf messages involved are encoded by hand (`protobuf.rs`), after TensorBoard's
//! `.proto` files, whose fields each module quotes.

mod event;
mod hparams;
mod protobuf;
mod reader;
mod record;
mod tensor;
mod writer;

pub use event::{Event, Scalar, FILE_VERSION};
pub use hparams::{HParamValue, SessionStatus};
pub use protobuf::DecodeError;
pub use reader::{read_events, EventFile, EventFileError, MAX_EVENT_FILE_BYTES};
pub use record::{Corruption, MAX_RECORD_BYTES};
pub use writer::EventWriter;

/// Whether `bytes`, the start of a file, open with a TFRecord header whose length's CRC
/// checks: how an event file is told from other files by its content.
pub fn starts_like_an_event_file(bytes: &[u8]) -> bool {
    bytes
        .get(..record::HEADER_BYTES)
        .and_then(|header| record::declared_length(header.try_into().expect("12 bytes")))
        .is_some()
}
