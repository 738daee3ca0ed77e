//! A protocol run in the UI (issue 36, items 1 and 4): `sapnet` without `--headless`
//! trains the config's whole protocol into its `--out` folder and leaves the files
//! `--headless` leaves; `q` asks once and leaves a stopped folder that `--resume`
//! finishes; the stop question, `L`'s picker and the Run view before its run starts,
//! drawn at 80×24 and 120×40 (TestBackend, insta, `NO_COLOR`'s theme).

use std::path::{Path, PathBuf};

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::folder_lock::Holder;
use sapnet::results::folder_state::FolderReader;
use sapnet::tui::theme::Theme;
use sapnet::tui::workbench::screens::session::picker::Picker;
use sapnet::tui::workbench::screens::session::{overlays, Overlay, Phase, Request, Session};
use sapnet::tui::workbench::screens::workbench::Tab;

use crate::common::cli::{configs, sapnet, stderr};
use crate::common::tmux;

const SIZES: [(u16, u16); 2] = [(120, 40), (80, 24)];

fn summary_status(out: &Path) -> String {
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    summary["status"].as_str().unwrap().to_string()
}

/// Done-when: the protocol run in the UI, driven in tmux until it ends, then `q`, leaves
/// comparison.csv, improvement.csv and scores.csv (and the runs' tests and activations)
/// byte for byte as `--headless` leaves them with the same config and seed. The suite
/// uses tiny_transfer.ron (SAP-Net and a DQN, two runs each, on a library of three tiny
/// sources); BENCHMARKS.md says the same of assets/reuse_cartpole.ron with --quick.
#[test]
fn the_protocol_run_in_the_ui_leaves_the_files_of_headless() {
    if !tmux::available() {
        eprintln!("tmux is not installed: the end-to-end protocol test is skipped");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let (library, headless, ui) = (
        tmp.path().join("library"),
        tmp.path().join("headless"),
        tmp.path().join("ui"),
    );
    let output = sapnet()
        .args(["--headless", "--jobs", "2", "--train-library", "--config"])
        .arg(configs("tiny_transfer.ron"))
        .arg("--library")
        .arg(&library)
        .arg("--out")
        .arg(&headless)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));

    let command = format!(
        "{} --jobs 2 --config {} --library {} --out {}; echo SAPNET-EXITED $?; sleep 60",
        env!("CARGO_BIN_EXE_sapnet"),
        configs("tiny_transfer.ron").display(),
        library.display(),
        ui.display()
    );
    let session = tmux::Session::start(120, 40, &command);
    // The Run view follows SAP-Net's run 0 and says where the protocol is.
    let screen = session.wait_for(&["▶ sapnet run 0", "complete", "4 of 4 runs finished"]);
    assert!(screen.contains("SAP-Net graph"), "{screen}");
    // Ended, the protocol leaves the UI open on its results: the Runs view lists them.
    session.keys("r");
    session.wait_for(&["Runs · 4 runs: done 4"]);
    session.keys("q");
    let screen = session.wait_for(&["SAPNET-EXITED 0"]);
    assert!(!screen.contains("Runs · 4 runs"), "{screen}");
    for file in [
        "comparison.csv",
        "improvement.csv",
        "scores.csv",
        "tests.csv",
        "activations.csv",
    ] {
        let (a, b) = (
            std::fs::read(headless.join(file)).unwrap(),
            std::fs::read(ui.join(file)).unwrap(),
        );
        assert!(a == b, "{file} differs between --headless and the UI");
    }
    assert_eq!(summary_status(&ui), "complete");
}

