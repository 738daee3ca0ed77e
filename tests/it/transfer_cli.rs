//! `sapnet --headless` with SAP-Net in the protocol: the library is trained when missing
//! and asked for, reused when present, refused with the file named when it does not fit;
//! every result file is written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use sapnet::policy_store;

fn config(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/configs")
        .join(name)
        .display()
        .to_string()
}

fn sapnet(args: &[&str], library: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(args)
        .arg("--library")
        .arg(library)
        .arg("--out")
        .arg(out)
        .output()
        .expect("the binary runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn transfer(library: &Path, out: &Path) -> Output {
    sapnet(
        &[
            "--headless",
            "--config",
            &config("tiny_transfer.ron"),
            "--jobs",
            "2",
            "--add-to-library",
        ],
        library,
        out,
    )
}

#[test]
fn a_library_named_by_flag_that_does_not_exist_is_not_trained_unasked() {
    let tmp = tempfile::tempdir().unwrap();
    let (library, out) = (tmp.path().join("typo"), tmp.path().join("out"));
    let output = transfer(&library, &out);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("no source library in"), "{message}");
    assert!(message.contains("--train-library"), "{message}");
    assert!(!library.exists());
}

/// Trains the tiny library once for a test and returns its task directory.
fn train_library(library: &Path) -> PathBuf {
    let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args([
            "sources",
            "--config",
            &config("tiny_sources.ron"),
            "--library",
        ])
        .arg(library)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    library.join("cartpole")
}

