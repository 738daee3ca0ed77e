//! A lesson edited and saved in teach mode by keys (issue 39, items 1 and 2): the keys
//! refuse what `--add-edge` and `--cut-edge` refuse, and `w` writes a lesson that
//! `sapnet teach --config` reads back to the walk the screen showed.

use std::process::{Command, Output};

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use sapnet::teach::lesson::TeachConfig;
use sapnet::teach::Teach;
use sapnet::tui::dashboard::apply_teach_key;

fn fig2() -> Teach {
    let lesson = TeachConfig::load(None).unwrap();
    Teach::new(lesson.names, lesson.net)
}

fn press(teach: &mut Teach, code: KeyCode) {
    assert!(apply_teach_key(
        teach,
        KeyEvent::new(code, KeyModifiers::NONE)
    ));
}

fn type_line(teach: &mut Teach, text: &str) {
    for c in text.chars() {
        press(teach, KeyCode::Char(c));
    }
    press(teach, KeyCode::Enter);
}

fn sapnet(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("running sapnet");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The "done when": a teacher adds the edge π0–π3 of weight 0.3 to Fig. 2 by
/// keys and saves with `w`; the saved lesson walks from π1 exactly as the same edit made
/// by `--add-edge` does (the JSON byte for byte), and `--save` writes the same lesson.
#[test]
fn a_lesson_saved_by_w_walks_as_the_same_edit_by_flags() {
    let dir = tempfile::tempdir().unwrap();
    let saved = dir.path().join("by-keys.ron");
    let mut teach = fig2();
    press(&mut teach, KeyCode::Char('E'));
    type_line(&mut teach, "0 3 0.3");
    assert_eq!(teach.net().graph().weight(3, 0), Some(0.3));
    assert_eq!(teach.notice(), Some("--add-edge 0 3 0.3 done"));

    press(&mut teach, KeyCode::Char('w'));
    let offered = teach.prompt().expect("w asks for the path").text.clone();
    assert_eq!(offered, "lesson.ron");
    for _ in offered.chars() {
        press(&mut teach, KeyCode::Backspace);
    }
    // q and Esc are text here, not quit: the loop gives every key to the prompt.
    type_line(&mut teach, saved.to_str().unwrap());
    let notice = teach.notice().expect("says what it wrote");
    assert!(notice.starts_with("wrote "), "{notice}");
    assert!(teach.prompt().is_none());

    let by_keys = sapnet(&[
        "teach",
        "--headless",
        "--config",
        saved.to_str().unwrap(),
        "--activate",
        "1",
        "--json",
    ]);
    let by_flags = sapnet(&[
        "teach",
        "--add-edge",
        "0",
        "3",
        "0.3",
        "--activate",
        "1",
        "--headless",
        "--json",
    ]);
    assert_eq!(
        String::from_utf8_lossy(&by_keys.stdout),
        String::from_utf8_lossy(&by_flags.stdout)
    );

    let by_save = dir.path().join("by-flags.ron");
    sapnet(&[
        "teach",
        "--add-edge",
        "0",
        "3",
        "0.3",
        "--save",
        by_save.to_str().unwrap(),
    ]);
    assert_eq!(
        TeachConfig::load(Some(&saved)).unwrap(),
        TeachConfig::load(Some(&by_save)).unwrap()
    );
}

/// What `--add-edge` refuses the keys refuse, with the same words, and the graph stays as
/// it was; a cut restarts the walk on screen from the activations it started from.
#[test]
fn keys_refuse_edits_as_the_flags_do_and_cuts_restart_the_walk() {
    let mut teach = fig2();
    let edges: Vec<_> = teach.net().graph().edges().collect();
    for (typed, says) in [
        (
            "0 0 0.3",
            "--add-edge 0 0 0.3: an edge joins two policies, not policy 0 to itself",
        ),
        (
            "0 3 0",
            "--add-edge 0 3 0: the weight must be a number above 0, got 0",
        ),
        (
            "0 9 0.3",
            "--add-edge 0 9 0.3: there is no policy 9; the lesson has 4",
        ),
        ("0 three 0.3", "no edge added: J: expected a policy's index"),
    ] {
        press(&mut teach, KeyCode::Char('E'));
        type_line(&mut teach, typed);
        let notice = teach.notice().expect("refused");
        assert!(notice.starts_with(says), "{typed}: {notice}");
        assert_eq!(teach.net().graph().edges().collect::<Vec<_>>(), edges);
    }
    // Esc leaves the prompt and changes nothing.
    press(&mut teach, KeyCode::Char('E'));
    press(&mut teach, KeyCode::Char('1'));
    press(&mut teach, KeyCode::Esc);
    assert!(teach.prompt().is_none());

    // π1's walk on Fig. 2 makes 21 calls (tests/it/sapnet_spreading.rs); cut π1–π3 and
    // π3 is out of reach: from π1 (k = 2, η = 1/2) to π0 and π2 at Ω = 0.4, each on to
    // the other two at Ω = 0.8 (deposits), each of those to its two neighbours at
    // Ω = 1.2 (stopped): 2 + 2·2 + 4·2 = 14 calls.
    teach.move_cursor(1);
    press(&mut teach, KeyCode::Char('a'));
    press(&mut teach, KeyCode::Char('s'));
    while teach.selected_edge() != Some((1, 3)) {
        press(&mut teach, KeyCode::Char('e'));
    }
    press(&mut teach, KeyCode::Char('x'));
    assert_eq!(teach.net().graph().weight(1, 3), None);
    assert_eq!(
        teach.notice(),
        Some("--cut-edge 1 3 done: π1's walk 21 → 14 calls, restarted")
    );
    let walk = teach.walk().unwrap();
    assert_eq!((walk.policy, walk.trace.len()), (1, 0), "restarted");
    assert_eq!(teach.net().activations(), [0.0, 1.0, 0.0, 0.0]);
    let mut calls = 0;
    while teach.step().is_some() {
        calls += 1;
    }
    assert_eq!(calls, 14);
    // ΔA at Ω = 0.4, h = 1: (1/2)/0.4 = 1.25 on π0 and π2; then π0 → π2 at h = 2,
    // Ω = 0.8 with η = 1/4: (1/4)/(2·0.8) = 0.15625, and the same π2 → π0.
    let a = teach.net().activations();
    assert!((a[0] - (1.25 + 0.156_25)).abs() < 1e-12, "{a:?}");
    assert_eq!(a[3], 0.0);
}

/// The "done when", in tmux as a teacher does it: `sapnet teach`, `E 0 3 0.3`,
/// `w` to a file, `q`; the file then walks from π1 as `--add-edge 0 3 0.3` does.
#[test]
fn a_teacher_adds_an_edge_and_saves_the_lesson_in_tmux() {
    if !crate::common::tmux::available() {
        eprintln!("tmux is not installed: the end-to-end lesson test is skipped");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let saved = dir.path().join("class.ron");
    let command = format!(
        "{} teach; echo SAPNET-EXITED $?; sleep 60",
        env!("CARGO_BIN_EXE_sapnet")
    );
    let session = crate::common::tmux::Session::start(120, 40, &command);
    session.wait_for(&["the call", "pending spread calls"]);
    session.keys("E");
    session.wait_for(&["add edge I J W"]);
    session.keys("0 3 0.3");
    session.keys("Enter");
    session.wait_for(&["--add-edge 0 3 0.3 done"]);
    session.keys("w");
    session.wait_for(&["save the lesson to: lesson.ron"]);
    for _ in "lesson.ron".chars() {
        session.keys("BSpace");
    }
    session.keys(saved.to_str().unwrap());
    session.keys("Enter");
    session.wait_for(&["wrote "]);
    session.keys("q");
    session.wait_for(&["SAPNET-EXITED 0"]);
    let by_keys = sapnet(&[
        "teach",
        "--headless",
        "--config",
        saved.to_str().unwrap(),
        "--activate",
        "1",
        "--json",
    ]);
    let by_flags = sapnet(&[
        "teach",
        "--add-edge",
        "0",
        "3",
        "0.3",
        "--activate",
        "1",
        "--headless",
        "--json",
    ]);
    assert_eq!(by_keys.stdout, by_flags.stdout);
}
