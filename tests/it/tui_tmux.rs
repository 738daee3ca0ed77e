//! The real thing, once: the binary in a tmux pane, driven by keys as a user would drive it
//! (`send-keys`), read back from the screen (`capture-pane`). `.ci/run` installs tmux; on
//! a machine without it this test says so and passes.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use crate::common::tmux::Session;

#[test]
fn a_user_pauses_steps_teaches_and_quits() {
    if Command::new("tmux").arg("-V").output().is_err() {
        eprintln!(
            "tmux is not installed: the end-to-end TUI test is skipped (.ci/run installs it)"
        );
        return;
    }
    let library = Path::new(env!("CARGO_MANIFEST_DIR")).join("saved_policies");
    // The UI runs the whole protocol into its folder (issue 36).
    let tmp = tempfile::tempdir().unwrap();
    let command = format!(
        "{} --library {} --out {}; echo SAPNET-EXITED $?; sleep 60",
        env!("CARGO_BIN_EXE_sapnet"),
        library.display(),
        tmp.path().join("out").display()
    );
    let session = Session::start(120, 40, &command);

    session.wait_for(&[
        "SAP-Net graph",
        "policies",
        "source-9",
        "RUNNING",
        "episode return, MA10",
    ]);
    session.keys("Space");
    session.wait_for(&["PAUSED"]);
    session.keys("n");
    session.keys("t");
    session.wait_for(&["TEACH", "pending spread calls", "the call"]);
    session.keys("a");
    session.wait_for(&["next (Alg. 2): spread("]);
    session.keys("s");
    let screen = session.wait_for(&["calls 1 made"]);
    assert!(screen.contains("Ω < T_ω"), "{screen}");
    // A teacher lowers T_ω below the library's same-category weight (0.95): the walk
    // restarts and no longer reaches any neighbour.
    session.keys("1");
    session.keys("-");
    let screen = session.wait_for(&["T_ω 1 → 0.9", "restarted", "calls 0 made"]);
    assert!(screen.contains("SAP-Net · T_ω 0.9"), "{screen}");
    session.keys("q");
    // The protocol is still training: `q` asks once.
    session.wait_for(&["protocol running: stop it? the folder stays resumable"]);
    session.keys("y");
    let screen = session.wait_for(&["SAPNET-EXITED 0"]);
    assert!(
        !screen.contains("SAP-Net graph"),
        "the alternate screen was left:\n{screen}"
    );
}

#[test]
fn sigterm_leaves_the_dashboard_with_the_terminal_restored() {
    if Command::new("tmux").arg("-V").output().is_err() {
        eprintln!("tmux is not installed: the SIGTERM test is skipped (.ci/run installs it)");
        return;
    }
    let library = Path::new(env!("CARGO_MANIFEST_DIR")).join("saved_policies");
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    // The seed marks this process apart from the other test's.
    let command = format!(
        "{} --library {} --seed 4242 --out {}; echo SAPNET-EXITED $?; stty -a | grep -o -- '-*icanon'; sleep 60",
        env!("CARGO_BIN_EXE_sapnet"),
        library.display(),
        out.display()
    );
    let session = Session::start(120, 40, &command);
    session.wait_for(&["SAP-Net graph", "RUNNING"]);
    // Anchored, so that the pane's shell, whose command line holds the same words, lives.
    let pattern = format!(
        "^{} --library {} --seed 4242 --out {}$",
        env!("CARGO_BIN_EXE_sapnet"),
        library.display(),
        out.display()
    );
    let killed = Command::new("pkill")
        .args(["-TERM", "-f", &pattern])
        .status()
        .expect("running pkill");
    assert!(killed.success(), "no dashboard process found");
    // stty prints a moment after the exit line: wait for both.
    let screen = session.wait_for(&["SAPNET-EXITED 143", "icanon"]);
    assert!(
        !screen.contains("SAP-Net graph"),
        "the alternate screen was left:\n{screen}"
    );
    // Raw mode is off again: the terminal reads lines (`icanon`, not `-icanon`).
    assert!(
        screen.lines().any(|l| l.trim() == "icanon"),
        "raw mode was left on:\n{screen}"
    );
}

#[test]
fn closing_the_terminal_ends_the_dashboard() {
    if Command::new("tmux").arg("-V").output().is_err() {
        eprintln!("tmux is not installed: the hang-up test is skipped (.ci/run installs it)");
        return;
    }
    let library = Path::new(env!("CARGO_MANIFEST_DIR")).join("saved_policies");
    let tmp = tempfile::tempdir().unwrap();
    let command = format!(
        "{} --library {} --seed 4343 --out {}",
        env!("CARGO_BIN_EXE_sapnet"),
        library.display(),
        tmp.path().join("out").display()
    );
    let pattern = format!("^{command}$");
    let session = Session::start(120, 40, &command);
    session.wait_for(&["SAP-Net graph", "RUNNING"]);
    // The window closes under the dashboard: its terminal hangs up (SIGHUP).
    drop(session);
    let started = Instant::now();
    loop {
        let alive = Command::new("pgrep")
            .args(["-f", &pattern])
            .output()
            .expect("running pgrep")
            .status
            .success();
        if !alive {
            break;
        }
        if started.elapsed() > Duration::from_secs(15) {
            let _ = Command::new("pkill")
                .args(["-KILL", "-f", &pattern])
                .status();
            panic!("the dashboard outlived its terminal by 15 s");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Issue 27: at 80 columns the progress bars wrapped mid-number, and "12s 40s left" did not
/// say which figure was elapsed. The bars now take the terminal's width.
#[test]
fn headless_progress_fits_80_columns_and_says_what_is_elapsed() {
    if Command::new("tmux").arg("-V").output().is_err() {
        eprintln!("tmux is not installed: the progress test is skipped (.ci/run installs it)");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let library = Path::new(env!("CARGO_MANIFEST_DIR")).join("saved_policies");
    let command = format!(
        "{} --headless --quick --library {} --out {}; echo SAPNET-EXITED $?; sleep 60",
        env!("CARGO_BIN_EXE_sapnet"),
        library.display(),
        tmp.path().join("quick").display(),
    );
    let session = Session::start(80, 24, &command);
    session.wait_for(&["SAPNET-EXITED 0"]);
    let rows = session.rows();
    let bar = rows
        .iter()
        .find(|r| r.trim_start().starts_with("protocol ["))
        .unwrap_or_else(|| panic!("no protocol bar on the screen:\n{}", rows.join("\n")));
    assert!(
        bar.contains("episodes, ") && bar.contains(" elapsed"),
        "{bar}"
    );
    assert!(bar.chars().count() <= 80, "{bar}");
}
