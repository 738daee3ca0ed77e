//! Sweeps as a cluster runs them: planned once, each cell an ordinary process fanned out by
//! GNU parallel, one cell killed with SIGKILL and run again, merged to what a sweep that
//! never failed merges to.

use crate::common::cli::{ok, sapnet, stderr};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A grid over tiny_transfer.ron (SAP-Net and a DQN on a library of three tiny sources):
/// two values of τ × three seeds, six cells of a second or so.
fn grid(tmp: &Path) -> PathBuf {
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/configs/tiny_transfer.ron");
    let text = std::fs::read_to_string(base)
        .unwrap()
        .replace("episodes: 12,", "episodes: 60,");
    std::fs::write(tmp.join("base.ron"), text).unwrap();
    let grid = tmp.join("grid.ron");
    std::fs::write(
        &grid,
        "(base: \"base.ron\", seeds: Some(3), \
         axes: [(path: \"sapnet.temperature\", values: [1.0, 4.0])])",
    )
    .unwrap();
    grid
}

fn plan(grid: &Path, sweep: &Path, library: &Path) -> Output {
    sapnet()
        .args(["sweep", "plan", "--grid"])
        .arg(grid)
        .arg("--out")
        .arg(sweep)
        .arg("--library")
        .arg(library)
        .output()
        .unwrap()
}

fn sweep(args: &[&str], sweep: &Path) -> Output {
    sapnet()
        .args(["sweep", args[0]])
        .arg(sweep)
        .args(&args[1..])
        .output()
        .unwrap()
}

/// The merged files, `wall_s` (the last column of the episodes) left out.
fn merged(sweep: &Path) -> (String, String) {
    let comparison = std::fs::read_to_string(sweep.join("merged/comparison.csv")).unwrap();
    let episodes = std::fs::read_to_string(sweep.join("merged/episodes.csv"))
        .unwrap()
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string())
        .collect::<Vec<_>>()
        .join("\n");
    (comparison, episodes)
}

