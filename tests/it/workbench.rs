//! The workbench (issue 36): `sapnet open DIR` on finished and live folders, its views
//! drawn at 80×24 and 120×40 (TestBackend, insta, `NO_COLOR`'s theme), its Comparison
//! equal to `comparison.csv`, and `sapnet plot` refusing a folder another process writes.
//! Each test makes its folder with the binary; a live folder is a headless protocol
//! stopped (SIGSTOP) mid-run, so that it holds its lock and its files stay still while
//! they are compared.

use std::collections::BTreeMap;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::folder_lock::{FolderLock, Holder};
use sapnet::results::folder_state::{FolderReader, RunStatus};
use sapnet::tui::theme::Theme;
use sapnet::tui::workbench::state::Workbench;
use sapnet::tui::workbench::view;

use crate::common::library::quick_protocol;
use crate::common::tmux;

const SIZES: [(u16, u16); 2] = [(120, 40), (80, 24)];

fn sapnet() -> Command {
    Command::new(env!("CARGO_BIN_EXE_sapnet"))
}

fn configs(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/configs")
        .join(name)
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn key(c: char) -> KeyEvent {
    KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE)
}

/// A finished protocol of tests/configs/two_baselines.ron in `out`.
fn finished_folder(out: &Path) {
    let output = sapnet()
        .args(["--headless", "--jobs", "2", "--config"])
        .arg(configs("two_baselines.ron"))
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
}

/// The workbench on `out` as the binary opens it, its views pressed by `keys`.
fn workbench(out: &Path, keys: &str) -> Workbench {
    let folder = FolderReader::new(out).read().unwrap();
    let report = (!folder.finished_key().is_empty()).then(|| folder.report());
    let mut workbench = Workbench::new(folder, report);
    for c in keys.chars() {
        workbench.on_key(key(c));
    }
    workbench
}

fn screen(workbench: &Workbench, (w, h): (u16, u16)) -> Terminal<TestBackend> {
    let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
    terminal
        .draw(|f| view::draw(f, workbench, Theme::plain()))
        .unwrap();
    terminal
}

fn text(terminal: &Terminal<TestBackend>) -> String {
    format!("{}", terminal.backend())
}

/// Every entry under `dir` (the lock file too) with its size, modification time and bytes.
fn listing(dir: &Path) -> BTreeMap<PathBuf, (u64, i64, i64, Vec<u8>)> {
    let mut entries = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(at) = todo.pop() {
        for entry in std::fs::read_dir(&at).unwrap() {
            let path = entry.unwrap().path();
            let meta = std::fs::symlink_metadata(&path).unwrap();
            let bytes = if meta.is_file() {
                std::fs::read(&path).unwrap()
            } else {
                todo.push(path.clone());
                Vec::new()
            };
            entries.insert(path, (meta.len(), meta.mtime(), meta.mtime_nsec(), bytes));
        }
    }
    entries
}

/// A protocol of two_baselines.ron (its runs made long) into `out`, one run at a time,
/// stopped by SIGSTOP once a run has finished and the next has episodes on disk: a live
/// folder whose process holds the lock and writes nothing while the test reads it.
fn stopped_protocol(out: &Path) -> Child {
    let child = sapnet()
        .args(["--headless", "--jobs", "1", "--episodes", "400", "--config"])
        .arg(configs("two_baselines.ron"))
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let runs = out.join("runs");
    let ready = || {
        let Ok(entries) = std::fs::read_dir(&runs) else {
            return false;
        };
        let (mut finished, mut partial_rows) = (false, false);
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.ends_with(".partial") {
                partial_rows |= std::fs::read_to_string(entry.path().join("episodes.csv"))
                    .is_ok_and(|t| t.lines().count() > 5);
            } else {
                finished |= entry.path().join("run.json").exists();
            }
        }
        finished && partial_rows
    };
    let started = Instant::now();
    while !ready() {
        assert!(started.elapsed() < Duration::from_secs(120), "never ready");
        std::thread::sleep(Duration::from_millis(5));
    }
    signal(&child, "STOP");
    // The process has stopped once its state says so: nothing it does is under way.
    let stat = format!("/proc/{}/stat", child.id());
    while !std::fs::read_to_string(&stat).is_ok_and(|s| s.contains(") T ")) {
        std::thread::sleep(Duration::from_millis(5));
    }
    child
}

fn signal(child: &Child, name: &str) {
    assert!(Command::new("kill")
        .arg(format!("-{name}"))
        .arg(child.id().to_string())
        .status()
        .unwrap()
        .success());
}

fn end(mut child: Child) {
    let _ = child.kill();
    let _ = child.wait();
}