#[test]
fn a_missing_library_is_trained_then_every_result_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let (library, out) = (tmp.path().join("lib"), tmp.path().join("out"));
    let output = sapnet(
        &[
            "--headless",
            "--config",
            &config("tiny_transfer.ron"),
            "--jobs",
            "2",
            "--train-library",
            "--add-to-library",
        ],
        &library,
        &out,
    );
    assert!(output.status.success(), "{}", stderr(&output));
    let message = stderr(&output);
    assert!(message.contains("no source library in"), "{message}");
    assert!(message.contains("chosen policy source-"), "{message}");
    assert_eq!(
        policy_store::list(&library.join("cartpole")).unwrap().len(),
        3
    );

    // 2 methods × 2 runs × 12 episodes, SAP-Net's rows naming a policy.
    let episodes = std::fs::read_to_string(out.join("episodes.csv")).unwrap();
    let rows: Vec<&str> = episodes.lines().skip(1).collect();
    assert_eq!(rows.len(), 48);
    assert!(episodes.starts_with(
        "run,method,episode,reward,steps,loss,statistic_loss,epsilon,policy,wall_s\n"
    ));
    assert!(rows
        .iter()
        .filter(|r| r.contains(",dqn[8],"))
        .all(|r| r.split(',').nth(8) == Some("")));
    // SAP-Net's rows after the warm-up name the source that acted most, as tests.csv
    // names the chosen one.
    let policies: Vec<&str> = rows
        .iter()
        .filter(|r| r.contains(",sapnet,"))
        .filter_map(|r| r.split(',').nth(8))
        .collect();
    assert!(policies
        .iter()
        .all(|p| p.is_empty() || p.starts_with("source-")));
    assert!(policies.iter().any(|p| p.starts_with("source-")));

    let tests = std::fs::read_to_string(out.join("tests.csv")).unwrap();
    assert_eq!(tests.lines().next(), Some("run,method,test,return,policy"));
    assert_eq!(tests.lines().count(), 1 + 2 * 2 * 2);
    assert!(tests
        .lines()
        .filter(|l| l.contains(",sapnet,"))
        .all(|l| l.ends_with(|c: char| c.is_ascii_digit()) && l.contains("source-")));

    let activations = std::fs::read_to_string(out.join("activations.csv")).unwrap();
    assert!(
        activations.starts_with("run,method,episode,A_source-0,A_source-1,A_source-2,P_source-0")
    );
    assert_eq!(activations.lines().count(), 1 + 2 * 12);

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["library"].as_array().unwrap().len(), 3);
    let runs = summary["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 4);
    let chosen = runs
        .iter()
        .find(|r| r["method"] == "sapnet")
        .map(|r| r["chosen"]["name"].as_str().unwrap().to_string())
        .unwrap();

    let policy = policy_store::load(&out.join("policies"), "sapnet-run0").unwrap();
    assert_eq!(
        policy.metadata.reused.as_deref(),
        Some(format!("cartpole/{chosen}").as_str())
    );
    // Algorithm 3's last step: each run's chosen policy joins the library, beside the
    // sources, as the results hold it.
    let chosen_dir = library.join("cartpole/chosen");
    assert_eq!(
        policy_store::list(&chosen_dir).unwrap(),
        ["out-sapnet-run0", "out-sapnet-run1"]
    );
    let added = policy_store::load(&chosen_dir, "out-sapnet-run0").unwrap();
    assert_eq!(added.metadata, policy.metadata);
    assert_eq!(
        std::fs::read(chosen_dir.join("out-sapnet-run0.safetensors")).unwrap(),
        std::fs::read(out.join("policies/sapnet-run0.safetensors")).unwrap()
    );
    let sapnet_run = runs.iter().find(|r| r["method"] == "sapnet").unwrap();
    assert!(sapnet_run["library_copy"]
        .as_str()
        .unwrap()
        .ends_with("out-sapnet-run0.ron"));
    assert!(
        message.contains("added to the policy library as"),
        "{message}"
    );
    let plots = [
        "learning_curve.png",
        "learning_curve.svg",
        "tests.png",
        "activations.png",
    ];
    for plot in plots {
        assert!(out.join(plot).metadata().unwrap().len() > 1000, "{plot}");
    }

    // `sapnet plot` makes the same report and plots again from summary.json and the run
    // records alone.
    let again = tmp.path().join("again");
    std::fs::create_dir(&again).unwrap();
    std::fs::copy(out.join("summary.json"), again.join("summary.json")).unwrap();
    for run in std::fs::read_dir(out.join("runs")).unwrap() {
        let run = run.unwrap().path();
        let to = again.join("runs").join(run.file_name().unwrap());
        std::fs::create_dir_all(&to).unwrap();
        for file in std::fs::read_dir(&run).unwrap() {
            let file = file.unwrap().path();
            std::fs::copy(&file, to.join(file.file_name().unwrap())).unwrap();
        }
    }
    let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .arg("plot")
        .arg(&again)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    for file in plots.iter().chain(&[
        "comparison.csv",
        "improvement.csv",
        "scores.csv",
        "intervals.png",
        "episodes.csv",
    ]) {
        assert!(
            std::fs::read(again.join(file)).unwrap() == std::fs::read(out.join(file)).unwrap(),
            "{file} differs when made again"
        );
    }
}

#[test]
fn plotting_a_directory_without_results_names_the_missing_file() {
    let tmp = tempfile::tempdir().unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .arg("plot")
        .arg(tmp.path())
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("summary.json"), "{message}");
    assert!(
        message.contains("is this a results directory?"),
        "{message}"
    );
    assert!(
        std::fs::read_dir(tmp.path()).unwrap().next().is_none(),
        "nothing written"
    );
}

/// A report shipped without its run records (docs/reuse/<task>/ is one) is refused by
/// `plot` and `pool` before anything is written: made again from no records it would be a
/// report of no runs, written over the files it came with.
#[test]
fn a_report_shipped_without_its_run_records_is_refused_and_kept() {
    let tmp = tempfile::tempdir().unwrap();
    let shipped = tmp.path().join("acrobot");
    std::fs::create_dir(&shipped).unwrap();
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/reuse/acrobot");
    for file in ["summary.json", "comparison.csv", "tests.csv", "scores.csv"] {
        std::fs::copy(docs.join(file), shipped.join(file)).unwrap();
    }
    let before: Vec<Vec<u8>> = ["summary.json", "comparison.csv", "tests.csv"]
        .iter()
        .map(|f| std::fs::read(shipped.join(f)).unwrap())
        .collect();
    for args in [
        vec!["plot".into(), shipped.display().to_string()],
        vec![
            "pool".into(),
            shipped.display().to_string(),
            docs.parent()
                .unwrap()
                .join("cartpole")
                .display()
                .to_string(),
            "--out".into(),
            tmp.path().join("pooled").display().to_string(),
        ],
    ] {
        let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(
            output.status.code(),
            Some(2),
            "{args:?}: {}",
            stderr(&output)
        );
        let message = stderr(&output);
        assert!(
            message.contains("runs but the folder holds none of their records"),
            "{message}"
        );
    }
    let after: Vec<Vec<u8>> = ["summary.json", "comparison.csv", "tests.csv"]
        .iter()
        .map(|f| std::fs::read(shipped.join(f)).unwrap())
        .collect();
    assert!(before == after, "a refused folder was changed");
    assert!(!shipped.join("episodes.csv").exists());
    assert!(
        !tmp.path().join("pooled").exists(),
        "no pooled folder is made"
    );
}