#[test]
fn a_sweep_through_gnu_parallel_survives_a_killed_cell() {
    let tmp = tempfile::tempdir().unwrap();
    let grid = grid(tmp.path());
    let library = tmp.path().join("lib");
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    ok(plan(&grid, &a, &library));
    // Planning again gives the same cells, and changes nothing.
    let cells = std::fs::read(a.join("cells/0004.ron")).unwrap();
    ok(plan(&grid, &a, &library));
    assert_eq!(std::fs::read(a.join("cells/0004.ron")).unwrap(), cells);
    let text = String::from_utf8(cells).unwrap();
    assert!(text.contains("sapnet.temperature=4.0, seed=6"), "{text}");
    ok(plan(&grid, &b, &library));

    // The cells never train the library: they ask for `sweep prepare`.
    let refused = sweep(&["run", "--cell", "0"], &a);
    assert_eq!(refused.status.code(), Some(2));
    assert!(
        stderr(&refused).contains("sapnet sweep prepare"),
        "{}",
        stderr(&refused)
    );
    let status = String::from_utf8(sweep(&["status"], &a).stdout).unwrap();
    assert!(status.contains("1 failed"), "{status}");
    assert!(status.contains("0000 failed:"), "{status}");
    ok(sapnet()
        .args(["sources", "--config"])
        .arg(tmp.path().join("base.ron"))
        .arg("--library")
        .arg(&library)
        .output()
        .unwrap());

    // The reference: every cell on this machine, nothing failing.
    ok(sweep(&["run", "--all", "--jobs", "2"], &b));
    ok(sweep(&["merge"], &b));

    // Cell 2 killed half-way: a partial result, no result.
    let mut child = sapnet()
        .args(["sweep", "run"])
        .arg(&a)
        .args(["--cell", "2", "--jobs", "1"])
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let partial = a.join("results/.0002.partial/runs");
    let started = Instant::now();
    while std::fs::read_dir(&partial).map_or(true, |d| d.count() == 0) {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "cell 2 never started"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let status = String::from_utf8(sweep(&["status"], &a).stdout).unwrap();
    assert!(status.contains("0002 running"), "{status}");

    // Nothing finished: nothing to merge. Then merging what there is names what is missing.
    let nothing = sweep(&["merge"], &a);
    assert_eq!(nothing.status.code(), Some(2));
    ok(sweep(&["run", "--cell", "0", "--jobs", "1"], &a));
    let partly = ok(sweep(&["merge"], &a));
    assert!(
        stderr(&partly).contains("5 cells are not done"),
        "{}",
        stderr(&partly)
    );

    if Command::new("parallel").arg("--version").output().is_err() {
        eprintln!("GNU parallel is not installed: the cells run one by one instead");
        for cell in 0..6 {
            ok(sweep(
                &["run", "--cell", &cell.to_string(), "--jobs", "1"],
                &a,
            ));
        }
    } else {
        // The sweep's own command line, as a user copies it from parallel.txt.
        let lines = std::fs::read_to_string(a.join("parallel.txt")).unwrap();
        let line = lines.lines().find(|l| l.starts_with("parallel ")).unwrap();
        ok(Command::new("bash").args(["-c", line]).output().unwrap());
    }
    let status = String::from_utf8(sweep(&["status"], &a).stdout).unwrap();
    assert!(status.starts_with("6 cells: 6 done"), "{status}");
    ok(sweep(&["merge"], &a));
    assert_eq!(merged(&a), merged(&b));
    let (comparison, episodes) = merged(&a);
    assert!(
        comparison.starts_with("axis,value,cells,method,runs,"),
        "{comparison}"
    );
    assert!(
        comparison.contains("\nsapnet.temperature,4.0,3,sapnet,6,"),
        "{comparison}"
    );
    // The temperature does not touch DQN: seed 7's two cells ran the same two DQN runs,
    // counted once (they were counted twice, 4 runs).
    assert!(comparison.contains("\nseed,7,2,dqn[8],2,"), "{comparison}");
    assert!(
        episodes.starts_with("cell,sapnet.temperature,seed,run,method,episode,reward"),
        "{episodes}"
    );
    // 6 cells × 2 methods × 2 runs × 60 episodes, and the header.
    assert_eq!(episodes.lines().count(), 1 + 6 * 2 * 2 * 60);
    assert!(a
        .join("merged/sapnet.temperature=4.0/learning_curve.png")
        .exists());
    // The value's plots name it, and say what their band is over how many runs: 3 seeds
    // × 2 runs of each method (DQN's counted once per seed, as above).
    let value = a.join("merged/sapnet.temperature=4.0");
    let curve = std::fs::read_to_string(value.join("learning_curve.svg")).unwrap();
    for text in [
        "sapnet.temperature = 4.0 · ",
        "band: 95% bootstrap CI of the mean",
        "over 6 runs",
        "sapnet (6 runs)",
    ] {
        assert!(curve.contains(text), "learning_curve.svg lacks {text:?}");
    }
    let intervals = std::fs::read_to_string(value.join("intervals.svg")).unwrap();
    assert!(intervals.contains("sapnet.temperature = 4.0 · "));
    assert!(intervals.contains("over 6 runs per method"));
    // Each score against each axis's values, beside the merged results.
    assert!(a.join("merged/sweep.png").exists());
    let sweep_plot = std::fs::read_to_string(a.join("merged/sweep.svg")).unwrap();
    for text in [
        "greedy test score against sapnet.temperature",
        "training return against seed",
        "95% stratified bootstrap CI",
    ] {
        assert!(sweep_plot.contains(text), "sweep.svg lacks {text:?}");
    }
}

#[test]
fn a_grid_key_that_names_no_field_is_a_located_error() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("base.ron"), "()").unwrap();
    let grid = tmp.path().join("grid.ron");
    std::fs::write(
        &grid,
        "(base: \"base.ron\", axes: [(path: \"dqn.gama\", values: [0.9])])",
    )
    .unwrap();
    let output = plan(&grid, &tmp.path().join("s"), &tmp.path().join("lib"));
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("axis `dqn.gama`"), "{message}");
    assert!(message.contains("gama"), "{message}");
    assert!(!tmp.path().join("s/sweep.ron").exists());
}

#[test]
fn a_scheduler_names_the_cell_through_its_environment() {
    let tmp = tempfile::tempdir().unwrap();
    let output = sapnet()
        .args(["sweep", "run"])
        .arg(tmp.path())
        .env("SLURM_ARRAY_TASK_ID", "x1")
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("SLURM_ARRAY_TASK_ID=\"x1\" is not a cell number"),
        "{}",
        stderr(&output)
    );
}

/// A merge before any cell finished wrote empty files and said "merged 0 cells": it is
/// refused, pointing at `sweep status`.
#[test]
fn a_merge_with_no_finished_cell_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("sweep");
    ok(plan(&grid(tmp.path()), &dir, &tmp.path().join("lib")));
    let output = sweep(&["merge"], &dir);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("has finished: nothing to merge"),
        "{}",
        stderr(&output)
    );
    assert!(!dir.join("merged").exists());
}

/// A cell file edited after planning is refused by `sweep run`, whose message says to plan
/// again; planning the same sweep again writes the file back (it once left it edited).
#[test]
fn planning_again_restores_an_edited_cell() {
    let tmp = tempfile::tempdir().unwrap();
    let (dir, grid, library) = (
        tmp.path().join("sweep"),
        grid(tmp.path()),
        tmp.path().join("lib"),
    );
    ok(plan(&grid, &dir, &library));
    let cell = dir.join("cells/0001.ron");
    let planned = std::fs::read_to_string(&cell).unwrap();
    std::fs::write(&cell, planned.replace("temperature", "temperature ")).unwrap();
    let output = sweep(&["run", "--cell", "1"], &dir);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("`sapnet sweep plan` with the same grid and --out writes it back"),
        "{}",
        stderr(&output)
    );
    ok(plan(&grid, &dir, &library));
    assert_eq!(std::fs::read_to_string(&cell).unwrap(), planned);
}