/// Item 6: `sapnet plot` on a folder whose protocol is running exits 2, naming the
/// process (its PID, since when) and `sapnet open`, and changes nothing there.
#[test]
fn plot_refuses_a_live_folder_naming_its_writer_and_changes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("live");
    let child = stopped_protocol(&out);
    let pid = child.id();
    let before = listing(&out);
    let output = sapnet().arg("plot").arg(&out).output().unwrap();
    let after = listing(&out);
    end(child);
    let said = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{said}");
    for names in [
        format!("written by the sapnet process PID {pid} since "),
        format!("running as PID {pid} on "),
        format!("sapnet open {}", out.display()),
    ] {
        assert!(said.contains(&names), "{names:?} in {said}");
    }
    assert_eq!(before, after, "sapnet plot changed the live folder");
    assert!(!out.join("comparison.csv").exists());
}

/// Item 3: `sapnet open` on a live folder shows who writes it and its progress — finished
/// runs of all, the running one, the queued ones — without an error, and changes nothing
/// in it: the binary in a tmux pane, driven to the Comparison view and out.
#[test]
fn open_shows_a_live_folders_progress_and_changes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("live");
    let child = stopped_protocol(&out);
    let pid = child.id();
    let before = listing(&out);
    // What the folder holds, counted from its files.
    let folder = FolderReader::new(&out).read().unwrap();
    let done = folder.finished_runs();
    let count = |s: RunStatus| folder.runs.iter().filter(|r| r.status == s).count();
    assert!(done >= 1, "a finished run");
    assert_eq!(count(RunStatus::Running), 1, "one job: one run in progress");
    assert_eq!(done + 1 + count(RunStatus::Queued), 6);
    assert_eq!(folder.writer.as_ref().map(|w| w.pid), Some(pid));
    // The views, drawn from it.
    let drawn = text(&screen(&workbench(&out, ""), (120, 40)));
    for said in [
        format!("written by PID {pid} since "),
        format!("{done} of 6 runs finished"),
        "running".to_string(),
        "queued".to_string(),
    ] {
        assert!(drawn.contains(&said), "{said:?} in\n{drawn}");
    }
    // The dashboard's `--compare` takes it too: a band of each method's finished runs.
    let bands = sapnet::tui::reference::bands_of_folder(&out, "CartPole-v1").unwrap();
    let banded: usize = bands.iter().map(|b| b.runs).sum();
    assert_eq!(banded, done, "{bands:?}");
    let comparison = text(&screen(&workbench(&out, "c"), (120, 40)));
    assert!(
        comparison.contains(&format!("partial: over the {done} finished runs of 6")),
        "{comparison}"
    );
    // The binary itself, as a user runs it.
    if tmux::available() {
        let command = format!(
            "{} open {}; echo SAPNET-EXITED $?; sleep 60",
            env!("CARGO_BIN_EXE_sapnet"),
            out.display()
        );
        let session = tmux::Session::start(120, 40, &command);
        session.wait_for(&[&format!("written by PID {pid}"), "running", "queued"]);
        session.keys("c");
        session.wait_for(&["partial: over the", "P(dqn[16] > Y)"]);
        session.keys("q");
        session.wait_for(&["SAPNET-EXITED 0"]);
    } else {
        eprintln!("tmux is not installed: the binary's part of this test is skipped");
    }
    let after = listing(&out);
    end(child);
    assert_eq!(before, after, "sapnet open changed the live folder");
}