/// A finished protocol shipped with its top-level files and without its run records (as
/// `docs/`'s folders are, their episodes decompressed) is made again by `plot` from those
/// files: the same scores and comparison, today's improvement.csv; the data kept as it was.
#[test]
fn a_report_shipped_with_its_episodes_is_made_again_from_them() {
    let tmp = tempfile::tempdir().unwrap();
    let config = tmp.path().join("protocol.ron");
    std::fs::write(
        &config,
        "(env: CartPole(), dqn: (replay_start_size: 20), protocol: (episodes: 6, runs: 3, \
         test_episodes: 2, methods: [Dqn(hidden: [8]), Dqn(hidden: [16])]))",
    )
    .unwrap();
    let out = tmp.path().join("out");
    let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(["--headless", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let read = |f: &str| std::fs::read(out.join(f)).unwrap();
    let made: Vec<Vec<u8>> = ["scores.csv", "comparison.csv", "improvement.csv"]
        .map(read)
        .to_vec();
    let data: Vec<Vec<u8>> = ["episodes.csv", "tests.csv"].map(read).to_vec();
    std::fs::remove_dir_all(out.join("runs")).unwrap();
    for f in [
        "scores.csv",
        "comparison.csv",
        "improvement.csv",
        "learning_curve.png",
    ] {
        std::fs::remove_file(out.join(f)).unwrap();
    }
    let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .arg("plot")
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let again: Vec<Vec<u8>> = ["scores.csv", "comparison.csv", "improvement.csv"]
        .map(read)
        .to_vec();
    assert!(made == again, "the report made again differs");
    assert!(data == ["episodes.csv", "tests.csv"].map(read).to_vec());
    assert!(out.join("learning_curve.png").is_file());
}

#[test]
fn a_present_library_is_reused_unchanged() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    let dir = train_library(&library);
    let before = std::fs::read(dir.join("source-1.safetensors")).unwrap();
    let output = transfer(&library, &tmp.path().join("out"));
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(!stderr(&output).contains("no source library"));
    assert_eq!(
        std::fs::read(dir.join("source-1.safetensors")).unwrap(),
        before
    );
}

#[test]
fn trace_csv_holds_every_spread_call_and_adds_up_to_the_activations() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    train_library(&library);
    // SAP-Net alone, long enough for positive transitions (12 episodes have none), on the
    // complete graph: the library's lone two-layer source, which may lock in, has
    // neighbours to spread to there.
    let text = std::fs::read_to_string(config("tiny_transfer.ron"))
        .unwrap()
        .replace("episodes: 12,", "episodes: 80,")
        .replace("runs: 2,", "runs: 1,")
        .replace("seed: 5,", "sapnet: (base_graph: Complete),\n    seed: 5,")
        .replace("methods: [SapNet, Dqn(hidden: [8])]", "methods: [SapNet]");
    let longer = tmp.path().join("longer.ron");
    std::fs::write(&longer, text).unwrap();
    let out = tmp.path().join("out");
    let output = sapnet(
        &[
            "--headless",
            "--config",
            longer.to_str().unwrap(),
            "--trace",
        ],
        &library,
        &out,
    );
    assert!(output.status.success(), "{}", stderr(&output));

    let mut trace = csv::Reader::from_path(out.join("trace.csv")).unwrap();
    assert_eq!(
        trace.headers().unwrap(),
        vec![
            "run", "method", "step", "policy", "call", "from", "to", "h", "omega", "eta", "delta",
            "stopped"
        ]
    );
    // Deposits per (run, policy), and activations per (run, policy): a call numbered 1 opens
    // an activation.
    let mut deposits = std::collections::HashMap::<(String, String), f64>::new();
    let mut rows = 0;
    for row in trace.records() {
        let row = row.unwrap();
        rows += 1;
        let num = |i: usize| row[i].parse::<f64>().unwrap();
        assert_eq!(&row[1], "sapnet");
        let (h, omega, eta, delta) = (num(7), num(8), num(9), num(10));
        let stopped = &row[11] == "true";
        // Eq. 10 with Table II's T_ω = 1: stopped exactly when Ω ≥ T_ω, else η/(h·Ω).
        assert_eq!(stopped, omega >= 1.0, "{row:?}");
        if stopped {
            assert_eq!(delta, 0.0);
        } else {
            assert!((delta - eta / (h * omega)).abs() < 1e-12, "{row:?}");
        }
        if h == 1.0 {
            assert_eq!(row[5], row[3], "a first hop leaves the activated policy");
        }
        *deposits
            .entry((row[0].to_string(), row[6].to_string()))
            .or_default() += delta;
    }
    assert!(rows > 0, "the tiny run spreads at least once");

    // Each policy's final activation is 𝒜 = 1 per activation of its own plus what spread to
    // it: whatever the trace deposited leaves a whole number.
    let mut activations = csv::Reader::from_path(out.join("activations.csv")).unwrap();
    let headers = activations.headers().unwrap().clone();
    let mut last_rows = std::collections::HashMap::new();
    for row in activations.records() {
        let row = row.unwrap();
        last_rows.insert(row[0].to_string(), row);
    }
    for (run, row) in &last_rows {
        for (column, value) in headers.iter().zip(row.iter()) {
            let Some(policy) = column.strip_prefix("A_") else {
                continue;
            };
            let spread = deposits
                .get(&(run.clone(), policy.to_string()))
                .copied()
                .unwrap_or(0.0);
            let own = value.parse::<f64>().unwrap() - spread;
            assert!(
                own > -1e-6 && (own - own.round()).abs() < 1e-6,
                "run {run} {policy}: A − deposits = {own}"
            );
        }
    }
}

