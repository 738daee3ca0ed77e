//! Event files as TensorBoard itself reads and writes them: what sapnet writes reads back
//! with its own reader and with TensorBoard's (`SAPNET_TEST_PYTHON`, else the active
//! virtualenv, with the `tensorboard` package); what TensorBoard's writers write —
//! `simple_value`s as torch's `SummaryWriter` logs them, tensors as TensorFlow 2 does —
//! reads with sapnet's. Without such a Python those tests say they are skipped.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use sapnet::safe_io::Links;
use sapnet::tensorboard::{read_events, EventWriter, HParamValue, SessionStatus, FILE_VERSION};
use serde_json::{json, Value};

/// The Python to check against, if it has TensorBoard.
fn python() -> Option<PathBuf> {
    let python = std::env::var_os("SAPNET_TEST_PYTHON")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("VIRTUAL_ENV").map(|v| PathBuf::from(v).join("bin/python")))?;
    let ok = Command::new(&python)
        .args(["-c", "import tensorboard"])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        eprintln!("{} has no tensorboard", python.display());
        return None;
    }
    Some(python)
}

macro_rules! python_or_skip {
    () => {
        match python() {
            Some(p) => p,
            None => {
                eprintln!("no Python with TensorBoard (SAPNET_TEST_PYTHON): skipped");
                return;
            }
        }
    };
}

/// Runs `script` with `args`; its standard output, parsed as JSON.
fn run_python(python: &Path, script: &str, args: &[&Path]) -> Value {
    let out = Command::new(python)
        .arg("-c")
        .arg(script)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "python failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The scalars every test writes: (tag, step, value), values exact in `f32`.
const SCALARS: [(&str, i64, f32); 5] = [
    ("charts/episodic_return", 12, 12.0),
    ("charts/episodic_return", 40, 28.0),
    ("losses/td_loss", 40, 0.125),
    ("charts/episodic_return", 97, -3.5),
    ("charts/episodic_return", 1 << 40, 0.0),
];

fn hparams() -> Vec<(&'static str, HParamValue)> {
    vec![
        ("method", "sapnet".into()),
        ("delta", (-0.5).into()),
        ("hidden_units", 100i64.into()),
        ("simple_paths", false.into()),
    ]
}

/// An event file of `SCALARS` and `hparams()` in a new directory.
fn write_run(dir: &Path) -> PathBuf {
    let mut writer = EventWriter::create(dir).unwrap();
    writer.hparams(&hparams()).unwrap();
    for (tag, step, value) in SCALARS {
        writer.scalar(tag, step, value).unwrap();
    }
    writer.end_session(SessionStatus::Success).unwrap();
    writer.path().to_path_buf()
}

#[test]
fn an_event_file_reads_back_as_written() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_run(&dir.path().join("run"));
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(name.starts_with("events.out.tfevents."), "{name}");
    let events = read_events(&path, Links::Refuse).unwrap();
    assert_eq!(events[0].file_version.as_deref(), Some(FILE_VERSION));
    let scalars: Vec<(String, i64, f64)> = events
        .iter()
        .flat_map(|e| e.scalars.iter().map(|s| (s.tag.clone(), e.step, s.value)))
        .collect();
    let written: Vec<(String, i64, f64)> = SCALARS
        .iter()
        .map(|&(tag, step, value)| (tag.to_string(), step, f64::from(value)))
        .collect();
    assert_eq!(scalars, written);
    assert!(events.windows(2).all(|w| w[0].wall_time <= w[1].wall_time));
    assert!(events.windows(2).all(|w| w[0].offset < w[1].offset));
    // A second writer in the same directory and second gets a file of its own.
    let second = EventWriter::create(&dir.path().join("run")).unwrap();
    assert_ne!(second.path(), path);
}

