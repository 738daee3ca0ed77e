//! A run's hyper-parameters as TensorBoard's HParams plugin reads them: a `Summary.Value`
//! tagged `_hparams_/session_start_info` that holds no value, only plugin data, and at the
//! run's end one tagged `_hparams_/session_end_info` (as torch's `SummaryWriter.add_hparams`
//! and `tensorboard.plugins.hparams` write them). The plugin finds the metrics itself,
//! among the run's scalars.
//!
//! From `tensorboard/compat/proto/summary.proto`, `plugins/hparams/plugin_data.proto`,
//! `api.proto` and protobuf's `struct.proto`:
//!
//! ```text
//! SummaryMetadata   { PluginData plugin_data = 1; }
//! PluginData        { string plugin_name = 1; bytes content = 2; }
//! HParamsPluginData { int32 version = 1;
//!                     oneof data { SessionStartInfo session_start_info = 3;
//!                                  SessionEndInfo session_end_info = 4; … } }
//! SessionStartInfo  { map<string, google.protobuf.Value> hparams = 1; double start_time_secs = 5; }
//! SessionEndInfo    { Status status = 1; double end_time_secs = 2; }
//! Value             { oneof kind { double number_value = 2; string string_value = 3;
//!                                  bool bool_value = 4; … } }
//! ```
//!
//! A map is written as repeated entries `{ key = 1; value = 2; }`.

use super::protobuf::Message;

const PLUGIN_NAME: &str = "hparams";
const SESSION_START_TAG: &str = "_hparams_/session_start_info";
const SESSION_END_TAG: &str = "_hparams_/session_end_info";

/// A hyper-parameter's value: the three kinds the HParams plugin shows.
#[derive(Debug, Clone, PartialEq)]
pub enum HParamValue {
    Text(String),
    Number(f64),
    Bool(bool),
}

impl From<&str> for HParamValue {
    fn from(text: &str) -> Self {
        Self::Text(text.to_string())
    }
}

impl From<String> for HParamValue {
    fn from(text: String) -> Self {
        Self::Text(text)
    }
}

impl From<f64> for HParamValue {
    fn from(number: f64) -> Self {
        Self::Number(number)
    }
}

/// Exact up to 2^53, which hyper-parameters stay well below.
impl From<i64> for HParamValue {
    fn from(number: i64) -> Self {
        Self::Number(number as f64)
    }
}

impl From<bool> for HParamValue {
    fn from(flag: bool) -> Self {
        Self::Bool(flag)
    }
}

/// How a run ended, as the HParams plugin lists its sessions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SessionStatus {
    /// The run did what it was asked.
    Success,
    /// The run failed or was stopped before its end.
    Failure,
}

/// The `Summary.Value` that starts a session with `hparams`, in their order, at
/// `start_time` (seconds since the Unix epoch).
pub fn session_start<'a>(
    hparams: impl IntoIterator<Item = (&'a str, &'a HParamValue)>,
    start_time: f64,
) -> Message {
    let info = hparams
        .into_iter()
        .fold(Message::new(), |info, (name, value)| {
            let entry = Message::new()
                .string(1, name)
                .message(2, &value_message(value));
            info.message(1, &entry)
        })
        .double(5, start_time);
    plugin_value(SESSION_START_TAG, Message::new().message(3, &info))
}

/// The `Summary.Value` that ends the session with `status` at `end_time`.
pub fn session_end(status: SessionStatus, end_time: f64) -> Message {
    // api.proto's Status: STATUS_SUCCESS = 1, STATUS_FAILURE = 2.
    let status = match status {
        SessionStatus::Success => 1,
        SessionStatus::Failure => 2,
    };
    let info = Message::new().int64(1, status).double(2, end_time);
    plugin_value(SESSION_END_TAG, Message::new().message(4, &info))
}

/// `google.protobuf.Value` of one hyper-parameter.
fn value_message(value: &HParamValue) -> Message {
    match value {
        HParamValue::Number(number) => Message::new().double(2, *number),
        HParamValue::Text(text) => Message::new().string(3, text),
        HParamValue::Bool(flag) => Message::new().bool(4, *flag),
    }
}

/// A `Summary.Value` tagged `tag` holding the hparams plugin's `data` (an
/// `HParamsPluginData` without its `version`: version 0 is proto3's default, left out as
/// TensorBoard's own writer leaves it).
fn plugin_value(tag: &str, data: Message) -> Message {
    let plugin_data = Message::new()
        .string(1, PLUGIN_NAME)
        .bytes_field(2, &data.into_bytes());
    let metadata = Message::new().message(1, &plugin_data);
    Message::new().string(1, tag).message(9, &metadata)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hex(message: Message) -> String {
        message
            .into_bytes()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }

    #[test]
    fn the_session_start_is_the_bytes_tensorboards_own_summary_writes() {
        // tensorboard 2.21:
        //   ssi = plugin_data_pb2.SessionStartInfo(start_time_secs=1.5)
        //   ssi.hparams["delta"].number_value = -0.5
        //   md = metadata.create_summary_metadata(
        //       plugin_data_pb2.HParamsPluginData(session_start_info=ssi))
        //   summary_pb2.Summary.Value(tag=metadata.SESSION_START_INFO_TAG, metadata=md)
        //       .SerializeToString().hex()
        // (one hyper-parameter: Python writes a map's entries in an order of its own).
        let expected = "0a1c5f68706172616d735f2f73657373696f6e5f73746172745f696e666f4a2c0a2a0a07\
                        68706172616d73121f1a1d0a120a0564656c7461120911000000000000e0bf29000000\
                        000000f83f";
        let delta = HParamValue::Number(-0.5);
        assert_eq!(hex(session_start([("delta", &delta)], 1.5)), expected);
    }

    #[test]
    fn text_and_flags_are_the_bytes_of_protobufs_value() {
        // struct_pb2.Value(string_value="sapnet"), (bool_value=False), (number_value=0.0):
        // a false flag and a zero, in a oneof, are still written.
        assert_eq!(hex(value_message(&"sapnet".into())), "1a067361706e6574");
        assert_eq!(hex(value_message(&false.into())), "2000");
        assert_eq!(hex(value_message(&0.0.into())), "110000000000000000");
    }

    #[test]
    fn the_session_end_is_the_bytes_tensorboards_own_summary_writes() {
        //   end = plugin_data_pb2.HParamsPluginData(session_end_info=
        //       plugin_data_pb2.SessionEndInfo(status=api_pb2.STATUS_SUCCESS, end_time_secs=2.5))
        //   summary_pb2.Summary.Value(tag=metadata.SESSION_END_INFO_TAG,
        //       metadata=metadata.create_summary_metadata(end)).SerializeToString().hex()
        let expected = "0a1a5f68706172616d735f2f73657373696f6e5f656e645f696e666f4a1a0a180a0768\
                        706172616d73120d220b0801110000000000000440";
        assert_eq!(hex(session_end(SessionStatus::Success, 2.5)), expected);
    }
}