/// `q` while the protocol trains asks once; `y` stops it and the folder is left stopped,
/// and `--headless --resume` finishes it.
#[test]
fn q_asks_once_and_leaves_a_resumable_folder() {
    if !tmux::available() {
        eprintln!("tmux is not installed: the stop test is skipped");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let command = format!(
        "{} --jobs 2 --runs 3 --episodes 600 --config {} --out {}; echo SAPNET-EXITED $?; sleep 60",
        env!("CARGO_BIN_EXE_sapnet"),
        configs("learn_cartpole.ron").display(),
        out.display()
    );
    let session = tmux::Session::start(80, 24, &command);
    session.wait_for(&["▶ dqn[100] run 0 · training"]);
    session.keys("q");
    session.wait_for(&["protocol running: stop it? the folder stays resumable"]);
    session.keys("y");
    session.wait_for(&["SAPNET-EXITED 0"]);
    assert_eq!(summary_status(&out), "stopped");

    let output = sapnet()
        .args(["--headless", "--resume", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    assert_eq!(summary_status(&out), "complete");
}

fn key(code: KeyCode) -> KeyEvent {
    KeyEvent::new(code, KeyModifiers::NONE)
}

fn draw(session: &Session, (w, h): (u16, u16)) -> Terminal<TestBackend> {
    let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
    terminal
        .draw(|f| overlays::draw(f, session, Theme::plain()))
        .unwrap();
    terminal
}

/// The session's screens a protocol run in the UI adds, at both sizes: the stop question
/// over the Runs view of a folder being written, `L`'s picker, and the Run view before the
/// followed run has started.
#[test]
fn the_protocol_screens_at_both_sizes() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let output = sapnet()
        .args(["--headless", "--jobs", "2", "--config"])
        .arg(configs("two_baselines.ron"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let mut folder = FolderReader::new(&out).read().unwrap();
    let report = Some(Some(folder.report()));
    // The folder's path, and who writes it, are the test's own.
    folder.dir = PathBuf::from("out/two_baselines");
    folder.writer = Some(Holder {
        pid: 1234,
        says: "running as PID 1234 on host since 10:02:07 UTC (the protocol)".into(),
    });
    let mut session = Session::new(
        Path::new("out/two_baselines"),
        "CartPole-v1",
        Some(("dqn[16]".into(), 0)),
        Phase::Running,
    );
    session.refreshed(folder, report);

    // Before its run starts, the Run view says so, under the protocol's line.
    for size in SIZES {
        let (w, h) = size;
        let terminal = draw(&session, size);
        let drawn = format!("{}", terminal.backend());
        assert!(drawn.contains("▶ dqn[16] run 0 · training"), "{drawn}");
        assert!(drawn.contains("dqn[16] run 0 has not started"), "{drawn}");
        insta::assert_snapshot!(
            format!("workbench_protocol_run_waiting_{w}x{h}"),
            terminal.backend()
        );
    }

    // `r`, then `q`: the question, over the Runs view.
    assert_eq!(session.on_key(key(KeyCode::Char('r'))), Request::None);
    assert_eq!(session.workbench.tab, Tab::Runs);
    assert_eq!(session.on_key(key(KeyCode::Char('q'))), Request::None);
    assert!(matches!(
        session.overlay,
        Some(Overlay::Stop { then_quit: true })
    ));
    for size in SIZES {
        let (w, h) = size;
        let terminal = draw(&session, size);
        let drawn = format!("{}", terminal.backend());
        assert!(
            drawn.contains("protocol running: stop it? the folder stays resumable"),
            "{drawn}"
        );
        insta::assert_snapshot!(
            format!("workbench_protocol_stop_{w}x{h}"),
            terminal.backend()
        );
    }

    // Ended, `L` opens the picker on the shipped configs.
    session.on_key(key(KeyCode::Char('n')));
    session.phase = Phase::Ended(sapnet::results::Status::Complete);
    session.on_key(key(KeyCode::Char('L')));
    let Some(Overlay::Picker(picker)) = &mut session.overlay else {
        panic!("L opened no picker");
    };
    // A folder of two configs and a lesson, as assets/ holds them (the shipped list
    // changes; `picker`'s unit test reads the real one).
    let assets = tmp.path().join("assets");
    std::fs::create_dir(&assets).unwrap();
    for name in ["two_baselines.ron", "short_cartpole.ron"] {
        std::fs::copy(configs(name), assets.join(name)).unwrap();
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::copy(
        root.join("assets/teach_fig2.ron"),
        assets.join("teach_fig2.ron"),
    )
    .unwrap();
    *picker = Picker::of(&assets);
    assert_eq!(picker.entries.len(), 2);
    assert_eq!(picker.left_out, 1);
    picker.dir = PathBuf::from("assets");
    for size in SIZES {
        let (w, h) = size;
        let terminal = draw(&session, size);
        let drawn = format!("{}", terminal.backend());
        assert!(
            drawn.contains("short_cartpole.ron  A few seconds of DQN on CartPole"),
            "{drawn}"
        );
        assert!(
            drawn.contains("launch a protocol into a new folder"),
            "{drawn}"
        );
        insta::assert_snapshot!(
            format!("workbench_protocol_picker_{w}x{h}"),
            terminal.backend()
        );
    }
}