#[test]
fn tensorboard_reads_our_scalars_and_hparams() {
    let python = python_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    write_run(&run);
    let script = r#"
import json, sys
from tensorboard.backend.event_processing import event_accumulator, plugin_event_accumulator
from tensorboard.plugins.hparams import plugin_data_pb2

scalars = event_accumulator.EventAccumulator(sys.argv[1])
scalars.Reload()
out = {"scalars": {
    tag: [[e.step, e.value] for e in scalars.Scalars(tag)]
    for tag in scalars.Tags()["scalars"]
}}
plugins = plugin_event_accumulator.EventAccumulator(sys.argv[1])
plugins.Reload()
content = plugins.PluginTagToContent("hparams")
start = plugin_data_pb2.HParamsPluginData.FromString(content["_hparams_/session_start_info"])
out["hparams"] = {
    name: getattr(value, value.WhichOneof("kind"))
    for name, value in start.session_start_info.hparams.items()
}
end = plugin_data_pb2.HParamsPluginData.FromString(content["_hparams_/session_end_info"])
out["status"] = end.session_end_info.status
out["versions"] = [start.version, end.version]
print(json.dumps(out))
"#;
    let read = run_python(&python, script, &[&run]);
    assert_eq!(
        read["scalars"],
        json!({
            "charts/episodic_return": [[12, 12.0], [40, 28.0], [97, -3.5], [1u64 << 40, 0.0]],
            "losses/td_loss": [[40, 0.125]],
        })
    );
    assert_eq!(
        read["hparams"],
        json!({"method": "sapnet", "delta": -0.5, "hidden_units": 100.0, "simple_paths": false})
    );
    assert_eq!(read["status"], 1, "STATUS_SUCCESS");
    assert_eq!(read["versions"], json!([0, 0]));
}

#[test]
fn we_read_tensorboards_simple_values_and_tensorflow_2s_tensors() {
    let python = python_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    // TensorBoard's own writer (what torch's SummaryWriter wraps), without TensorFlow:
    // one file of simple_values as torch writes them, one of rank-0 tensors as
    // tf.summary.scalar does, float32 and float64.
    let script = r#"
import sys
import numpy as np
from tensorboard.compat.proto import event_pb2, summary_pb2
from tensorboard.plugins.scalar import metadata
from tensorboard.summary.writer.event_file_writer import EventFileWriter
from tensorboard.util import tensor_util

simple = EventFileWriter(sys.argv[1] + "/simple")
for step, value in [(5, 1.5), (9, -2.0)]:
    summary = summary_pb2.Summary(value=[summary_pb2.Summary.Value(
        tag="charts/episodic_return", simple_value=value)])
    simple.add_event(event_pb2.Event(wall_time=1.0, step=step, summary=summary))
simple.close()

tensors = EventFileWriter(sys.argv[1] + "/tensors")
for step, value in [(3, np.float32(0.25)), (4, np.float64(1.0 / 3.0))]:
    summary = summary_pb2.Summary(value=[summary_pb2.Summary.Value(
        tag="charts/episodic_return",
        metadata=metadata.create_summary_metadata(display_name="", description=""),
        tensor=tensor_util.make_tensor_proto(value))])
    tensors.add_event(event_pb2.Event(wall_time=1.0, step=step, summary=summary))
tensors.close()
print("{}")
"#;
    run_python(&python, script, &[dir.path()]);
    let read = |run: &str| -> Vec<(i64, f64)> {
        let run_dir = dir.path().join(run);
        let mut files: Vec<_> = std::fs::read_dir(&run_dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        assert_eq!(files.len(), 1, "{files:?}");
        let events = read_events(&files.remove(0), Links::Refuse).unwrap();
        assert_eq!(events[0].file_version.as_deref(), Some(FILE_VERSION));
        events
            .iter()
            .flat_map(|e| e.scalars.iter().map(move |s| (e.step, s.value)))
            .collect()
    };
    assert_eq!(read("simple"), [(5, 1.5), (9, -2.0)]);
    assert_eq!(read("tensors"), [(3, 0.25), (4, 1.0 / 3.0)]);
}