/// Cells that differ only by seed reuse one library: `sweep prepare` readies it once (it
/// said "ready" once per seed).
#[test]
fn prepare_readies_a_library_once_for_every_seed() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("sweep");
    ok(plan(&grid(tmp.path()), &dir, &tmp.path().join("lib")));
    let library = tmp.path().join("lib");
    // Without --library, prepare says how to name the library it would train.
    let unnamed = sweep(&["prepare"], &dir);
    assert_eq!(unnamed.status.code(), Some(2));
    assert!(
        stderr(&unnamed).contains("--library"),
        "{}",
        stderr(&unnamed)
    );
    let prepared = ok(sweep(
        &["prepare", "--library", library.to_str().unwrap()],
        &dir,
    ));
    let said = stderr(&prepared);
    assert_eq!(said.matches(" ready").count(), 1, "{said}");
}

/// A sweep over tasks: each task's rows in its returns, and the rows of axis `*` pooling
/// every cell, normalised and stratified by task.
#[test]
fn a_sweep_over_tasks_is_pooled_with_normalised_scores() {
    let tmp = tempfile::tempdir().unwrap();
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/configs/tiny_transfer.ron");
    // Both tasks reuse one library trained on the default CartPole.
    let text = std::fs::read_to_string(base).unwrap().replace(
        "training_episodes: 3)",
        "training_episodes: 3, env: Some(CartPole()))",
    );
    assert!(text.contains("env: Some(CartPole())"), "{text}");
    std::fs::write(tmp.path().join("base.ron"), text).unwrap();
    let grid = tmp.path().join("grid.ron");
    std::fs::write(
        &grid,
        "(base: \"base.ron\", axes: [(path: \"env\", values: [CartPole(), \
         CartPole(length: 1.0)])])",
    )
    .unwrap();
    let (library, s) = (tmp.path().join("lib"), tmp.path().join("s"));
    ok(plan(&grid, &s, &library));
    ok(sweep(
        &["prepare", "--library", library.to_str().unwrap()],
        &s,
    ));
    ok(sweep(&["run", "--all", "--jobs", "2"], &s));
    let merged = ok(sweep(&["merge"], &s));
    let table = String::from_utf8_lossy(&merged.stdout).into_owned();
    assert!(table.contains("* = every cell"), "{table}");
    assert!(table.contains("normalised to [0, 1]"), "{table}");
    let comparison = std::fs::read_to_string(s.join("merged/comparison.csv")).unwrap();
    let header: Vec<&str> = comparison.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = comparison
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    // Two env values and the pooled rows, SAP-Net and DQN each.
    assert_eq!(rows.len(), 3 * 2, "{comparison}");
    for row in &rows {
        let pooled = row[col("axis")] == "*";
        let units = row[col("units")];
        assert_eq!(
            units,
            if pooled { "normalised" } else { "return" },
            "{row:?}"
        );
        let iqm: f64 = row[col("test_iqm")].parse().unwrap();
        if pooled {
            // Both tasks' runs, on [0, 1]; no thresholds (each task has its own).
            assert_eq!(row[col("runs")], "4");
            assert!((0.0..=1.0).contains(&iqm), "{row:?}");
            assert_eq!(row[col("episodes_to_195")], "");
        }
    }
    let improvement = std::fs::read_to_string(s.join("merged/improvement.csv")).unwrap();
    assert!(
        improvement.starts_with(
            "axis,value,score,method,over,p,lo,hi,rank_p,holm_p,seeds_excluding,verdict,\
             runs_needed,per_task\n"
        ),
        "{improvement}"
    );
    // Pooled over the two tasks, each pair carries each task's verdict (two runs each
    // separate nothing).
    let pooled = improvement
        .lines()
        .find(|l| l.starts_with("*,every cell,test,sapnet,dqn[8],"))
        .expect("the pooled pair's row");
    assert!(
        pooled.ends_with(",cartpole=not separated;cartpole(length=1.0)=not separated"),
        "{pooled}"
    );
    assert!(
        improvement.contains("\n*,every cell,test,sapnet,dqn[8],"),
        "{improvement}"
    );
    // The pooled folder's report, and each task's curves apart.
    let pooled = s.join("merged/across-tasks");
    assert!(pooled.join("intervals.png").exists());
    assert!(pooled.join("task=cartpole/learning_curve.png").exists());
}
