//! SIGINT, SIGTERM and SIGHUP stop a headless run after its current step: everything it did
//! is written, and the exit code is 128 + the signal (130, 143, 129), in headless runs and
//! library training alike.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use crate::common::signal::signal_when;

/// A DQN that would train for hours: only a signal ends it.
const ENDLESS: &str = "(protocol: (episodes: 1000000, runs: 1, methods: [Dqn(hidden: [8])]))";

fn start(args: &[&str], dir: &Path) -> Child {
    let config = dir.join("endless.ron");
    std::fs::write(&config, ENDLESS).unwrap();
    Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(args)
        .arg("--config")
        .arg(&config)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Episodes written so far by every run, finished or in progress (`runs/*/episodes.csv`,
/// `runs/.*.partial/episodes.csv`).
fn episodes_written(out: &Path) -> usize {
    std::fs::read_dir(out.join("runs")).map_or(0, |entries| {
        entries
            .flatten()
            .map(|e| {
                std::fs::read_to_string(e.path().join("episodes.csv"))
                    .map_or(0, |t| t.lines().count().saturating_sub(1))
            })
            .sum()
    })
}

#[test]
fn a_signalled_headless_run_writes_what_it_did_and_exits_128_plus_the_signal() {
    for (signal, code, said) in [
        ("TERM", 143, "terminated (SIGTERM)"),
        ("INT", 130, "interrupted"),
        ("HUP", 129, "hung up (SIGHUP)"),
    ] {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("out");
        let child = start(&["--headless", "--out", out.to_str().unwrap()], tmp.path());
        signal_when(&child, signal, || episodes_written(&out) > 3);
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(code), "{signal}: {stderr}");
        assert!(stderr.contains(said), "{stderr}");
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["status"], "stopped", "{signal}");
        assert_eq!(summary["runs"][0]["stopped"], true, "{signal}");
        assert!(
            std::fs::read_to_string(out.join("episodes.csv"))
                .unwrap()
                .lines()
                .count()
                > 3
        );
        assert!(out.join("learning_curve.png").exists());
        // The closing table scores finished runs only and names the stopped one apart.
        let plot = Command::new(env!("CARGO_BIN_EXE_sapnet"))
            .arg("plot")
            .arg(&out)
            .output()
            .unwrap();
        let table = String::from_utf8_lossy(&plot.stdout);
        let episodes = summary["runs"][0]["episodes"].as_u64().unwrap();
        let steps = summary["runs"][0]["steps"].as_u64().unwrap();
        assert_eq!(
            table.trim(),
            format!(
                "not in the table, stopped before their end: dqn[8] run 0 at episode \
                 {episodes} (step {steps}) of 1000000 episodes"
            ),
            "{signal}"
        );
    }
}

#[test]
fn a_signalled_library_training_keeps_it_unfinished_and_exits_143() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    let config = tmp.path().join("sources.ron");
    std::fs::write(
        &config,
        "(sources: (count: 2, hidden_layers: (1, 1), units: (4, 4), training_episodes: 1000000))",
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(["sources", "--config"])
        .arg(&config)
        .arg("--library")
        .arg(&library)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Signal once training has begun (its first progress line), not before the handlers
    // are in place; stderr is read to its end on a thread of its own.
    let (begun_tx, begun) = std::sync::mpsc::channel();
    let pipe = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        use std::io::BufRead;
        let mut all = String::new();
        for line in std::io::BufReader::new(pipe).lines() {
            let line = line.unwrap();
            if line.contains("started") {
                let _ = begun_tx.send(());
            }
            all.push_str(&line);
            all.push('\n');
        }
        all
    });
    begun
        .recv_timeout(Duration::from_secs(60))
        .expect("training began");
    signal_when(&child, "TERM", || true);
    let status = child.wait().unwrap();
    let stderr = reader.join().unwrap();
    assert_eq!(status.code(), Some(143), "{stderr}");
    assert!(
        stderr.contains("0 of 2 policies are trained and kept in"),
        "{stderr}"
    );
    assert!(!library.join("cartpole/source-0.ron").exists());
    let manifest = std::fs::read_to_string(library.join("cartpole/library.ron")).unwrap();
    assert!(manifest.contains("complete: false"), "{manifest}");
}
