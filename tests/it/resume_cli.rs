//! Nothing lost: a headless protocol killed (SIGKILL) or stopped (SIGTERM) is put together
//! from its finished runs and resumed with `--resume` to the numbers of an uninterrupted
//! one; the same seed gives the same files whatever `--jobs`; `--force` deletes the old
//! results only once the new ones are written.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use crate::common::cli::{sapnet, stderr};
use crate::common::signal::signal_when;

fn config(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/configs")
        .join(name)
}

/// The tiny source library, trained once for a test.
fn library(tmp: &Path) -> PathBuf {
    let library = tmp.join("lib");
    let output = sapnet()
        .args(["sources", "--config"])
        .arg(config("tiny_sources.ron"))
        .arg("--library")
        .arg(&library)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    library
}

/// tiny_transfer.ron with 3 runs of 150 episodes: long enough to be killed between runs.
fn longer_config(tmp: &Path) -> PathBuf {
    let text = std::fs::read_to_string(config("tiny_transfer.ron"))
        .unwrap()
        .replace("episodes: 12,", "episodes: 150,")
        .replace("runs: 2,", "runs: 3,");
    let path = tmp.join("longer.ron");
    std::fs::write(&path, text).unwrap();
    path
}

fn headless(args: &[&str], library: &Path, out: &Path) -> Command {
    let mut command = sapnet();
    command
        .arg("--headless")
        .args(args)
        .arg("--library")
        .arg(library)
        .arg("--out")
        .arg(out);
    command
}

/// Finished run records in `out/runs/`.
fn finished_runs(out: &Path) -> usize {
    std::fs::read_dir(out.join("runs")).map_or(0, |entries| {
        entries
            .flatten()
            .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
            .count()
    })
}

