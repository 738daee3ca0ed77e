//! `sapnet compare`: runs made elsewhere through a protocol's report. Stable-Baselines3's
//! own monitor files of DQN and PPO, three seeds each (tests/fixtures/outside/sb3/, made by
//! make_sb3_runs.py), give the IQMs rliable gives on the same runs; a sapnet results
//! folder's runs join them; and what it refuses.

use crate::common::cli::{sapnet, stderr};
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/outside/sb3")
}

/// `NAME=` and the three monitor files of `algo`.
pub fn method(algo: &str) -> String {
    let paths: Vec<String> = (0..3)
        .map(|s| {
            fixtures()
                .join(format!("{algo}-seed{s}.monitor.csv"))
                .display()
                .to_string()
        })
        .collect();
    format!("{algo}={}", paths.join(","))
}

/// `sapnet compare` of DQN's and PPO's three monitor files, its other flags to come.
pub fn dqn_and_ppo() -> std::process::Command {
    let mut command = sapnet();
    command.args([
        "compare",
        "--method",
        &method("dqn"),
        "--method",
        &method("ppo"),
    ]);
    command
}

/// `comparison.csv`'s rows as (method, column → cell).
fn comparison(dir: &Path) -> Vec<std::collections::HashMap<String, String>> {
    rows(&dir.join("comparison.csv"))
}

/// A CSV file's rows, each as column → cell.
pub fn rows(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    reader
        .records()
        .map(|r| {
            header
                .iter()
                .cloned()
                .zip(r.unwrap().iter().map(String::from))
                .collect()
        })
        .collect()
}

#[test]
fn sb3_monitor_files_give_rliables_intervals() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("compared");
    let output = dqn_and_ppo()
        .args([
            "--range",
            "0",
            "500",
            "--last",
            "20",
            "--task",
            "CartPole-v1",
            // rliable.json scored each run over its episodes.
            "--by-episode",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let table = String::from_utf8_lossy(&output.stdout);
    assert!(table.contains("dqn") && table.contains("ppo"), "{table}");
    assert!(table.contains("final IQM [95% CI]"), "{table}");

    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixtures().join("rliable.json")).unwrap())
            .unwrap();
    let rows = comparison(&out);
    assert_eq!(rows.len(), 2);
    for row in &rows {
        let algo = &row["method"];
        assert_eq!(row["runs"], "3");
        assert_eq!(row["tested"], "last-episodes");
        for (score, column) in [("return", "return_iqm"), ("final", "test_iqm")] {
            let want = &expected[algo.as_str()][score];
            let cell = |end: &str| row[&format!("{column}{end}")].parse::<f64>().unwrap();
            // The point exactly (up to float formatting); the interval's ends within 0.02
            // of the task's range of 500, as rliable's own resampling differs from ours.
            assert!(
                (cell("") - want["iqm"].as_f64().unwrap()).abs() < 1e-9,
                "{algo} {score}: {} vs {}",
                cell(""),
                want["iqm"]
            );
            for (end, key) in [("_lo", "lo"), ("_hi", "hi")] {
                let (ours, theirs) = (cell(end), want[key].as_f64().unwrap());
                assert!(
                    (ours - theirs).abs() <= 0.02 * 500.0,
                    "{algo} {score}{end}: {ours} vs rliable's {theirs}"
                );
            }
        }
    }
    for file in [
        "improvement.csv",
        "scores.csv",
        "runs.csv",
        "sample_efficiency.csv",
        "sample_efficiency.png",
        "learning_curve.png",
        "intervals.png",
    ] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    // Every pair carries the separation rule's columns.
    let improvement = std::fs::read_to_string(out.join("improvement.csv")).unwrap();
    assert!(improvement.lines().next().unwrap().contains("holm_p"));
    assert!(improvement
        .lines()
        .skip(1)
        .all(|l| l.contains("separated") || l.contains("fragile")));
    // runs.csv says where each run came from.
    let runs = std::fs::read_to_string(out.join("runs.csv")).unwrap();
    assert_eq!(runs.lines().count(), 1 + 6);
    assert!(runs.contains("dqn-seed2.monitor.csv") && runs.contains("Monitor"));
}

