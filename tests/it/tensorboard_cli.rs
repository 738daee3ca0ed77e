//! `--tensorboard` as a user runs it: each run's event file under `<out>/tensorboard/`,
//! whose episodic returns are `episodes.csv`'s, read by our reader and, where the test's
//! Python has the `tensorboard` package (CI's virtualenv), by TensorBoard's own.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use sapnet::experiment::event_dir_name;
use sapnet::safe_io::Links;
use sapnet::tensorboard::read_events;

/// Each run's returns in `episodes.csv`, by its event folder's name (`dqn[16]-run0`).
fn returns_in_episodes_csv(out: &Path) -> BTreeMap<String, Vec<f64>> {
    let mut reader = csv::Reader::from_path(out.join("episodes.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut rows: Vec<(String, u32, f64)> = reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            (
                event_dir_name(&r[col("method")], r[col("run")].parse().unwrap()),
                r[col("episode")].parse().unwrap(),
                r[col("reward")].parse().unwrap(),
            )
        })
        .collect();
    rows.sort_by(|a, b| (&a.0, a.1).cmp(&(&b.0, b.1)));
    let mut runs: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for (run, _, reward) in rows {
        runs.entry(run).or_default().push(reward);
    }
    runs
}

/// The one event file of a run's folder.
fn event_file(run: &Path) -> PathBuf {
    let files: Vec<PathBuf> = std::fs::read_dir(run)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1, "one event file in {run:?}: {files:?}");
    files.into_iter().next().unwrap()
}

fn run_quick(out: &Path) {
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/configs/short_cartpole.ron");
    let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(["--headless", "--tensorboard", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

#[test]
fn each_runs_event_file_holds_its_episodic_returns() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    run_quick(&out);
    let expected = returns_in_episodes_csv(&out);
    let names: Vec<&String> = expected.keys().collect();
    assert_eq!(
        names,
        ["dqn[16]-run0", "dqn[16]-run1"],
        "named as the results name them"
    );
    let mut python_runs = Vec::new();
    for (run, returns) in &expected {
        let dir = out.join("tensorboard").join(run);
        let events = read_events(&event_file(&dir), Links::Refuse).unwrap();
        let scalars = |tag: &str| -> Vec<(i64, f64)> {
            events
                .iter()
                .flat_map(|e| e.scalars.iter().map(move |s| (e.step, s)))
                .filter(|(_, s)| s.tag == tag)
                .map(|(step, s)| (step, s.value))
                .collect()
        };
        let logged = scalars("charts/episodic_return");
        let values: Vec<f64> = logged.iter().map(|(_, v)| *v).collect();
        assert_eq!(&values, returns, "{run}");
        // At the global step, as CleanRL logs: CartPole's return is its length.
        let mut steps = 0;
        for ((step, _), length) in logged.iter().zip(scalars("charts/episodic_length")) {
            steps += length.1 as i64;
            assert_eq!(*step, steps, "{run}");
        }
        assert_eq!(scalars("charts/epsilon").len(), returns.len(), "{run}");
        // CleanRL's steps per second, at each episode's end.
        let sps = scalars("charts/SPS");
        assert_eq!(sps.len(), returns.len(), "{run}");
        assert!(
            sps.iter().all(|(_, v)| v.is_finite() && *v > 0.0),
            "{run}: {sps:?}"
        );
        python_runs.push((run.clone(), dir));
    }

    let Some(python) = python_with_tensorboard() else {
        return;
    };
    let script = r#"
import json, sys
from tensorboard.backend.event_processing import event_accumulator
runs = event_accumulator.EventAccumulator(sys.argv[1])
runs.Reload()
print(json.dumps([e.value for e in runs.Scalars("charts/episodic_return")]))
"#;
    for (run, dir) in python_runs {
        let out = Command::new(&python)
            .arg("-c")
            .arg(script)
            .arg(&dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let read: Vec<f64> = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(&read, &expected[&run], "TensorBoard's reader, {run}");
    }
}

/// Which source acted most in an episode is a category: one indicator a source, exactly one
/// of them 1 at each episode's end, never one scalar of source indices.
#[test]
fn the_acting_source_is_one_indicator_a_source() {
    let tmp = tempfile::tempdir().unwrap();
    let (library, out) = (tmp.path().join("lib"), tmp.path().join("out"));
    let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/configs");
    let run = |args: &[&std::ffi::OsStr]| {
        let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
    };
    let sources = configs.join("tiny_sources.ron");
    run(&[
        "sources".as_ref(),
        "--config".as_ref(),
        sources.as_os_str(),
        "--library".as_ref(),
        library.as_os_str(),
    ]);
    let transfer = configs.join("tiny_transfer.ron");
    run(&[
        "--headless".as_ref(),
        "--tensorboard".as_ref(),
        "--config".as_ref(),
        transfer.as_os_str(),
        "--library".as_ref(),
        library.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let events = read_events(
        &event_file(&out.join("tensorboard/sapnet-run0")),
        Links::Refuse,
    )
    .unwrap();
    let mut led: BTreeMap<i64, Vec<(String, f64)>> = BTreeMap::new();
    for event in &events {
        for s in &event.scalars {
            assert_ne!(s.tag, "sapnet/acting_source", "a category drawn as a line");
            if let Some(source) = s.tag.strip_prefix("sapnet/acting_source/") {
                led.entry(event.step)
                    .or_default()
                    .push((source.to_owned(), s.value));
            }
        }
    }
    // An episode in which no source acted (the replay's random warm-up) leads none.
    let mut reader = csv::Reader::from_path(out.join("episodes.csv")).unwrap();
    let led_in_csv = reader
        .deserialize::<BTreeMap<String, String>>()
        .map(Result::unwrap)
        .filter(|r| r["method"] == "sapnet" && r["run"] == "0" && !r["policy"].is_empty())
        .count();
    assert!(led_in_csv > 0);
    assert_eq!(
        led.len(),
        led_in_csv,
        "one set of indicators an episode a source led"
    );
    for (step, sources) in &led {
        assert_eq!(
            sources.len(),
            3,
            "every source of the tiny library, at step {step}"
        );
        let ones = sources.iter().filter(|(_, v)| *v == 1.0).count();
        let zeros = sources.iter().filter(|(_, v)| *v == 0.0).count();
        assert_eq!((ones, zeros), (1, 2), "at step {step}: {sources:?}");
    }
    assert!(out.join("tensorboard/dqn[8]-run0").is_dir());
}

/// The UI runs the protocol headless runs, into the same folder, so `--tensorboard` is
/// taken there too: without a terminal, what is refused is the UI, not the flag.
#[test]
fn the_ui_takes_tensorboard_and_without_a_terminal_points_at_headless() {
    let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .arg("--tensorboard")
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("not a terminal"), "{stderr}");
    assert!(stderr.contains("--headless"), "{stderr}");
    assert!(!stderr.contains("--tensorboard"), "{stderr}");
}

/// The test's Python (`SAPNET_TEST_PYTHON`) if it has the `tensorboard` package; else the
/// check by TensorBoard's own reader says it is skipped.
fn python_with_tensorboard() -> Option<PathBuf> {
    let python = PathBuf::from(std::env::var_os("SAPNET_TEST_PYTHON")?);
    let ok = Command::new(&python)
        .args(["-c", "import tensorboard"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        eprintln!(
            "{} has no tensorboard: TensorBoard's own reader skipped",
            python.display()
        );
    }
    ok.then_some(python)
}
