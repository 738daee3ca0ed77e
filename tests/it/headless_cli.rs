//! Headless mode driven as a user would: the binary, its files and its exit codes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn sapnet(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn config(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/configs")
        .join(name)
        .display()
        .to_string()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// `episodes.csv` without its `wall_s` column, which measures the machine, not the run,
/// and with its rows sorted: runs trained side by side interleave their rows as the
/// threads happen to finish episodes.
fn episodes_without_time(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join("episodes.csv")).unwrap();
    let mut lines: Vec<String> = text
        .lines()
        .map(|line| line.rsplit_once(',').unwrap().0.to_string())
        .collect();
    lines[1..].sort();
    lines
}

fn run_short(out: &Path, seed: &str) -> Output {
    sapnet(&[
        "--headless",
        "--config",
        &config("short_cartpole.ron"),
        "--seed",
        seed,
        "--out",
        out.to_str().unwrap(),
    ])
}

#[test]
fn the_same_seed_gives_the_same_episodes() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        tmp.path().join("a"),
        tmp.path().join("b"),
        tmp.path().join("c"),
    );
    for (dir, seed) in [(&a, "7"), (&b, "7"), (&c, "8")] {
        let output = run_short(dir, seed);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    let first = episodes_without_time(&a);
    assert_eq!(
        first[0],
        "run,method,episode,reward,steps,loss,statistic_loss,epsilon,policy"
    );
    assert_eq!(first.len(), 1 + 2 * 30, "two runs of 30 episodes");
    assert_eq!(first, episodes_without_time(&b));
    assert_ne!(first, episodes_without_time(&c));
}

#[test]
fn a_run_writes_its_summary_and_policies() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let output = run_short(&out, "1");
    assert!(output.status.success(), "{}", stderr(&output));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let runs = summary["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    for run in runs {
        assert_eq!(run["method"], "dqn[16]");
        assert_eq!(run["episodes"], 30);
        assert_eq!(run["test_returns"].as_array().unwrap().len(), 2);
        assert_eq!(run["stopped"], false);
    }
    for run in 0..2 {
        let stem: PathBuf = out.join("policies").join(format!("dqn-16-run{run}"));
        assert!(stem.with_extension("safetensors").exists());
        assert!(stem.with_extension("ron").exists());
    }
}

#[test]
fn results_are_not_overwritten_without_force() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    assert!(run_short(&out, "1").status.success());
    let before = std::fs::read(out.join("episodes.csv")).unwrap();

    let refused = run_short(&out, "2");
    assert_eq!(refused.status.code(), Some(2));
    assert!(
        stderr(&refused).contains("already holds results"),
        "{}",
        stderr(&refused)
    );
    assert!(stderr(&refused).contains("--force"), "{}", stderr(&refused));
    assert_eq!(std::fs::read(out.join("episodes.csv")).unwrap(), before);

    let forced = sapnet(&[
        "--headless",
        "--config",
        &config("short_cartpole.ron"),
        "--seed",
        "2",
        "--force",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(forced.status.success(), "{}", stderr(&forced));
}

#[test]
fn an_unknown_config_path_is_exit_code_2() {
    let output = sapnet(&["--headless", "--config", "no/such/file.ron"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("no/such/file.ron"),
        "{}",
        stderr(&output)
    );
}

#[test]
fn an_unwritable_out_is_exit_code_2() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("a-file");
    std::fs::write(&file, "not a directory").unwrap();
    let out = file.join("out");
    let output = run_short(&out, "1");
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("output directory"),
        "{}",
        stderr(&output)
    );
    // --out naming the file itself is said so, not with the OS's "File exists".
    let output = run_short(&file, "1");
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("expected a directory for the results, and it is a file"),
        "{}",
        stderr(&output)
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "not a directory");
}

