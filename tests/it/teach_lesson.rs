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

fn table2() -> Teach {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/teach_table2.ron");
    let (source, _) = TeachConfig::read(Some(&path)).unwrap();
    let lesson = source.lesson().unwrap();
    Teach::new(lesson.names, lesson.net)
        .with_groups(lesson.groups.unwrap())
        .with_source(source)
}

/// `n` adds a policy to Fig. 2 (joined to nothing, its graph given by edges), `E` joins
/// it; the walk on screen restarts; `w` then writes the lesson `--add-policy - --add-edge`
/// writes, and it walks as they do.
#[test]
fn a_policy_added_by_key_is_the_one_added_by_flag() {
    let dir = tempfile::tempdir().unwrap();
    let mut teach = fig2();
    teach.move_cursor(1);
    press(&mut teach, KeyCode::Char('a'));
    press(&mut teach, KeyCode::Char('s'));
    press(&mut teach, KeyCode::Char('n'));
    assert_eq!(teach.net().len(), 5);
    assert_eq!(teach.names()[4], "π4");
    assert_eq!(teach.cursor(), 4, "the new policy is picked");
    assert_eq!(
        teach.notice(),
        Some("--add-policy - done: π1's walk 21 → 21 calls, restarted")
    );
    let walk = teach.walk().unwrap();
    assert_eq!((walk.policy, walk.trace.len()), (1, 0));
    assert_eq!(teach.net().activations(), [0.0, 1.0, 0.0, 0.0, 0.0]);
    press(&mut teach, KeyCode::Char('E'));
    type_line(&mut teach, "4 3 0.3");
    assert_eq!(teach.net().graph().weight(3, 4), Some(0.3));

    let by_keys = dir.path().join("by-keys.ron");
    press(&mut teach, KeyCode::Char('w'));
    for _ in "lesson.ron".chars() {
        press(&mut teach, KeyCode::Backspace);
    }
    type_line(&mut teach, by_keys.to_str().unwrap());
    let by_flags = dir.path().join("by-flags.ron");
    sapnet(&[
        "teach",
        "--add-policy",
        "-",
        "--add-edge",
        "4",
        "3",
        "0.3",
        "--save",
        by_flags.to_str().unwrap(),
    ]);
    let keys = TeachConfig::load(Some(&by_keys)).unwrap();
    let flags = TeachConfig::load(Some(&by_flags)).unwrap();
    assert_eq!((&keys.names, &keys.net), (&flags.names, &flags.net));
    assert_eq!(keys.net.len(), 5);
    let walk = |file: &std::path::Path| {
        sapnet(&[
            "teach",
            "--headless",
            "--config",
            file.to_str().unwrap(),
            "--activate",
            "1",
            "--json",
        ])
        .stdout
    };
    assert_eq!(walk(&by_keys), walk(&by_flags));
}

/// `D` removes the picked policy: π3 of Fig. 2 leaves the triangle π0 π1 π2, where π1's
/// walk makes 14 calls (from π1, k = 2, to π0 and π2 at Ω = 0.4; each on to its two
/// neighbours at Ω = 0.8; each of those to two at Ω = 1.2, stopped: 2 × (1 + 2 + 4)).
/// Removing the walk's own policy ends the walk.
#[test]
fn a_policy_removed_by_key_restarts_the_walk_without_it() {
    let mut teach = fig2();
    teach.move_cursor(1);
    press(&mut teach, KeyCode::Char('a'));
    teach.move_cursor(2);
    press(&mut teach, KeyCode::Char('D'));
    assert_eq!(
        teach.notice(),
        Some("--remove-policy 3 done: π1's walk 21 → 14 calls, restarted")
    );
    assert_eq!(teach.net().len(), 3);
    assert_eq!(teach.cursor(), 2);
    teach.run_to_end();
    assert_eq!(teach.walk().unwrap().trace.len(), 14);
    teach.move_cursor(-1);
    press(&mut teach, KeyCode::Char('D'));
    assert_eq!(
        teach.notice(),
        Some("--remove-policy 1 done: the walk's own policy is gone, so is its walk")
    );
    assert!(teach.walk().is_none());
    assert_eq!(
        teach.net().graph().edges().collect::<Vec<_>>(),
        [(0, 1, 0.4)]
    );
}

