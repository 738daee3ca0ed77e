//! Issue 51, item 1: every way back into a stopped protocol works, and every message that
//! says what to type is followed here as written. A protocol stopped in the UI comes back
//! by `R` there, by `R` in `sapnet open`, and by `sapnet --resume --out DIR` (the UI, not
//! only `--headless`), and ends with the files of an uninterrupted headless run.

use std::path::Path;
use std::process::{Command, Output, Stdio};

use crate::common::cli::{configs, sapnet, stderr};
use crate::common::signal::signal_when;
use crate::common::tmux;

/// Every `sapnet …` command a message quotes (between backticks), as its words.
fn advised(message: &str) -> Vec<Vec<String>> {
    message
        .split('`')
        .skip(1)
        .step_by(2)
        .filter(|quoted| quoted.starts_with("sapnet "))
        .map(|quoted| quoted.split_whitespace().map(str::to_string).collect())
        .collect()
}

/// Runs `words` (`sapnet …`) as typed, with the binary under test for `sapnet`.
fn follow(words: &[String]) -> Output {
    assert_eq!(words[0], "sapnet");
    sapnet()
        .args(&words[1..])
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

fn status(out: &Path) -> String {
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    summary["status"].as_str().unwrap().to_string()
}

/// two_baselines.ron (two DQNs, no library: a resume needs no --library) made longer: 2
/// runs each of 300 episodes, long enough to be stopped while its first run trains.
fn protocol(command: &mut Command) -> &mut Command {
    command
        .args(["--episodes", "300", "--runs", "2", "--config"])
        .arg(configs("two_baselines.ron"))
}

/// A headless protocol stopped by SIGTERM once its first run is recorded.
fn stopped_folder(out: &Path) {
    let mut command = sapnet();
    protocol(command.args(["--headless", "--jobs", "1"]))
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    let mut child = command.spawn().unwrap();
    let runs = out.join("runs");
    signal_when(&child, "TERM", || {
        std::fs::read_dir(&runs).is_ok_and(|entries| {
            entries
                .flatten()
                .any(|e| !e.file_name().to_string_lossy().starts_with('.'))
        })
    });
    child.wait().unwrap();
    assert_eq!(status(out), "stopped");
}

/// Without a terminal: `sapnet --out DIR` on a stopped folder names the two commands that
/// finish it; the UI's (`--resume` without `--headless`) names the headless one when
/// stdout is no terminal; that one, typed as said, finishes the protocol; on the complete
/// folder, `--out DIR` names neither.
#[test]
fn the_commands_the_messages_name_work_as_typed() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    stopped_folder(&out);

    let mut again = sapnet();
    let refused = protocol(again.arg("--headless"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(refused.status.code(), Some(2));
    let said = stderr(&refused);
    let commands = advised(&said);
    let dir = out.display().to_string();
    assert_eq!(
        commands,
        [
            vec!["sapnet", "--resume", "--out", &dir],
            vec!["sapnet", "--headless", "--resume", "--out", &dir],
        ],
        "{said}"
    );

    // The UI's, with no terminal to draw on, says what to type instead.
    let ui = follow(&commands[0]);
    assert_eq!(ui.status.code(), Some(2));
    let said = stderr(&ui);
    assert!(said.contains("stdout is not a terminal"), "{said}");
    assert_eq!(advised(&said), [commands[1].clone()], "{said}");
    assert_eq!(
        status(&out),
        "stopped",
        "refused before the folder is touched"
    );

    let resumed = follow(&commands[1]);
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert_eq!(status(&out), "complete");

    // Complete: no resume is offered; what is is `sapnet open`.
    let mut again = sapnet();
    let refused = protocol(again.arg("--headless"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let said = stderr(&refused);
    assert_eq!(advised(&said), [vec!["sapnet", "open", &dir]], "{said}");
    assert!(said.contains("--force"), "{said}");
}

/// Done-when: a protocol stopped in the UI comes back three ways — `R` where it stopped,
/// `R` in `sapnet open`, `sapnet --resume --out DIR` — each message on the way saying what
/// works, and ends with the files of the same protocol run headless, byte for byte.
#[test]
fn a_protocol_stopped_in_the_ui_comes_back_every_way_to_the_files_of_headless() {
    if !tmux::available() {
        eprintln!("tmux is not installed: the ways-back test is skipped");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let (headless, ui) = (tmp.path().join("headless"), tmp.path().join("ui"));
    // A DQN that learns CartPole, 2 runs of 2,000 episodes: seconds per run, long enough
    // to stop it twice while it trains.
    let flags = "--runs 2 --episodes 2000 --config";
    let config = configs("learn_cartpole.ron");
    let output = sapnet()
        .args(["--headless", "--jobs", "2"])
        .args(flags.split(' '))
        .arg(&config)
        .arg("--out")
        .arg(&headless)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));

    let bin = env!("CARGO_BIN_EXE_sapnet");
    let dir = ui.display();
    let command = format!(
        "{bin} --jobs 1 {flags} {} --out {dir}; echo FIRST-EXITED $?; \
         {bin} open {dir}; echo SECOND-EXITED $?; \
         {bin} --resume --out {dir}; echo SAPNET-EXITED $?; sleep 60",
        config.display(),
    );
    let session = tmux::Session::start(120, 40, &command);

    // Stopped by S: the question says R here finishes it, and R here does.
    session.wait_for(&["▶ dqn[100] run 0 · training"]);
    session.keys("S");
    session.wait_for(&["stop it?", "(R here, or `sapnet --resume --out"]);
    session.keys("y");
    session.wait_for(&["stopped: R resumes it"]);
    session.keys("R");
    session.wait_for(&["resuming", "· training"]);

    // Stopped by q: the screen closes, so the question names the command instead.
    session.keys("q");
    let screen = session.wait_for(&["stop it?"]);
    assert!(!screen.contains("R here"), "{screen}");
    assert!(screen.contains("finishes it later"), "{screen}");
    session.keys("y");

    // `sapnet open` reads the stopped folder (its screen hides the line the first command
    // ended with: the exit codes are read at the end); R takes it and resumes it there.
    session.wait_for(&["Runs · 2 runs", "stopped: R resumes it", "R resume"]);
    assert_eq!(status(&ui), "stopped");
    session.keys("R");
    session.wait_for(&["resuming", "· training"]);
    session.keys("q");
    session.wait_for(&["stop it?"]);
    session.keys("y");

    // `sapnet --resume --out DIR` reopens the workbench and finishes it; the notice of
    // its start is gone once it has ended.
    let screen = session.wait_for(&["complete", "2 of 2 runs finished"]);
    assert!(!screen.contains("resuming"), "{screen}");
    session.keys("q");
    session.wait_for(&["SAPNET-EXITED 0"]);
    let printed = session.rows().join("\n");
    for exited in ["FIRST-EXITED 0", "SECOND-EXITED 0"] {
        assert!(printed.contains(exited), "{printed}");
    }
    assert_eq!(status(&ui), "complete");
    for file in [
        "comparison.csv",
        "improvement.csv",
        "scores.csv",
        "tests.csv",
    ] {
        let (a, b) = (
            std::fs::read(headless.join(file)).unwrap(),
            std::fs::read(ui.join(file)).unwrap(),
        );
        assert!(
            a == b,
            "{file} differs between --headless and the UI resumed"
        );
    }
}