/// SB3's DQN finishes about 2,000 episodes in its 20,000 steps and PPO about 300: by
/// default the runs are put side by side by step, up to the steps every run reached
/// (19,993), each method given the same experience; `--by-episode` puts them by episode.
#[test]
fn monitor_files_of_different_episode_counts_are_aligned_by_step() {
    let tmp = tempfile::tempdir().unwrap();
    let compare = |out: &Path, extra: &[&str]| {
        let output = dqn_and_ppo()
            .args(["--range", "0", "500", "--last", "20"])
            .args(extra)
            .arg("--out")
            .arg(out)
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", stderr(&output));
    };
    let by_step = tmp.path().join("by-step");
    compare(&by_step, &[]);
    let rows = comparison(&by_step);
    for row in &rows {
        assert_eq!(row["env_steps"], "19993.0", "{}", row["method"]);
    }
    let runs = std::fs::read_to_string(by_step.join("runs.csv")).unwrap();
    let mut reader = csv::Reader::from_reader(runs.as_bytes());
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut episodes = Vec::new();
    for record in reader.records() {
        let record = record.unwrap();
        assert_eq!(&record[col("steps")], "19993");
        episodes.push(record[col("episodes")].parse::<usize>().unwrap());
    }
    // DQN's runs end ~2,000 episodes by the budget, PPO's ~300: the same steps.
    assert!(episodes[..3].iter().all(|&e| e > 1_800), "{episodes:?}");
    assert!(episodes[3..].iter().all(|&e| e < 320), "{episodes:?}");
    let efficiency = std::fs::read_to_string(by_step.join("sample_efficiency.csv")).unwrap();
    assert!(efficiency.starts_with("method,step,"), "{efficiency:.60}");
    let last_step = efficiency
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse::<u64>().unwrap())
        .max();
    assert_eq!(last_step, Some(19_993));

    let by_episode = tmp.path().join("by-episode");
    compare(&by_episode, &["--by-episode"]);
    let efficiency = std::fs::read_to_string(by_episode.join("sample_efficiency.csv")).unwrap();
    assert!(
        efficiency.starts_with("method,episode,"),
        "{efficiency:.60}"
    );
    // The step column never aligned the scores: the training return differs.
    let return_of =
        |rows: &[std::collections::HashMap<String, String>]| rows[1]["return_iqm"].clone();
    assert_ne!(return_of(&rows), return_of(&comparison(&by_episode)));
}

#[test]
fn without_a_range_the_bounds_come_from_the_data_with_a_warning() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("compared");
    let output = dqn_and_ppo().arg("--out").arg(&out).output().unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        stderr(&output).contains("warning: no --range"),
        "{}",
        stderr(&output)
    );
}

#[test]
fn a_results_folders_runs_join_as_a_method() {
    let tmp = tempfile::tempdir().unwrap();
    let config = tmp.path().join("protocol.ron");
    std::fs::write(
        &config,
        "(env: CartPole(), dqn: (replay_start_size: 20), protocol: (episodes: 6, runs: 2, \
         test_episodes: 1, methods: [Dqn(hidden: [8])]))",
    )
    .unwrap();
    let results = tmp.path().join("results");
    let output = sapnet()
        .args(["--headless", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(&results)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let out = tmp.path().join("compared");
    let output = sapnet()
        .args(["compare", "--method", &method("ppo"), "--method"])
        .arg(format!("ours={}#dqn[8]", results.display()))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let rows = comparison(&out);
    let ours = rows.iter().find(|r| r["method"] == "ours").unwrap();
    assert_eq!(ours["runs"], "2");
    // Its training returns are the protocol's own, run by run.
    let scores = |dir: &Path, method: &str| -> Vec<f64> {
        let text = std::fs::read_to_string(dir.join("scores.csv")).unwrap();
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        reader
            .records()
            .map(|r| r.unwrap())
            .filter(|r| &r[0] == method)
            .map(|r| r[4].parse().unwrap())
            .collect()
    };
    assert_eq!(scores(&out, "ours"), scores(&results, "dqn[8]"));
}

#[test]
fn unreadable_runs_are_refused_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let empty = tmp.path().join("empty.csv");
    std::fs::write(&empty, "").unwrap();
    let nan = tmp.path().join("nan.csv");
    std::fs::write(&nan, "episode,return\n1,10\n2,NaN\n").unwrap();
    let header_only = tmp.path().join("header.csv");
    std::fs::write(&header_only, "episode,return\n").unwrap();
    for (bad, says) in [
        (&empty, "an empty file"),
        (&nan, "is not finite"),
        (&header_only, "no episode"),
    ] {
        let output = sapnet()
            .args(["compare", "--method", &method("dqn"), "--method"])
            .arg(format!("bad={}", bad.display()))
            .arg("--out")
            .arg(tmp.path().join("never"))
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
        let error = stderr(&output);
        assert!(error.contains(&bad.display().to_string()), "{error}");
        assert!(error.contains(says), "{error}");
        assert!(!tmp.path().join("never").exists());
    }
    // One method is no comparison; a name that is no name is refused.
    for (args, says) in [
        (
            vec!["--method".to_string(), method("dqn")],
            "at least two methods",
        ),
        (
            vec![
                "--method".into(),
                "a/b=x".into(),
                "--method".into(),
                method("ppo"),
            ],
            "--method",
        ),
    ] {
        let output = sapnet()
            .arg("compare")
            .args(&args)
            .arg("--out")
            .arg(tmp.path().join("never"))
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
        assert!(stderr(&output).contains(says), "{}", stderr(&output));
    }
}