/// Starts `command` and sends `signal` once `out` holds `runs` finished run records.
fn signal_after(mut command: Command, out: &Path, runs: usize, signal: &str) -> Child {
    let child = command
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    signal_when(&child, signal, || finished_runs(out) >= runs);
    child
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// The files whose every byte the seed decides; `episodes.csv` without its `wall_s`.
fn numbers(out: &Path) -> Vec<(String, String)> {
    [
        "episodes.csv",
        "tests.csv",
        "activations.csv",
        "comparison.csv",
        "improvement.csv",
        "scores.csv",
    ]
    .iter()
    .map(|name| {
        let text =
            std::fs::read_to_string(out.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let text = if *name == "episodes.csv" {
            text.lines()
                .map(|l| l.rsplit_once(',').unwrap().0)
                .collect::<Vec<_>>()
                .join("\n")
        } else {
            text
        };
        (name.to_string(), text)
    })
    .collect()
}

#[test]
fn a_killed_then_stopped_protocol_resumes_to_the_numbers_of_an_uninterrupted_one() {
    let tmp = tempfile::tempdir().unwrap();
    let library = library(tmp.path());
    let config = longer_config(tmp.path());
    let config = config.to_str().unwrap();

    let whole = tmp.path().join("whole");
    let output = headless(&["--config", config, "--jobs", "2"], &library, &whole)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(summary(&whole)["status"], "complete");
    assert_eq!(summary(&whole)["unfinished"].as_array().unwrap().len(), 0);

    // SIGKILL once a first run is recorded: nothing can be cleaned up.
    let out = tmp.path().join("out");
    let mut child = signal_after(
        headless(&["--config", config, "--jobs", "1"], &library, &out),
        &out,
        1,
        "KILL",
    );
    child.wait().unwrap();
    assert_eq!(summary(&out)["status"], "running");
    // `sapnet plot` puts the finished runs together and says the protocol was interrupted.
    let plotted = sapnet().arg("plot").arg(&out).output().unwrap();
    assert!(plotted.status.success(), "{}", stderr(&plotted));
    assert!(
        stderr(&plotted).contains("--resume"),
        "{}",
        stderr(&plotted)
    );
    let interrupted = summary(&out);
    assert_eq!(interrupted["status"], "interrupted");
    let finished = interrupted["runs"].as_array().unwrap().len();
    assert!((1..6).contains(&finished), "{interrupted}");
    assert_eq!(
        interrupted["unfinished"].as_array().unwrap().len(),
        6 - finished
    );
    assert!(out.join("learning_curve.png").exists());

    // Resumed, then stopped by SIGTERM after one more run: `stopped`, resumable again.
    let mut child = signal_after(
        headless(&["--resume", "--jobs", "1"], &library, &out),
        &out,
        finished + 1,
        "TERM",
    );
    assert_eq!(child.wait().unwrap().code(), Some(143));
    let stopped = summary(&out);
    assert_eq!(stopped["status"], "stopped", "{stopped}");
    assert!(!stopped["unfinished"].as_array().unwrap().is_empty());

    let resumed = headless(&["--resume", "--jobs", "2"], &library, &out)
        .output()
        .unwrap();
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert!(
        stderr(&resumed).contains("finished before"),
        "{}",
        stderr(&resumed)
    );
    assert_eq!(summary(&out)["status"], "complete");
    assert_eq!(numbers(&out), numbers(&whole));

    // A complete protocol has nothing to resume.
    let again = headless(&["--resume"], &library, &out).output().unwrap();
    assert_eq!(again.status.code(), Some(2));
    assert!(
        stderr(&again).contains("nothing to resume"),
        "{}",
        stderr(&again)
    );
}

#[test]
fn the_same_seed_gives_the_same_files_whatever_the_jobs() {
    let tmp = tempfile::tempdir().unwrap();
    let library = library(tmp.path());
    let config = config("tiny_reuse.ron");
    let config = config.to_str().unwrap();
    let run = |jobs: &str| {
        let out = tmp.path().join(format!("jobs{jobs}"));
        let output = headless(
            &["--config", config, "--jobs", jobs, "--trace"],
            &library,
            &out,
        )
        .output()
        .unwrap();
        assert!(output.status.success(), "{}", stderr(&output));
        let mut files = numbers(&out);
        files.push((
            "trace.csv".into(),
            std::fs::read_to_string(out.join("trace.csv")).unwrap(),
        ));
        files
    };
    let one = run("1");
    assert!(one[0].1.lines().count() > 10);
    assert_eq!(one, run("2"));
}

/// tiny_reuse.ron with `methods` in place of its own list.
fn with_methods(tmp: &Path, name: &str, methods: &str) -> PathBuf {
    let text = std::fs::read_to_string(config("tiny_reuse.ron")).unwrap();
    let start = text.find("methods: [").unwrap();
    let end = start + text[start..].find("\n        ],").unwrap() + "\n        ]".len();
    let path = tmp.join(name);
    std::fs::write(
        &path,
        format!("{}methods: [{methods}]{}", &text[..start], &text[end..]),
    )
    .unwrap();
    path
}

/// A finished protocol extended by `--add-methods` holds the numbers of the protocol that
/// had every method from the start; a config that differs elsewhere, or lists the methods
/// in another order, is refused naming its field, and the folder is left as it was.
#[test]
fn methods_added_to_a_finished_protocol_give_the_protocol_that_had_them_all() {
    let tmp = tempfile::tempdir().unwrap();
    let library = library(tmp.path());
    let two = with_methods(tmp.path(), "two.ron", "SapNet, Dqn(hidden: [8])");
    let four = with_methods(
        tmp.path(),
        "four.ron",
        "SapNet, Dqn(hidden: [8]), Gpi(hidden: [8]), QSwitch(hidden: [8])",
    );
    let (extended, whole) = (tmp.path().join("extended"), tmp.path().join("whole"));
    let run = |mut command: Command| {
        let output = command.output().unwrap();
        assert!(output.status.success(), "{}", stderr(&output));
    };
    run(headless(
        &["--config", two.to_str().unwrap()],
        &library,
        &extended,
    ));
    let before = numbers(&extended);
    let refused = |config: &Path, expected: &str| {
        let added = ["--resume", "--add-methods", config.to_str().unwrap()];
        let output = headless(&added, &library, &extended).output().unwrap();
        assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
        assert!(stderr(&output).contains(expected), "{}", stderr(&output));
        assert_eq!(numbers(&extended), before);
    };
    let swapped = with_methods(tmp.path(), "swapped.ron", "Dqn(hidden: [8]), SapNet, Gpi()");
    refused(
        &swapped,
        "field `protocol.methods`: expected the folder's methods first",
    );
    let reseeded = tmp.path().join("reseeded.ron");
    let text = std::fs::read_to_string(&four).unwrap();
    assert!(text.contains("seed: 5,"));
    std::fs::write(&reseeded, text.replace("seed: 5,", "seed: 6,")).unwrap();
    refused(&reseeded, "field `seed`: expected the folder's own");

    let added = ["--resume", "--add-methods", four.to_str().unwrap()];
    run(headless(&added, &library, &extended));
    run(headless(
        &["--config", four.to_str().unwrap()],
        &library,
        &whole,
    ));
    assert_eq!(numbers(&extended), numbers(&whole));
    assert!(numbers(&whole)[0].1.contains(",gpi[8],"));
}

#[test]
fn resume_takes_its_config_from_the_results_not_the_command_line() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let output = sapnet()
        .args(["--headless", "--resume", "--seed", "3", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("--seed"), "{}", stderr(&output));
    let output = sapnet()
        .args(["--headless", "--resume", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("summary.json"),
        "{}",
        stderr(&output)
    );
}

/// `--force` into a folder whose old results cannot all be moved aside (run as an
/// unprivileged user: root may write anything) changes nothing; where they can, the new
/// results replace them, the old ones deleted last.
#[test]
fn force_deletes_old_results_only_after_writing_new_ones() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let first = sapnet()
        .args(["--headless", "--config"])
        .arg(config("short_cartpole.ron"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(first.status.success(), "{}", stderr(&first));
    let policy = out.join("policies/dqn-16-run0.safetensors");
    let before = std::fs::read(&policy).unwrap();

    if is_root() && nobody_can_run_sapnet() {
        use std::os::unix::fs::PermissionsExt;
        let mode = |path: &Path, mode: u32| {
            std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).unwrap()
        };
        let as_nobody = || {
            Command::new("/usr/bin/setpriv")
                .args([
                    "--reuid=65534",
                    "--regid=65534",
                    "--clear-groups",
                    env!("CARGO_BIN_EXE_sapnet"),
                    "--headless",
                    "--force",
                    "--config",
                ])
                .arg(config("short_cartpole.ron"))
                .arg("--out")
                .arg(&out)
                .output()
                .unwrap()
        };
        mode(tmp.path(), 0o755);
        mode(&out, 0o777);
        // policies/ is root's and read-only to others: it cannot be moved aside, so
        // nothing may change.
        let refused = as_nobody();
        assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
        assert!(
            stderr(&refused).contains("nothing was changed"),
            "{}",
            stderr(&refused)
        );
        assert_eq!(std::fs::read(&policy).unwrap(), before);
        assert!(out.join("episodes.csv").exists() && out.join("summary.json").exists());

        // policies/ may go, episodes.csv (root's) cannot be rewritten: the previous
        // version deleted policies/ and then failed on it. Now the old results move aside,
        // the new ones are written, and only then are the old ones deleted.
        for dir in ["policies", "runs", "runs/dqn-16-run0", "runs/dqn-16-run1"] {
            mode(&out.join(dir), 0o777);
        }
        let replaced = as_nobody();
        assert!(replaced.status.success(), "{}", stderr(&replaced));
        assert!(out.join("policies/dqn-16-run0.safetensors").exists());
        assert!(!out.join(".replaced").exists());
    }

    let forced = sapnet()
        .args(["--headless", "--force", "--seed", "9", "--config"])
        .arg(config("short_cartpole.ron"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(forced.status.success(), "{}", stderr(&forced));
    assert_ne!(std::fs::read(&policy).unwrap(), before);
    assert!(!out.join(".replaced").exists());
}

/// Whether an unprivileged user can run the binary on the test configs: not when the
/// checkout sits in a folder only its owner may enter. The unprivileged half of the test
/// says so and is left out then.
fn nobody_can_run_sapnet() -> bool {
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/configs/short_cartpole.ron");
    let ran = Command::new("/usr/bin/setpriv")
        .args(["--reuid=65534", "--regid=65534", "--clear-groups"])
        .arg("cat")
        .arg(&config)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
        && Command::new("/usr/bin/setpriv")
            .args(["--reuid=65534", "--regid=65534", "--clear-groups"])
            .arg(env!("CARGO_BIN_EXE_sapnet"))
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success());
    if !ran {
        eprintln!(
            "skipped: an unprivileged user cannot run {} here",
            env!("CARGO_BIN_EXE_sapnet")
        );
    }
    ran
}

/// Whether the tests run as root (who may write into read-only folders).
fn is_root() -> bool {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("Uid:"))
                .and_then(|l| l.split_whitespace().nth(2).map(|u| u == "0"))
        })
        .unwrap_or(false)
}
