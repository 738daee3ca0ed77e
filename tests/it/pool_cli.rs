//! `sapnet pool`: finished protocols on two tasks as one comparison, normalised and
//! stratified by task; and what it refuses.

use crate::common::cli::{sapnet, stderr};
use std::path::Path;

/// Two DQNs from scratch, three runs each, a few episodes on `env`.
fn protocol(tmp: &Path, env: &str, out: &str) -> std::path::PathBuf {
    let config = tmp.join(format!("{out}.ron"));
    std::fs::write(
        &config,
        format!(
            "(env: {env}, dqn: (replay_start_size: 20), protocol: (episodes: 4, runs: 3, \
             test_episodes: 1, methods: [Dqn(hidden: [8]), Dqn(hidden: [16])]))"
        ),
    )
    .unwrap();
    let out = tmp.join(out);
    let output = sapnet()
        .args(["--headless", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    out
}

#[test]
fn two_tasks_pool_into_one_normalised_comparison() {
    let tmp = tempfile::tempdir().unwrap();
    let cartpole = protocol(tmp.path(), "CartPole()", "cartpole");
    let car = protocol(tmp.path(), "MountainCar()", "car");
    let pooled = tmp.path().join("pooled");
    let output = sapnet()
        .arg("pool")
        .arg(&cartpole)
        .arg(&car)
        .arg("--out")
        .arg(&pooled)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let table = String::from_utf8_lossy(&output.stdout);
    assert!(table.contains("normalised to [0, 1]"), "{table}");
    let comparison = std::fs::read_to_string(pooled.join("comparison.csv")).unwrap();
    let header: Vec<&str> = comparison.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = comparison
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 2, "{comparison}");
    for row in &rows {
        // Three runs on each task, normalised: a failing MountainCar run scores 0.
        assert_eq!(row[col("runs")], "6");
        assert_eq!(row[col("units")], "normalised");
        let mean: f64 = row[col("test_mean")].parse().unwrap();
        assert!((0.0..=1.0).contains(&mean), "{row:?}");
    }
    // The per-run scores name both tasks, in their own returns.
    let scores = std::fs::read_to_string(pooled.join("scores.csv")).unwrap();
    assert!(
        scores.contains(",cartpole,") && scores.contains(",mountain_car,"),
        "{scores}"
    );
    assert!(pooled.join("profiles.png").exists());

    // Two folders on one task, an unfinished one, or a used --out are refused.
    let twice = sapnet()
        .arg("pool")
        .arg(&cartpole)
        .arg(&cartpole)
        .arg("--out")
        .arg(tmp.path().join("p2"))
        .output()
        .unwrap();
    assert_eq!(twice.status.code(), Some(2));
    assert!(
        stderr(&twice).contains("are both on cartpole"),
        "{}",
        stderr(&twice)
    );
    let used = sapnet()
        .arg("pool")
        .arg(&cartpole)
        .arg(&car)
        .arg("--out")
        .arg(&pooled)
        .output()
        .unwrap();
    assert_eq!(used.status.code(), Some(2));
    assert!(
        stderr(&used).contains("a new or empty directory"),
        "{}",
        stderr(&used)
    );
    let summary = car.join("summary.json");
    let text = std::fs::read_to_string(&summary).unwrap();
    std::fs::write(&summary, text.replacen("\"complete\"", "\"stopped\"", 1)).unwrap();
    let unfinished = sapnet()
        .arg("pool")
        .arg(&cartpole)
        .arg(&car)
        .arg("--out")
        .arg(tmp.path().join("p3"))
        .output()
        .unwrap();
    assert_eq!(unfinished.status.code(), Some(2));
    assert!(
        stderr(&unfinished).contains("not complete"),
        "{}",
        stderr(&unfinished)
    );
}