/// `--quick` cuts the protocol to 1/20 of its episodes, and an explicit `--episodes` wins
/// over that (it once divided `--episodes` by 20 too).
#[test]
fn episodes_wins_over_quick() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let output = sapnet(&[
        "--headless",
        "--quick",
        "--episodes",
        "7",
        "--config",
        &config("short_cartpole.ron"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let runs = summary["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2, "--quick keeps at most 2 runs");
    for run in runs {
        assert_eq!(run["episodes"], 7);
    }
}

#[test]
fn a_bad_field_is_exit_code_2_with_its_location() {
    let tmp = tempfile::tempdir().unwrap();
    let bad = tmp.path().join("bad.ron");
    std::fs::write(&bad, "(\n  dqn: (gamma: \"high\"),\n)\n").unwrap();
    let output = sapnet(&["--headless", "--config", bad.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("line 2"), "{message}");
    assert!(message.contains("dqn.gamma"), "{message}");
}

#[test]
fn the_env_subcommand_prints_every_episode() {
    let output = sapnet(&["env", "--episodes", "3", "--seed", "1"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let stdout = String::from_utf8(output.stdout).unwrap();
    assert!(
        stdout.starts_with("CartPole-v1: 3 random-action episodes"),
        "{stdout}"
    );
    assert_eq!(stdout.lines().count(), 2 + 3 + 1, "{stdout}");
}

#[test]
fn a_diverging_run_stops_with_an_error_and_keeps_its_last_good_weights() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let output = sapnet(&[
        "--headless",
        "--config",
        &config("diverging_cartpole.ron"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(
        message.contains("policy dqn[8] (run 0) diverged"),
        "{message}"
    );
    assert!(message.contains("at step"), "{message}");
    assert!(message.contains("last good weights are in"), "{message}");

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(summary["error"].as_str().unwrap().contains("diverged"));

    let policy = sapnet::policy_store::load(&out.join("policies"), "dqn-8-run0").unwrap();
    for (name, tensor) in policy.net.named_parameters() {
        let values = tensor.flatten_all().unwrap().to_vec1::<f32>().unwrap();
        assert!(values.iter().all(|v| v.is_finite()), "{name} is not finite");
    }
}

/// Issue 36: the output flags are the UI's too (it runs the protocol into --out); with
/// no terminal to draw on, the UI says so and points at --headless before it takes a
/// folder or trains anything.
#[test]
fn output_flags_without_headless_and_without_a_terminal_are_refused_before_anything_is_written() {
    for flag in [
        &["--out", "somewhere"][..],
        &["--trace"],
        &["--tensorboard"],
        &["--add-to-library"],
    ] {
        let output = sapnet(flag);
        assert_eq!(output.status.code(), Some(2));
        assert!(
            stderr(&output).contains(
                "the protocol runs in the terminal UI, and stdout is not a terminal: use \
                 --headless"
            ),
            "{}",
            stderr(&output)
        );
    }
    assert!(!Path::new("somewhere").exists());
}

/// Issue 13: an OS error was printed twice (once by the error, once by its source) and
/// numbers in messages took 300 digits.
#[test]
fn errors_say_their_cause_once_with_numbers_in_their_shortest_form() {
    let tmp = tempfile::tempdir().unwrap();
    let output = sapnet(&["--headless", "--config", "no/such/file.ron"]);
    let message = stderr(&output);
    assert_eq!(message.matches("No such file").count(), 1, "{message}");

    let huge = tmp.path().join("huge.ron");
    std::fs::write(&huge, "(dqn: (gamma: 1e300))").unwrap();
    let output = sapnet(&["--headless", "--config", huge.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("got 1e300"), "{message}");
    assert!(!message.contains("0000000000"), "{message}");
}

/// Issue 13: a training run with `sapnet.coefficient: 1e308` wrote NaN probabilities to
/// activations.csv with exit 0. It is refused before any run trains, and said once.
#[test]
fn a_coefficient_that_would_overflow_is_refused_before_any_run() {
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    let trained = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args([
            "sources",
            "--config",
            &config("tiny_sources.ron"),
            "--library",
        ])
        .arg(&library)
        .output()
        .unwrap();
    assert!(trained.status.success(), "{}", stderr(&trained));
    let big = tmp.path().join("big.ron");
    let text = std::fs::read_to_string(config("tiny_transfer.ron"))
        .unwrap()
        .replace("seed: 5,", "seed: 5, sapnet: (coefficient: 1e308),");
    std::fs::write(&big, text).unwrap();
    let out = tmp.path().join("out");
    let output = sapnet(&[
        "--headless",
        "--config",
        big.to_str().unwrap(),
        "--library",
        library.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert_eq!(message.matches("too large").count(), 1, "{message}");
    assert!(
        message.contains(&format!(
            "config {}: method sapnet: field `sapnet.coefficient`",
            big.display()
        )),
        "the file and the field are named: {message}"
    );
    assert!(!out.exists(), "no run started, and no empty folder is left");
}

/// Issue 13: a network of 40 GB a copy tried to allocate (here 4 TB a copy, more than any
/// machine running these tests), 5 M layers aborted and `--config /dev/zero` read without
/// end. Each is refused before anything is allocated.
#[test]
fn sizes_that_cannot_fit_are_refused_before_allocating() {
    let tmp = tempfile::tempdir().unwrap();
    let huge = tmp.path().join("huge.ron");
    std::fs::write(
        &huge,
        "(protocol: (methods: [Dqn(hidden: [1000000, 1000000])]))",
    )
    .unwrap();
    let output = sapnet(
        &["--headless", "--config", huge.to_str().unwrap(), "--out"]
            .into_iter()
            .chain([tmp.path().join("out").to_str().unwrap()])
            .collect::<Vec<_>>(),
    );
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(
        message.contains("needs about 18.2 TiB per run"),
        "{message}"
    );
    assert!(message.contains("this machine has"), "{message}");

    let deep = tmp.path().join("deep.ron");
    let layers = vec!["2"; 100_000].join(",");
    std::fs::write(
        &deep,
        format!("(protocol: (methods: [Dqn(hidden: [{layers}])]))"),
    )
    .unwrap();
    let output = sapnet(&["--headless", "--config", deep.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(
        message.contains("at most 64 hidden layers, got 100000 layers"),
        "{message}"
    );
    assert!(message.len() < 500, "{message}");

    if std::path::Path::new("/dev/zero").exists() {
        let output = sapnet(&["--headless", "--config", "/dev/zero"]);
        assert_eq!(output.status.code(), Some(2));
        // Refused at once for what it is, before a byte is read.
        assert!(
            stderr(&output).contains("a device, not a regular file"),
            "{}",
            stderr(&output)
        );
    }
}

/// `--compare` reads a results folder for the dashboard: said at once when it is not one
/// (before any terminal is opened), and refused with --headless.
#[test]
fn compare_needs_a_results_folder_and_the_dashboard() {
    let empty = tempfile::tempdir().unwrap();
    let dir = empty.path().to_str().unwrap();
    let output = sapnet(&["--compare", dir]);
    assert!(!output.status.success());
    let err = stderr(&output);
    assert!(
        err.contains(&format!(
            "--compare {dir}: expected the output folder of a `sapnet --headless` run"
        )),
        "{err}"
    );
    assert!(
        err.contains("summary.json"),
        "the missing file is named: {err}"
    );
    let output = sapnet(&["--headless", "--compare", dir]);
    assert!(!output.status.success());
    assert!(
        stderr(&output).contains("--compare is for the dashboard"),
        "{}",
        stderr(&output)
    );
}

/// `--compare` with another task's results drew CartPole's returns under MountainCar's:
/// refused, naming both tasks, before the dashboard opens.
#[test]
fn compare_refuses_another_tasks_results() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("cartpole");
    assert!(run_short(&out, "1").status.success());
    let mountain_car = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/mountain_car.ron");
    let output = sapnet(&[
        "--config",
        mountain_car.to_str().unwrap(),
        "--compare",
        out.to_str().unwrap(),
    ]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output)
            .contains("its results are on CartPole-v1, the dashboard trains on MountainCar-v0"),
        "{}",
        stderr(&output)
    );
}

/// Flags a subcommand does not read were accepted and ignored (`sapnet env --library DIR`,
/// `teach --json` opening the TUI, `--jobs 0`): each is refused, naming it.
#[test]
fn flags_a_subcommand_would_ignore_are_refused() {
    let cases: [(&[&str], &str); 5] = [
        (
            &["env", "--library", "/nonexistent", "--jobs", "5"],
            "`sapnet env` does not read --jobs, --library: leave them out (it reads --config, --seed, --python, --module-dir)",
        ),
        (
            &["plot", "--seed", "3", "/nonexistent"],
            "`sapnet plot` does not read --seed: leave it out",
        ),
        (
            &["--headless", "teach"],
            "`sapnet teach` does not read --headless: leave it out (it reads --config)",
        ),
        (&["teach", "--json"], "--headless"),
        (&["--headless", "--jobs", "0"], "invalid value '0' for '--jobs <N>'"),
    ];
    for (args, expected) in cases {
        let output = sapnet(args);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        assert!(
            stderr(&output).contains(expected),
            "{args:?}: {}",
            stderr(&output)
        );
    }
}

/// Help copied where it did not fit (issue 51): `env`'s --python spoke of resuming a results
/// folder, `sweep run`'s --jobs of runs, the run's --jobs of cells; `open` named three views
/// where it has four tabs.
#[test]
fn a_global_flags_help_fits_its_subcommand() {
    let help = |args: &[&str]| String::from_utf8_lossy(&sapnet(args).stdout).into_owned();
    for args in [&["env", "--help"][..], &["sources", "--help"]] {
        let text = help(args);
        assert!(text.contains("--python <PATH>"), "{args:?}: {text}");
        assert!(!text.contains("resuming one"), "{args:?}: {text}");
    }
    let run = help(&["sweep", "run", "--help"]);
    assert!(
        run.contains("Cells run at the same time with --all"),
        "{run}"
    );
    assert!(!run.contains("Runs trained"), "{run}");
    let main = help(&["--help"]);
    assert!(
        main.contains("Runs trained at the same time. Default"),
        "{main}"
    );
    let open = help(&["open", "--help"]);
    for tab in [
        "Runs (r or 1)",
        "Comparison (c, 2)",
        "Curves (v, 3)",
        "dashboard (f, 4",
    ] {
        assert!(open.contains(tab), "{open}");
    }
}

/// `sapnet teach --help` listed --seed, --jobs and --library, which teach then refused, and
/// described --config as the CartPole config: each subcommand's help lists the global flags
/// it reads, and only those, with its own words for --config.
#[test]
fn each_subcommands_help_lists_the_flags_it_reads() {
    for flags in sapnet::cli::SUBCOMMANDS {
        let mut args: Vec<&str> = flags.name.split(' ').collect();
        args.push("--help");
        let output = sapnet(&args);
        assert_eq!(output.status.code(), Some(0), "{args:?}");
        let help = String::from_utf8_lossy(&output.stdout).into_owned();
        for global in ["--config", "--seed", "--jobs", "--library"] {
            assert_eq!(
                help.contains(&format!("{global} <")),
                flags.reads.contains(&global),
                "`sapnet {}` reads {:?}; its help:\n{help}",
                flags.name,
                flags.reads
            );
        }
        if let Some(text) = flags.config {
            assert!(help.contains(text), "{help}");
        }
    }
    let teach = String::from_utf8_lossy(&sapnet(&["teach", "--help"]).stdout).into_owned();
    assert!(teach.contains("A lesson file"), "{teach}");
    assert!(!teach.contains("CartPole"), "{teach}");
    // A global still works before the subcommand as after it.
    for args in [
        &["--seed", "3", "env", "--episodes", "1"][..],
        &["env", "--seed", "3", "--episodes", "1"],
    ] {
        let output = sapnet(args);
        assert!(output.status.success(), "{args:?}: {}", stderr(&output));
    }
}

/// The study's configs give every method the same environment steps: the quick protocol of
/// assets/baselines_cartpole.ron (1/20 of its 200,000 steps) runs every method to exactly
/// 10,000 steps, comparison.csv says so beside each method's updates per step, and the
/// sample-efficiency curve is on the step axis up to the budget.
#[test]
fn a_step_budget_protocol_gives_every_method_the_same_steps() {
    let dir = tempfile::tempdir().unwrap();
    let (out, summary) = crate::common::library::quick_protocol(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/baselines_cartpole.ron"),
        "cartpole",
        dir.path(),
    );
    assert_eq!(summary["config"]["protocol"]["budget"]["Steps"], 10_000);
    let text = std::fs::read_to_string(out.join("comparison.csv")).unwrap();
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("comparison.csv has no {name}"))
    };
    let mut methods = Vec::new();
    for record in reader.records() {
        let record = record.unwrap();
        let method = record[col("method")].to_string();
        assert_eq!(&record[col("env_steps")], "10000.0", "{method}");
        let updates: f64 = record[col("updates_per_step")].parse().unwrap();
        // The frozen oracle learns nothing; A2T's base and attention, and GPI's learner and
        // the winner's estimate, update twice a step; the others once (their first
        // replay_start steps aside). QDagger's student has not started by 10,000 steps.
        let expected = match method.as_str() {
            "frozen-oracle" | "qdagger" => 0.0,
            "a2t" | "gpi" => 2.0,
            _ => 1.0,
        };
        assert!(
            (updates - expected).abs() < 0.06,
            "{method}: {updates} updates per step"
        );
        assert!(!record[col("final_iqm")].is_empty(), "{method}");
        methods.push(method);
    }
    assert_eq!(methods.len(), 10, "{methods:?}");
    for steps_column in ["steps_to_195", "steps_to_475"] {
        col(steps_column);
    }
    let efficiency = std::fs::read_to_string(out.join("sample_efficiency.csv")).unwrap();
    assert!(efficiency.starts_with("method,step,"));
    assert!(efficiency.lines().any(|l| l.starts_with("sapnet,10000,")));
    // A run's record keeps the episode the budget cut, truncated there.
    let runs = summary["runs"].as_array().unwrap();
    assert!(runs.iter().all(|r| r["steps"] == 10_000));
    assert!(runs
        .iter()
        .any(|r| r["cut_episode"]["steps"].as_u64().is_some()));
}