#[test]
fn a_chosen_policy_never_replaces_one_in_the_library() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    train_library(&library);
    let out = tmp.path().join("out");
    assert!(transfer(&library, &out).status.success());
    let chosen_dir = library.join("cartpole/chosen");
    let first = std::fs::read(chosen_dir.join("out-sapnet-run0.ron")).unwrap();

    // The same --out again (--force replaces the results, not the library), then another
    // seed: both runs' choices are added under new names.
    let again = sapnet(
        &[
            "--headless",
            "--config",
            &config("tiny_transfer.ron"),
            "--force",
            "--seed",
            "7",
            "--add-to-library",
        ],
        &library,
        &out,
    );
    assert!(again.status.success(), "{}", stderr(&again));
    assert_eq!(
        policy_store::list(&chosen_dir).unwrap(),
        [
            "out-sapnet-run0",
            "out-sapnet-run0-2",
            "out-sapnet-run1",
            "out-sapnet-run1-2"
        ]
    );
    assert_eq!(
        std::fs::read(chosen_dir.join("out-sapnet-run0.ron")).unwrap(),
        first
    );
    // The sources are what they were: the next run reuses the same library.
    assert_eq!(
        policy_store::list(&library.join("cartpole")).unwrap().len(),
        3
    );
}

#[test]
fn a_corrupted_policy_is_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    let dir = train_library(&library);
    let weights = dir.join("source-2.safetensors");
    let mut bytes = std::fs::read(&weights).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0xff;
    std::fs::write(&weights, &bytes).unwrap();

    let output = transfer(&library, &tmp.path().join("out"));
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("source-2.safetensors"), "{message}");
    assert!(message.contains("SHA-256"), "{message}");
    // Nothing in the library was touched.
    assert_eq!(std::fs::read(&weights).unwrap(), bytes);
}