/// `C` moves a policy of Table II to another category (the number of hidden layers): M
/// follows (eq. 3–5), the graph regroups; Fig. 2, given by edges, has no category and
/// the key says so in `--set-category`'s words.
#[test]
fn a_category_changed_by_key_rebuilds_m_and_fig2_refuses_it() {
    let mut teach = table2();
    press(&mut teach, KeyCode::Char('C'));
    assert_eq!(
        teach.prompt().unwrap().text,
        "1",
        "the current category offered"
    );
    press(&mut teach, KeyCode::Backspace);
    type_line(&mut teach, "2");
    assert_eq!(teach.notice(), Some("--set-category 0 2 done"));
    let graph = teach.net().graph();
    assert_eq!(graph.weight(0, 3), Some(0.95));
    assert_eq!(graph.weight(0, 1), None);
    assert_eq!(graph.edges().count(), 14);
    assert_eq!(teach.groups().unwrap()[..4], [0, 1, 1, 0]);
    // A typed category the prototype cannot read changes nothing.
    press(&mut teach, KeyCode::Char('C'));
    press(&mut teach, KeyCode::Backspace);
    type_line(&mut teach, "two");
    let notice = teach.notice().unwrap();
    assert!(
        notice.starts_with("--set-category 0 two: a category under HiddenLayers is"),
        "{notice}"
    );
    // The saved lesson keeps its categories, not the edges they gave.
    let saved = teach.lesson_file();
    assert!(saved.edges.is_empty());
    assert_eq!(saved.descriptions[0].hidden, [100, 100]);

    let mut fig2 = fig2();
    press(&mut fig2, KeyCode::Char('C'));
    let notice = fig2.notice().unwrap();
    assert!(
        notice.starts_with("--set-category 0 -: this lesson gives its graph by `edges`"),
        "{notice}"
    );
    let flags = Command::new(env!("CARGO_BIN_EXE_sapnet"))
        .args(["teach", "--set-category", "0", "-", "--headless"])
        .output()
        .unwrap();
    assert_eq!(flags.status.code(), Some(2));
    let said = String::from_utf8_lossy(&flags.stderr);
    let reason = notice.split_once(": ").unwrap().1;
    assert!(said.contains(reason), "{said}");
}

/// `M`: a click picks a policy, a click on another joins them at 0.4 (that edge then
/// selected for `5` and `x`), the same two clicks again cut it, and a second click on
/// the same policy lets it go.
#[test]
fn clicks_in_m_mode_join_and_cut_edges() {
    let mut teach = fig2();
    press(&mut teach, KeyCode::Char('M'));
    assert!(teach.is_linking());
    teach.pick(0);
    teach.pick(3);
    assert_eq!(teach.net().graph().weight(0, 3), Some(0.4));
    assert_eq!(teach.notice(), Some("--add-edge 0 3 0.4 done"));
    assert_eq!(teach.selected_edge(), Some((0, 3)));
    teach.pick(0);
    teach.pick(3);
    assert_eq!(teach.net().graph().weight(0, 3), None);
    assert_eq!(teach.notice(), Some("--cut-edge 0 3 done"));
    teach.pick(2);
    teach.pick(2);
    assert_eq!(teach.notice(), Some("π2 let go"));
    assert_eq!(teach.net().graph().edges().count(), 4);
    press(&mut teach, KeyCode::Char('M'));
    teach.pick(1);
    assert_eq!(teach.cursor(), 1);
    assert_eq!(teach.net().graph().edges().count(), 4, "a click only picks");
}