/// Item 5's check: the Comparison view of a finished `--quick` protocol of
/// assets/reuse_cartpole.ron shows every method's IQM, mean, median and optimality gap
/// of both scores with their intervals, equal to comparison.csv as the stdout table
/// rounds them (a tenth of a return; a thousandth of the normalised gap).
#[test]
fn the_comparison_view_shows_the_numbers_of_comparison_csv() {
    let tmp = tempfile::tempdir().unwrap();
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/reuse_cartpole.ron");
    let (out, _) = quick_protocol(&config, "cartpole", tmp.path());
    let mut reader = csv::Reader::from_path(out.join("comparison.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert!(rows.len() >= 5, "the comparison's methods");
    let column = |row: &csv::StringRecord, name: &str| -> f64 {
        let i = header.iter().position(|h| h == name).unwrap();
        row[i].parse().unwrap()
    };
    let mut workbench = workbench(&out, "c");
    for (aggregate, digits) in [
        ("iqm", 1),
        ("mean", 1),
        ("median", 1),
        ("optimality_gap", 3),
    ] {
        let drawn = text(&screen(&workbench, (120, 40)));
        assert!(drawn.contains("over all"), "{drawn}");
        for row in &rows {
            let method = &row[0];
            let line = drawn
                .lines()
                .find(|l| l.contains(&format!("│{method} ")))
                .unwrap_or_else(|| panic!("{method} in\n{drawn}"));
            for score in ["return", "test"] {
                let [point, lo, hi] =
                    ["", "_lo", "_hi"].map(|end| column(row, &format!("{score}_{aggregate}{end}")));
                let expected = format!("{point:.digits$} [{lo:.digits$}, {hi:.digits$}]");
                assert!(
                    line.contains(&expected),
                    "{method} {score} {aggregate}: {expected} in {line}"
                );
            }
        }
        workbench.on_key(key('a'));
    }
}

/// The views of a finished folder and of one being written, at both sizes, without
/// colour: Runs, Comparison (IQM, then the test score's pairs), the keys.
#[test]
fn the_views_at_both_sizes() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    finished_folder(&out);
    let steady = |mut w: Workbench| {
        // The folder's path is the test's temporary one.
        w.folder.dir = PathBuf::from("out/two_baselines");
        w
    };
    for size in SIZES {
        let (w, h) = size;
        for (name, keys) in [
            ("runs", ""),
            ("comparison", "c"),
            ("comparison_test", "cjs"),
            ("help", "?"),
        ] {
            let terminal = screen(&steady(workbench(&out, keys)), size);
            insta::assert_snapshot!(format!("workbench_{name}_{w}x{h}"), terminal.backend());
        }
    }

    // The same folder as a protocol still running would leave it: run 1 of dqn[8] in
    // progress at its 12th episode, run 2 of both methods not started, the lock held.
    let live = tmp.path().join("live");
    finished_folder(&live);
    let runs = live.join("runs");
    std::fs::remove_dir_all(runs.join("dqn-8-run2")).unwrap();
    std::fs::remove_dir_all(runs.join("dqn-16-run2")).unwrap();
    let partial = runs.join(".dqn-8-run1.partial");
    std::fs::rename(runs.join("dqn-8-run1"), &partial).unwrap();
    for done in ["run.json", "tests.csv"] {
        std::fs::remove_file(partial.join(done)).unwrap();
    }
    let episodes = std::fs::read_to_string(partial.join("episodes.csv")).unwrap();
    let kept: Vec<&str> = episodes.lines().take(13).collect();
    std::fs::write(partial.join("episodes.csv"), kept.join("\n") + "\n").unwrap();
    let _lock = FolderLock::acquire(&live, "the protocol").unwrap();
    for size in SIZES {
        let (w, h) = size;
        for (name, keys) in [("live_runs", ""), ("live_comparison", "c")] {
            let mut workbench = steady(workbench(&live, keys));
            assert_eq!(
                workbench.folder.writer.as_ref().map(|w| w.pid),
                Some(std::process::id())
            );
            // Who holds the lock, and the running run's pace, are this test's own.
            workbench.folder.writer = Some(Holder {
                pid: 1234,
                says: "running as PID 1234 on host since 10:02:07 UTC (the protocol)".into(),
            });
            for run in &mut workbench.folder.runs {
                if run.status == RunStatus::Running {
                    run.wall_s = Some(6.0);
                }
            }
            let terminal = screen(&workbench, size);
            let drawn = text(&terminal);
            assert!(
                drawn.contains("written by PID 1234 since 10:02 UTC"),
                "{drawn}"
            );
            assert!(drawn.contains("3 of 6 runs finished"), "{drawn}");
            insta::assert_snapshot!(format!("workbench_{name}_{w}x{h}"), terminal.backend());
        }
    }
}

/// A folder from elsewhere is untrusted: a partial record planted as a link, or a row
/// that is not a number, is refused before the screen opens — exit 2, naming the file,
/// the row and what was expected — and the link is not followed.
#[test]
fn open_refuses_a_bad_file_naming_it_before_the_screen_opens() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    finished_folder(&out);
    let runs = out.join("runs");
    std::fs::remove_dir_all(runs.join("dqn-8-run2")).unwrap();
    let partial = runs.join(".dqn-8-run2.partial");
    std::fs::create_dir(&partial).unwrap();
    let secret = tmp.path().join("secret.csv");
    std::fs::write(&secret, "run,method,episode,reward\n0,x,1,1.0\n").unwrap();
    std::os::unix::fs::symlink(&secret, partial.join("episodes.csv")).unwrap();
    let output = sapnet().arg("open").arg(&out).output().unwrap();
    let said = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{said}");
    assert!(said.contains(".dqn-8-run2.partial/episodes.csv"), "{said}");
    assert!(said.contains("symbolic link"), "{said}");

    std::fs::remove_file(partial.join("episodes.csv")).unwrap();
    std::fs::write(
        partial.join("episodes.csv"),
        "run,method,episode,reward,steps,loss,statistic_loss,epsilon,policy,wall_s\n\
         2,dqn[8],1,lots,12,,0.0,0.03,,0.5\n",
    )
    .unwrap();
    let output = sapnet().arg("open").arg(&out).output().unwrap();
    let said = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{said}");
    for names in [
        "episodes.csv: row 2",
        "expected the columns run, method",
        "reward",
    ] {
        assert!(said.contains(names), "{names:?} in {said}");
    }
}