#[test]
fn a_library_that_does_not_fit_the_task_is_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    train_library(&library);
    // MountainCar (2 inputs, 3 actions) reusing the CartPole sources (4 inputs, 2 actions).
    let text = std::fs::read_to_string(config("tiny_transfer.ron"))
        .unwrap()
        .replace("env: CartPole(),", "env: MountainCar(),")
        .replace(
            "training_episodes: 3)",
            "training_episodes: 3, env: Some(CartPole()))",
        );
    let other_task = tmp.path().join("mountain_car.ron");
    std::fs::write(&other_task, text).unwrap();
    let output = sapnet(
        &["--headless", "--config", other_task.to_str().unwrap()],
        &library,
        &tmp.path().join("out"),
    );
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("source-0.ron"), "{message}");
    assert!(message.contains("does not fit"), "{message}");
    assert!(
        message.contains("takes 4 observation values, the task gives 2"),
        "{message}"
    );
}

#[test]
fn a_library_of_another_source_task_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    train_library(&library);
    // The same config with a heavier pole as the source task: the library on disk was
    // trained on the default pole.
    let text = std::fs::read_to_string(config("tiny_transfer.ron"))
        .unwrap()
        .replace(
            "training_episodes: 3)",
            "training_episodes: 3, env: Some(CartPole(masspole: 0.2)))",
        );
    let heavier = tmp.path().join("heavier.ron");
    std::fs::write(&heavier, text).unwrap();
    let output = sapnet(
        &["--headless", "--config", heavier.to_str().unwrap()],
        &library,
        &tmp.path().join("out"),
    );
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("cartpole was trained on"), "{message}");
    assert!(message.contains("--retrain"), "{message}");
}