/// `w` mid-walk keeps the walk's position: the saved lesson, run headless without
/// `--activate`, prints the calls the screen showed and the activations it showed; with
/// `--activate 1` it walks the whole walk from the same start.
#[test]
fn a_lesson_saved_mid_walk_gives_the_trace_the_screen_showed() {
    let dir = tempfile::tempdir().unwrap();
    let saved = dir.path().join("mid.ron");
    let mut teach = fig2();
    teach.move_cursor(1);
    press(&mut teach, KeyCode::Char('a'));
    for _ in 0..7 {
        press(&mut teach, KeyCode::Char('s'));
    }
    press(&mut teach, KeyCode::Char('w'));
    for _ in "lesson.ron".chars() {
        press(&mut teach, KeyCode::Backspace);
    }
    type_line(&mut teach, saved.to_str().unwrap());
    let notice = teach.notice().unwrap();
    assert!(notice.ends_with("at call 7 of π1's walk"), "{notice}");
    let shown = teach.walk().unwrap();

    let out = sapnet(&[
        "teach",
        "--headless",
        "--json",
        "--config",
        saved.to_str().unwrap(),
    ]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let trace = json["trace"].as_array().unwrap();
    assert_eq!(trace.len(), 7);
    for (row, step) in trace.iter().zip(shown.trace) {
        assert_eq!(row["to"], step.to);
        assert_eq!(row["from"], step.from);
        assert_eq!(row["delta"].as_f64().unwrap(), step.delta);
    }
    let activations: Vec<f64> = json["activations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(activations, teach.net().activations());

    let whole = sapnet(&[
        "teach",
        "--headless",
        "--json",
        "--activate",
        "1",
        "--config",
        saved.to_str().unwrap(),
    ]);
    let whole: serde_json::Value = serde_json::from_slice(&whole.stdout).unwrap();
    assert_eq!(whole["trace"].as_array().unwrap().len(), 21);
}

/// In tmux, opened with `--exercise`: a teacher adds a policy by `n` (π4, joined to
/// nothing), joins it to π3 at 0.3 by `E`, saves with `w`, and quits; the file, run
/// headless from π4, walks as `--add-policy - --add-edge 4 3 0.3` does, its first call
/// π4 → π3 at h = 1, Ω = 0.3 with η = 𝒜/k = 1: ΔA = 1/(1×0.3) = 3.333333.
#[test]
fn a_teacher_adds_a_policy_and_saves_the_lesson_in_tmux() {
    if !crate::common::tmux::available() {
        eprintln!("tmux is not installed: the end-to-end lesson test is skipped");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let saved = dir.path().join("five.ron");
    let command = format!(
        "{} teach --exercise; echo SAPNET-EXITED $?; sleep 60",
        env!("CARGO_BIN_EXE_sapnet")
    );
    let session = crate::common::tmux::Session::start(120, 40, &command);
    session.wait_for(&["the call", "exercise 0/0"]);
    session.keys("n");
    session.wait_for(&["--add-policy - done"]);
    session.keys("E");
    session.wait_for(&["add edge I J W"]);
    session.keys("4 3 0.3");
    session.keys("Enter");
    session.wait_for(&["--add-edge 4 3 0.3 done"]);
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
        "4",
        "--json",
    ]);
    let by_flags = sapnet(&[
        "teach",
        "--add-policy",
        "-",
        "--add-edge",
        "4",
        "3",
        "0.3",
        "--activate",
        "4",
        "--headless",
        "--json",
    ]);
    assert_eq!(by_keys.stdout, by_flags.stdout);
    let json: serde_json::Value = serde_json::from_slice(&by_keys.stdout).unwrap();
    let first = &json["trace"][0];
    assert_eq!(
        (first["from"].as_u64(), first["to"].as_u64()),
        (Some(4), Some(3))
    );
    assert!((first["delta"].as_f64().unwrap() - 1.0 / 0.3).abs() < 1e-12);
}