#[test]
fn every_method_runs_and_the_comparison_has_a_row_for_each() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    train_library(&library);
    let out = tmp.path().join("out");
    let output = sapnet(
        &[
            "--headless",
            "--config",
            &config("tiny_reuse.ron"),
            "--jobs",
            "2",
        ],
        &library,
        &out,
    );
    assert!(output.status.success(), "{}", stderr(&output));
    let methods = [
        "sapnet",
        "sapnet-episode-decay0.99",
        "sapnet-tau-lin5-1-k5",
        "random",
        "random-episode",
        "ucb1",
        "prql[8]",
        "best-source",
        "dqn[8]",
    ];
    let comparison = std::fs::read_to_string(out.join("comparison.csv")).unwrap();
    let rows: Vec<&str> = comparison.lines().skip(1).collect();
    assert_eq!(rows.len(), methods.len(), "{comparison}");
    for (row, method) in rows.iter().zip(methods) {
        assert!(row.starts_with(&format!("{method},2,")), "{row}");
    }
    assert!(comparison.starts_with(
        "method,runs,tested,episodes_to_15,episodes_to_15_lo,episodes_to_15_hi,reached_15,\
         reached_15_share,reached_15_share_lo,reached_15_share_hi,episodes_to_500,"
    ));
    // The columns a script looks for, each once, beside the ones kept from before.
    let header: Vec<&str> = comparison.lines().next().unwrap().split(',').collect();
    for column in [
        "test_iqm",
        "test_iqm_lo",
        "test_iqm_hi",
        "test_mean",
        "test_mean_lo",
        "test_mean_hi",
        "return_iqm",
        "return_iqm_lo",
        "return_iqm_hi",
        "return_mean_lo",
        "return_mean_hi",
        "test_median",
        "test_optimality_gap",
        "units",
        "mean_return",
        "test_std",
        "ranks",
        "lock_in_median_step",
    ] {
        assert_eq!(
            header.iter().filter(|h| **h == column).count(),
            1,
            "{column}"
        );
    }
    // Every row's interval holds its point.
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    for row in &rows {
        let cells: Vec<&str> = row.split(',').collect();
        let v = |name: &str| cells[col(name)].parse::<f64>().unwrap();
        assert!(
            v("test_iqm_lo") <= v("test_iqm") && v("test_iqm") <= v("test_iqm_hi"),
            "{row}"
        );
        assert!(v("return_mean_lo") <= v("mean_return") && v("mean_return") <= v("return_mean_hi"));
        assert_eq!(&cells[col("units")], &"return");
    }
    // The tested rule of each method, by name.
    let tested = |method: &str| {
        rows.iter()
            .find(|r| r.starts_with(&format!("{method},")))
            .unwrap()
            .split(',')
            .nth(2)
            .unwrap()
            .to_string()
    };
    assert_eq!(tested("sapnet"), "highest-activation");
    assert_eq!(tested("random"), "drawn-at-start");
    assert_eq!(tested("ucb1"), "most-played");
    assert_eq!(tested("prql[8]"), "learner");
    assert_eq!(tested("best-source"), "best-recorded");
    // P(X > Y) of every ordered pair, for both scores: 9 · 8 · 2 rows.
    let improvement = std::fs::read_to_string(out.join("improvement.csv")).unwrap();
    let mut lines = improvement.lines();
    assert_eq!(
        lines.next(),
        Some(
            "score,method,over,p,lo,hi,rank_p,holm_p,seeds_excluding,verdict,runs_needed,\
             per_task"
        )
    );
    let pairs: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(pairs.len(), 9 * 8 * 2, "{improvement}");
    for pair in &pairs {
        let (p, lo, hi) = (
            pair[3].parse::<f64>().unwrap(),
            pair[4].parse::<f64>().unwrap(),
            pair[5].parse::<f64>().unwrap(),
        );
        assert!(
            (0.0..=1.0).contains(&lo) && lo <= p && p <= hi && hi <= 1.0,
            "{pair:?}"
        );
        // P(X > Y) + P(Y > X) = 1: ties count half both ways.
        let back = pairs
            .iter()
            .find(|q| q[0] == pair[0] && q[1] == pair[2] && q[2] == pair[1])
            .unwrap();
        assert!(
            (p + back[3].parse::<f64>().unwrap() - 1.0).abs() < 1e-12,
            "{pair:?}"
        );
    }
    // One row per run in scores.csv; the three interval plots, PNG and SVG.
    let scores = std::fs::read_to_string(out.join("scores.csv")).unwrap();
    assert_eq!(scores.lines().count(), 1 + 9 * 2, "{scores}");
    for plot in ["intervals", "profiles", "improvement"] {
        for ext in ["png", "svg"] {
            let bytes = std::fs::read(out.join(format!("{plot}.{ext}"))).unwrap();
            assert!(bytes.len() > 1000, "{plot}.{ext}");
        }
    }
    // The table on stdout names every method.
    let table = String::from_utf8_lossy(&output.stdout);
    assert!(methods.iter().all(|m| table.contains(m)), "{table}");

    // Every reusing method writes its selector's state per episode; DQN does not.
    let activations = std::fs::read_to_string(out.join("activations.csv")).unwrap();
    for method in &methods[..8] {
        let episodes = activations
            .lines()
            .filter(|l| l.split(',').nth(1) == Some(method))
            .count();
        assert_eq!(episodes, 2 * 12, "{method}");
    }
    assert!(!activations.contains(",dqn[8],"));
    assert!(out.join("selections.png").exists());

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let runs = summary["runs"].as_array().unwrap();
    let run_of = |method: &str| runs.iter().find(|r| r["method"] == method).unwrap();
    // PRQ-learning's result is its own learner; the selectors' results are sources.
    assert!(run_of("prql[8]")["chosen"].is_null());
    assert_eq!(run_of("best-source")["chosen"]["score_name"], "score");
    assert_eq!(run_of("sapnet")["chosen"]["score_name"], "A");
    // BestSource always acts with the best-scored source: given, not learned, so no
    // lock-in is recorded (reuse/lock_in.rs).
    let best = run_of("best-source");
    let steps: Vec<u64> = best["source_steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_u64().unwrap())
        .collect();
    assert_eq!(steps.iter().filter(|&&s| s > 0).count(), 1, "{steps:?}");
    assert!(best["lock_in_step"].is_null(), "{}", best["lock_in_step"]);
    // Learning steps all acted by sources, after the 3 × 20 warm-up.
    let total: u64 = steps.iter().sum();
    assert_eq!(total, best["steps"].as_u64().unwrap() - 60);
    assert_eq!(
        summary["comparison"].as_array().unwrap().len(),
        methods.len()
    );
}

/// Rows of a results CSV as maps from its header's names.
fn csv_rows(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|line| {
            header
                .iter()
                .cloned()
                .zip(line.split(',').map(String::from))
                .collect()
        })
        .collect()
}

/// GPI, the Q-switch, QDagger and A2T run end to end (issue 40): each has its row and its
/// test rule; GPI's and the Q-switch's counts of followed sources reach activations.csv,
/// the literal switch (greedy proposals) never follows a source, QDagger's first episodes
/// are its teacher's, and A2T's attention weights are its probabilities (each in (0, 1),
/// the sources' summing below 1: the base holds the rest).
#[test]
fn the_fields_baselines_run_and_say_whom_they_followed() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    train_library(&library);
    let out = tmp.path().join("out");
    let output = sapnet(
        &["--headless", "--config", &config("tiny_baselines.ron")],
        &library,
        &out,
    );
    assert!(output.status.success(), "{}", stderr(&output));
    let comparison = csv_rows(&out.join("comparison.csv"));
    let tested: Vec<(&str, &str)> = comparison
        .iter()
        .map(|r| (r["method"].as_str(), r["tested"].as_str()))
        .collect();
    assert_eq!(
        tested,
        [
            ("gpi[8]", "combined"),
            ("qswitch[8]", "learner"),
            ("qswitch[8]-greedy", "learner"),
            ("qdagger[8]", "learner"),
            ("a2t[8]", "combined"),
            ("dqn[8]", "learner"),
        ]
    );
    let activations = csv_rows(&out.join("activations.csv"));
    let followed = |method: &str| -> u64 {
        activations
            .iter()
            .filter(|r| r["method"] == method)
            .flat_map(|r| {
                r.iter()
                    .filter(|(k, _)| k.starts_with("selected_"))
                    .map(|(_, v)| v.parse::<u64>().unwrap())
                    .collect::<Vec<_>>()
            })
            .sum()
    };
    // GPI starts with an untrained learner beside trained sources: theirs win at first.
    assert!(followed("gpi[8]") > 0);
    assert_eq!(followed("qswitch[8]-greedy"), 0);
    // QDagger's teacher acts its 60 steps first: the first episode names it.
    let episodes = csv_rows(&out.join("episodes.csv"));
    let first = episodes
        .iter()
        .find(|r| r["method"] == "qdagger[8]" && r["run"] == "0" && r["episode"] == "1")
        .unwrap();
    assert!(first["policy"].starts_with("source-"), "{first:?}");
    for row in activations.iter().filter(|r| r["method"] == "a2t[8]") {
        let weights: Vec<f64> = row
            .iter()
            .filter(|(k, _)| k.starts_with("P_"))
            .map(|(_, v)| v.parse().unwrap())
            .collect();
        assert_eq!(weights.len(), 3);
        assert!(weights.iter().all(|&w| w > 0.0 && w < 1.0), "{weights:?}");
        assert!(weights.iter().sum::<f64>() < 1.0, "{weights:?}");
    }
    let tests = csv_rows(&out.join("tests.csv"));
    assert_eq!(tests.iter().filter(|r| r["method"] == "gpi[8]").count(), 4);
}

/// Started in a folder without `saved_policies/`, the default protocol reuses the library
/// shipped beside sapnet's source, says so, and trains nothing into the folder.
#[test]
fn started_elsewhere_the_default_library_is_the_shipped_one() {
    let tmp = tempfile::tempdir().unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args([
            "--headless",
            "--quick",
            "--episodes",
            "3",
            "--runs",
            "1",
            "--out",
            "out",
        ])
        .current_dir(tmp.path())
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("saved_policies");
    let said = format!(
        "the source library: {} (shipped with sapnet",
        shipped.display()
    );
    assert!(stderr(&output).contains(&said), "{}", stderr(&output));
    assert!(!stderr(&output).contains("no source library"));
    assert!(!tmp.path().join("saved_policies").exists());
}
