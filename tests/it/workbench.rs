//! The workbench (issue 36): `sapnet open DIR` on finished and live folders, its views
//! drawn at 80×24 and 120×40 (TestBackend, insta, `NO_COLOR`'s theme), its Comparison
//! equal to `comparison.csv`, and `sapnet plot` refusing a folder another process writes.
//! Each test makes its folder with the binary; a live folder is a headless protocol
//! stopped (SIGSTOP) mid-run, so that it holds its lock and its files stay still while
//! they are compared.

use std::collections::BTreeMap;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::folder_lock::{FolderLock, Holder};
use sapnet::results::folder_state::{FolderReader, RunStatus};
use sapnet::tui::theme::Theme;
use sapnet::tui::workbench::screens::opened::Opened;

use crate::common::cli::{configs, sapnet, stderr};
use crate::common::library::quick_protocol;
use crate::common::tmux;

const SIZES: [(u16, u16); 2] = [(120, 40), (80, 24)];

/// A key as the tests spell it: `\n` is Enter.
fn key(c: char) -> KeyEvent {
    let code = match c {
        '\n' => KeyCode::Enter,
        c => KeyCode::Char(c),
    };
    KeyEvent::new(code, KeyModifiers::NONE)
}

/// A finished protocol of tests/configs/two_baselines.ron in `out`.
fn finished_folder(out: &Path) {
    protocol_into(&configs("two_baselines.ron"), out);
}

/// The protocol of `config` run headless into `out`, on two jobs.
fn protocol_into(config: &Path, out: &Path) {
    let output = sapnet()
        .args(["--headless", "--jobs", "2", "--config"])
        .arg(config)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
}

/// The workbench on `out` as the binary opens it, its views pressed by `keys`.
fn workbench(out: &Path, keys: &str) -> Opened {
    let folder = FolderReader::new(out).read().unwrap();
    let report = (!folder.finished_key().is_empty()).then(|| folder.report());
    let mut workbench = Opened::new(folder, report);
    for c in keys.chars() {
        workbench.on_key(key(c));
    }
    workbench
}

/// The screen drawn, with the curves the Curves view makes in the background once they
/// are made (a user sees them a moment later).
fn screen(workbench: &Opened, (w, h): (u16, u16)) -> Terminal<TestBackend> {
    let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
    terminal
        .draw(|f| workbench.draw(f, Theme::plain()))
        .unwrap();
    workbench.workbench.curves.settle();
    terminal
        .draw(|f| workbench.draw(f, Theme::plain()))
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
    // Returned to the caller, who ends it and waits for it; a test that panics here
    // leaves it to the test harness's end.
    #[allow(clippy::zombie_processes)]
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
    let stat = format!("/proc/{}/stat", child.id());
    loop {
        while !ready() {
            assert!(started.elapsed() < Duration::from_secs(120), "never ready");
            std::thread::sleep(Duration::from_millis(5));
        }
        signal(&child, "STOP");
        // The process has stopped once its state says so: nothing it does is under way.
        while !std::fs::read_to_string(&stat).is_ok_and(|s| s.contains(") T ")) {
            std::thread::sleep(Duration::from_millis(5));
        }
        // The run seen in progress may have ended between the look and the stop (its
        // folder renamed, the next not begun): look again, stopped.
        if ready() {
            return child;
        }
        signal(&child, "CONT");
    }
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
        format!("written by the sapnet process PID {pid} on "),
        format!("sapnet open {}", out.display()),
    ] {
        assert!(said.contains(&names), "{names:?} in {said}");
    }
    assert_eq!(
        said.matches(&format!("PID {pid}")).count(),
        1,
        "the PID once: {said}"
    );
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
        comparison.contains(&format!("partial: over the {done} finished of 6 runs")),
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
        session.keys("v");
        session.wait_for(&["MA10 IQM over runs, 95% band · partial"]);
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
    let steady = |mut w: Opened| {
        // The folder's path is the test's temporary one.
        w.folder_mut().state.dir = PathBuf::from("out/two_baselines");
        w
    };
    for size in SIZES {
        let (w, h) = size;
        for (name, keys) in [
            ("runs", ""),
            ("comparison", "c"),
            ("comparison_test", "cjs"),
            ("curves", "v"),
            ("curves_zoomed_mean", "v+m"),
            ("curves_one_run", "vj\n]"),
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
        for (name, keys) in [
            ("live_runs", ""),
            ("live_comparison", "c"),
            ("live_curves", "v"),
        ] {
            let mut workbench = steady(workbench(&live, keys));
            assert_eq!(
                workbench.folder().state.writer.as_ref().map(|w| w.pid),
                Some(std::process::id())
            );
            // Who holds the lock, and the running run's pace, are this test's own.
            workbench.folder_mut().state.writer = Some(Holder {
                pid: 1234,
                says: "running as PID 1234 on host since 10:02:07 UTC (the protocol)".into(),
            });
            for run in &mut workbench.folder_mut().state.runs {
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

/// `sample_efficiency.csv`'s rows of `method` and `statistic`, as (episode or step, runs,
/// value, lo, hi), the numbers as the file writes them.
pub fn efficiency_rows(
    out: &Path,
    method: &str,
    statistic: &str,
) -> Vec<(String, String, [String; 3])> {
    let mut reader = csv::Reader::from_path(out.join("sample_efficiency.csv")).unwrap();
    reader
        .records()
        .map(Result::unwrap)
        .filter(|r| &r[0] == method && &r[3] == statistic)
        .map(|r| {
            (
                r[1].to_string(),
                r[2].to_string(),
                [r[4].to_string(), r[5].to_string(), r[6].to_string()],
            )
        })
        .collect()
}

/// A curve's points of one statistic (`of`) as `sample_efficiency.csv` writes them: (at,
/// runs, [value, lo, hi]).
pub fn as_written(
    points: &[sapnet::report::metric::CurvePoint],
    of: fn(&sapnet::report::metric::CurvePoint) -> sapnet::stats::Estimate,
) -> Vec<(String, String, [String; 3])> {
    points
        .iter()
        .map(|p| {
            let e = of(p);
            (
                p.at.to_string(),
                p.runs.to_string(),
                [e.point, e.lo, e.hi].map(|x| format!("{x:?}")),
            )
        })
        .collect()
}

/// Item 2, Curves: each method's curve is `sample_efficiency.csv`'s, point for point (the
/// same episodes, runs, values and interval ends, as the file writes them), for the IQM
/// and the mean; the legend shows each one's value where the view ends, to a tenth, and
/// after a zoom the value at the zoomed range's last point.
#[test]
fn the_curves_view_shows_the_points_of_sample_efficiency_csv() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    finished_folder(&out);
    let mut workbench = workbench(&out, "v");
    // sample_efficiency.csv's axis, the budget's: episodes (the view's default is the
    // step, every run having steps).
    workbench.workbench.curves.axis = Some(sapnet::report::metric::XAxis::Episode);
    let labels = ["dqn[16]", "dqn[8]"];
    for (index, label) in labels.iter().enumerate() {
        let points = workbench.workbench.curves.curve(workbench.folder(), index);
        for (statistic, of) in [
            (
                "iqm",
                (|p: &sapnet::report::metric::CurvePoint| p.iqm) as fn(&_) -> _,
            ),
            ("mean", |p| p.mean),
        ] {
            let rows = efficiency_rows(&out, label, statistic);
            // Episodes 10 to 30 of MA10: 21 points.
            assert_eq!(rows.len(), 21, "{label} {statistic}");
            assert_eq!(as_written(&points, of), rows, "{label} {statistic}");
        }
    }
    let legend_value = |workbench: &Opened, label: &str| -> String {
        let drawn = text(&screen(workbench, (120, 40)));
        let line = drawn
            .lines()
            .find(|l| l.contains(&format!(" {label} ")) && (l.contains("■ ") || l.contains("□ ")))
            .unwrap_or_else(|| panic!("{label} in the legend of\n{drawn}"))
            .to_string();
        let at = line.find(&format!("{label} ")).unwrap() + label.len();
        line[at..]
            .trim_end_matches('"')
            .trim_end_matches('│')
            .trim()
            .to_string()
    };
    let tenth = |row: &(String, String, [String; 3])| {
        let [v, lo, hi] = row.2.clone().map(|x| x.parse::<f64>().unwrap());
        format!("{v:.1} [{lo:.1}, {hi:.1}]")
    };
    for (statistic, keys) in [("iqm", ""), ("mean", "m")] {
        for k in keys.chars() {
            workbench.on_key(key(k));
        }
        for label in labels {
            let rows = efficiency_rows(&out, label, statistic);
            assert_eq!(legend_value(&workbench, label), tenth(rows.last().unwrap()));
        }
    }
    // Zoomed in once: half of episodes 1 to 30 around their middle, 15.5 ± 7.25, is
    // narrower than twenty, so 15.5 ± 10, in whole episodes 6 to 26: the last point
    // shown is episode 26's.
    workbench.on_key(key('m'));
    workbench.on_key(key('+'));
    let (from, to) = workbench.workbench.curves.range(workbench.folder());
    assert_eq!((from, to), (6.0, 26.0));
    let drawn = text(&screen(&workbench, (120, 40)));
    assert!(drawn.contains("ep 6–26 of 30"), "{drawn}");
    assert!(drawn.contains("IQM [95% CI] at ep 26"), "{drawn}");
    for label in labels {
        let rows = efficiency_rows(&out, label, "iqm");
        let row = rows.iter().find(|r| r.0 == "26").unwrap();
        assert_eq!(legend_value(&workbench, label), tenth(row));
    }
    // Space hides the picked method (the first): its legend box empties.
    workbench.on_key(key(' '));
    assert!(workbench.workbench.curves.hidden.contains(&0));
    let drawn = text(&screen(&workbench, (120, 40)));
    assert!(drawn.contains("□ ● dqn[16]"), "{drawn}");
    assert!(drawn.contains("■ ▲ dqn[8]"), "{drawn}");
}

/// Each method's line is drawn in the plots' colour of that method
/// (`report::plots::palette`), and without colour each carries a marker of its own.
#[test]
fn the_curves_are_drawn_in_each_methods_colour_or_marker() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    finished_folder(&out);
    let workbench = workbench(&out, "v");
    // The curves made first (in the background, a moment after the view opens).
    workbench.workbench.curves.made_now(workbench.folder());
    let kinds: Vec<_> = workbench
        .folder()
        .state
        .config
        .protocol
        .methods
        .iter()
        .map(|m| m.kind())
        .collect();
    let colours = sapnet::report::plots::palette::method_colours(&kinds);
    assert_ne!(colours[0], colours[1], "two DQN sizes read apart");
    let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
    terminal
        .draw(|f| workbench.draw(f, Theme { color: true }))
        .unwrap();
    let buffer = terminal.backend().buffer();
    for (r, g, b) in colours {
        let colour = ratatui::style::Color::Rgb(r, g, b);
        // Braille cells of the curve (not only the legend's swatch).
        let cells = buffer
            .content()
            .iter()
            .filter(|c| {
                c.fg == colour
                    && ('\u{2801}'..='\u{28ff}').contains(&c.symbol().chars().next().unwrap_or(' '))
            })
            .count();
        assert!(cells > 10, "{cells} braille cells of {colour:?}");
    }
    let plain = text(&screen(&workbench, (120, 40)));
    for (marker, label) in [("●", "dqn[16]"), ("▲", "dqn[8]")] {
        assert!(plain.contains(&format!("{marker} {label}")), "{plain}");
        assert!(
            plain.matches(marker).count() > 2,
            "markers along {label}'s line in\n{plain}"
        );
    }
}

/// Item 5, one truth: for a finished tiny folder of every kind of method, the Comparison
/// view's intervals are exactly the stdout table's cells (IQM of the training return and
/// of the test score), which are comparison.csv's numbers to a tenth; and lock-in is one
/// figure said one way: the table's cell is [`lock_in::over_runs`] of comparison.csv's
/// columns, a number for SAP-Net and PRQ-learning, `-` (an empty `locked_runs`) for every
/// other method.
#[test]
fn the_comparison_view_and_lock_in_equal_the_table_and_comparison_csv() {
    use sapnet::reuse::lock_in;
    let tmp = tempfile::tempdir().unwrap();
    let library = tmp.path().join("lib");
    let sources = sapnet()
        .args(["sources", "--config"])
        .arg(configs("tiny_sources.ron"))
        .arg("--library")
        .arg(&library)
        .output()
        .unwrap();
    assert!(sources.status.success(), "{}", stderr(&sources));
    let out = tmp.path().join("out");
    let run = sapnet()
        .args(["--headless", "--jobs", "2", "--config"])
        .arg(configs("tiny_reuse.ron"))
        .arg("--library")
        .arg(&library)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", stderr(&run));
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    // The table: cells two spaces or more apart.
    let mut lines = stdout.lines().skip_while(|l| !l.starts_with("method "));
    let header: Vec<String> = split_cells(lines.next().expect("the table"));
    let table: Vec<Vec<String>> = lines
        .take_while(|l| !l.trim().is_empty())
        .map(split_cells)
        .collect();
    let at = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut reader = csv::Reader::from_path(out.join("comparison.csv")).unwrap();
    let csv_header = reader.headers().unwrap().clone();
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 9);
    assert_eq!(table.len(), rows.len(), "{stdout}");
    let column = |row: &csv::StringRecord, name: &str| -> String {
        row[csv_header.iter().position(|h| h == name).unwrap()].to_string()
    };
    let workbench = workbench(&out, "c");
    let drawn = text(&screen(&workbench, (120, 40)));
    let mut measured = Vec::new();
    // The view's rows, in the table's order below its header (a long label is cut).
    let view_rows: Vec<&str> = drawn
        .lines()
        .skip_while(|l| !l.starts_with("\"│method "))
        .skip(1)
        .collect();
    for ((line, row), shown) in table.iter().zip(&rows).zip(view_rows) {
        let method = &row[0];
        assert_eq!(&line[0], method);
        // The table's cells are comparison.csv's numbers to a tenth.
        for (cell, score) in [
            ("return IQM [95% CI]", "return"),
            ("test IQM [95% CI]", "test"),
        ] {
            let [v, lo, hi] = ["", "_lo", "_hi"].map(|end| {
                column(row, &format!("{score}_iqm{end}"))
                    .parse::<f64>()
                    .unwrap()
            });
            assert_eq!(
                line[at(cell)],
                format!("{v:.1} [{lo:.1}, {hi:.1}]"),
                "{method}"
            );
        }
        // The view's row shows those two cells, and no other interval.
        let label: String = method.chars().take(21).collect();
        assert!(
            shown.starts_with(&format!("\"│{label}")),
            "{method}: {shown}"
        );
        let intervals: Vec<String> = intervals_in(shown);
        assert_eq!(
            intervals,
            [
                line[at("return IQM [95% CI]")].clone(),
                line[at("test IQM [95% CI]")].clone()
            ],
            "{method}: {shown}"
        );
        // Lock-in: the table's cell from the CSV's two columns by the one definition.
        let runs: usize = column(row, "runs").parse().unwrap();
        let median = column(row, "lock_in_median_step");
        let locked = column(row, "locked_runs");
        let is_measured = !locked.is_empty();
        let said = lock_in::over_runs(
            is_measured,
            median.parse().ok(),
            locked.parse().unwrap_or(0),
            runs,
        );
        assert_eq!(line[at("lock-in step")], said, "{method}");
        if is_measured {
            measured.push(method.to_string());
        }
    }
    assert_eq!(
        measured,
        [
            "sapnet",
            "sapnet-episode-decay0.99",
            "sapnet-tau-lin5-1-k5",
            "prql[8]"
        ],
        "lock-in means something for the learned selections only"
    );
}

/// The cells of a line of the stdout table.
fn split_cells(line: &str) -> Vec<String> {
    line.split("  ")
        .map(str::trim)
        .filter(|c| !c.is_empty())
        .map(String::from)
        .collect()
}

/// Every `12.3 [4.5, 6.7]` in a line, in order.
fn intervals_in(line: &str) -> Vec<String> {
    let mut found = Vec::new();
    let mut rest = line;
    while let Some(open) = rest.find(" [") {
        let start = rest[..open]
            .rfind(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
            .map_or(0, |i| i + 1);
        let Some(close) = rest[open..].find(']') else {
            break;
        };
        let candidate = &rest[start..open + close + 1];
        if start < open {
            found.push(candidate.to_string());
        }
        rest = &rest[open + close + 1..];
    }
    found
}

/// Where `needle` is drawn on `terminal`'s screen: its (column, row).
fn drawn_at(terminal: &Terminal<TestBackend>, needle: &str) -> (u16, u16) {
    let buffer = terminal.backend().buffer();
    let width = usize::from(buffer.area.width);
    let rows: Vec<String> = buffer
        .content()
        .chunks(width)
        .map(|row| row.iter().map(|c| c.symbol()).collect())
        .collect();
    for (y, row) in rows.iter().enumerate() {
        if let Some(byte) = row.find(needle) {
            let x = row[..byte].chars().count();
            return (x as u16, y as u16);
        }
    }
    panic!("{needle:?} not drawn in\n{}", rows.join("\n"));
}

/// Item 8, the mouse: a click on a view's name in the status bar shows it, on a run's
/// line picks the run, on a method's row of the Comparison picks the method, and on a
/// method in the Curves view's legend picks it and hides it (a second click shows it).
#[test]
fn a_click_picks_a_view_a_run_a_method_and_a_legend_entry() {
    use crossterm::event::{MouseButton, MouseEvent, MouseEventKind};
    use sapnet::tui::workbench::screens::workbench::Tab;
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    finished_folder(&out);
    let mut workbench = workbench(&out, "");
    let size = ratatui::layout::Rect::new(0, 0, 120, 40);
    let click = |workbench: &mut Opened, (column, row): (u16, u16)| {
        let event = MouseEvent {
            kind: MouseEventKind::Down(MouseButton::Left),
            column,
            row,
            modifiers: KeyModifiers::NONE,
        };
        assert!(
            workbench.on_mouse(event, size),
            "a click at {column}, {row}"
        );
    };
    // Runs: the first run of dqn[8] is the fourth (index 3).
    let at = drawn_at(&screen(&workbench, (120, 40)), "dqn[8]  0");
    click(&mut workbench, at);
    assert_eq!(workbench.workbench.runs.cursor, 3);
    let at = drawn_at(&screen(&workbench, (120, 40)), "v curves");
    click(&mut workbench, at);
    assert_eq!(workbench.workbench.tab, Tab::Curves);
    let at = drawn_at(&screen(&workbench, (120, 40)), "■ ▲ dqn[8]");
    click(&mut workbench, at);
    assert_eq!(workbench.workbench.curves.cursor, 1);
    assert!(workbench.workbench.curves.hidden.contains(&1));
    assert!(text(&screen(&workbench, (120, 40))).contains("□ ▲ dqn[8]"));
    click(&mut workbench, at);
    assert!(workbench.workbench.curves.hidden.is_empty());
    let at = drawn_at(&screen(&workbench, (120, 40)), "c comparison");
    click(&mut workbench, at);
    assert_eq!(workbench.workbench.tab, Tab::Comparison);
    let at = drawn_at(&screen(&workbench, (120, 40)), "│dqn[8] ");
    click(&mut workbench, (at.0 + 1, at.1));
    assert_eq!(workbench.workbench.comparison.cursor, 1);
}

/// Item 4: a folder shipped with its top-level files only (no `runs/`, as `docs/`'s) opens
/// from `summary.json` and `episodes.csv`, every run done, its Comparison the one its
/// `comparison.csv` holds; with its episodes compressed (`episodes.csv.xz`, as `docs/` ships
/// them) the same; with them damaged, `sapnet open` exits 2 naming the file. Nothing in the
/// folder changes either way.
#[test]
fn open_reads_a_shipped_folder_from_its_top_level_files_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("shipped");
    finished_folder(&out);
    std::fs::remove_dir_all(out.join("runs")).unwrap();
    let before = listing(&out);
    let folder = FolderReader::new(&out).read().unwrap();
    assert_eq!(folder.finished_runs(), 6);
    assert!(folder.runs.iter().all(|r| r.episodes() == 30));
    let drawn = text(&screen(&workbench(&out, "c"), (120, 40)));
    assert!(drawn.contains("6 of 6 runs finished"), "{drawn}");
    let mut reader = csv::Reader::from_path(out.join("comparison.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    for row in reader.records().map(Result::unwrap) {
        let column = |name: &str| -> f64 {
            row[header.iter().position(|h| h == name).unwrap()]
                .parse()
                .unwrap()
        };
        let expected = format!(
            "{:.1} [{:.1}, {:.1}]",
            column("return_iqm"),
            column("return_iqm_lo"),
            column("return_iqm_hi")
        );
        assert!(drawn.contains(&expected), "{expected} in\n{drawn}");
    }
    assert_eq!(before, listing(&out), "opening changed the shipped folder");

    // Compressed, as docs/ ships it: read the same, the folder untouched.
    let episodes = std::fs::read(out.join("episodes.csv")).unwrap();
    std::fs::remove_file(out.join("episodes.csv")).unwrap();
    let mut xz = Vec::new();
    lzma_rs::xz_compress(&mut &episodes[..], &mut xz).unwrap();
    std::fs::write(out.join("episodes.csv.xz"), &xz).unwrap();
    let before = listing(&out);
    let compressed = FolderReader::new(&out).read().unwrap();
    assert_eq!(compressed.finished_runs(), 6);
    assert_eq!(
        text(&screen(&workbench(&out, "c"), (120, 40))),
        drawn,
        "the compressed folder drew otherwise"
    );
    assert_eq!(before, listing(&out), "opening changed the shipped folder");

    // Damaged: refused before the screen opens, naming the file.
    std::fs::write(out.join("episodes.csv.xz"), &xz[..xz.len() / 2]).unwrap();
    let before = listing(&out);
    let output = sapnet().arg("open").arg(&out).output().unwrap();
    let said = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{said}");
    assert!(said.contains("episodes.csv.xz"), "{said}");
    assert_eq!(
        before,
        listing(&out),
        "the refusal changed the shipped folder"
    );
}

/// Item 2, Sweep: `sapnet open SWEEP` reads a sweep's cells — failed (its error's last
/// line), done, not run — and per axis value the comparison of its done cells, equal to
/// what `sweep merge` then writes in `merged/comparison.csv`; the view at both sizes; the
/// folder unchanged by the reading.
#[test]
fn the_sweep_view_shows_the_cells_and_the_merges_comparisons() {
    use sapnet::tui::workbench::screens::sweep::SweepScreen;
    use sapnet::tui::workbench::sweep_folder::{comparisons, CellStatus, SweepState};
    use sapnet::tui::workbench::views::sweep::SweepView;
    let tmp = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(configs("tiny_transfer.ron")).unwrap();
    std::fs::write(tmp.path().join("base.ron"), base).unwrap();
    let grid = tmp.path().join("grid.ron");
    std::fs::write(
        &grid,
        "(base: \"base.ron\", seeds: Some(3), \
         axes: [(path: \"sapnet.temperature\", values: [1.0, 4.0])])",
    )
    .unwrap();
    let (dir, library) = (tmp.path().join("sweep"), tmp.path().join("lib"));
    let run = |args: &[&std::ffi::OsStr]| {
        let output = sapnet().args(args).output().unwrap();
        output
    };
    let plan = run(&[
        "sweep".as_ref(),
        "plan".as_ref(),
        "--grid".as_ref(),
        grid.as_os_str(),
        "--out".as_ref(),
        dir.as_os_str(),
        "--library".as_ref(),
        library.as_os_str(),
    ]);
    assert!(plan.status.success(), "{}", stderr(&plan));
    // Cell 0 before its library is trained: failed.
    let cell = |id: &str| {
        run(&[
            "sweep".as_ref(),
            "run".as_ref(),
            dir.as_os_str(),
            "--cell".as_ref(),
            id.as_ref(),
        ])
    };
    assert_eq!(cell("0").status.code(), Some(2));
    let sources = run(&[
        "sources".as_ref(),
        "--config".as_ref(),
        tmp.path().join("base.ron").as_os_str(),
        "--library".as_ref(),
        library.as_os_str(),
    ]);
    assert!(sources.status.success(), "{}", stderr(&sources));
    for id in ["1", "2", "3"] {
        let output = cell(id);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    let before = listing(&dir);
    let sweep = SweepState::read(&dir).unwrap();
    let statuses: Vec<&str> = sweep.cells.iter().map(|c| c.status.name()).collect();
    assert_eq!(
        statuses,
        ["failed", "done", "done", "done", "not run", "not run"]
    );
    assert!(
        matches!(&sweep.cells[0].status, CellStatus::Failed(line) if line.contains("sapnet sweep prepare")),
        "{:?}",
        sweep.cells[0].status
    );
    let values = comparisons(&dir, &sweep.done()).unwrap();
    assert_eq!(before, listing(&dir), "reading the sweep changed it");

    // What `sweep merge` writes: the same groups, the same numbers.
    let merge = run(&["sweep".as_ref(), "merge".as_ref(), dir.as_os_str()]);
    assert!(merge.status.success(), "{}", stderr(&merge));
    let mut reader = csv::Reader::from_path(dir.join("merged/comparison.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    let column = |row: &csv::StringRecord, name: &str| -> String {
        row[header.iter().position(|h| h == name).unwrap()].to_string()
    };
    let mut compared = 0;
    for value in &values {
        for method in &value.report.comparison {
            let row = rows
                .iter()
                .find(|r| {
                    column(r, "axis") == value.axis
                        && column(r, "value") == value.value
                        && column(r, "method") == method.method
                })
                .unwrap_or_else(|| panic!("{} = {} {}", value.axis, value.value, method.method));
            assert_eq!(column(row, "cells"), value.cells.to_string());
            for (name, estimate) in [
                ("return_iqm", method.training.map(|a| a.iqm)),
                ("test_iqm", method.test.map(|a| a.iqm)),
            ] {
                let e = estimate.unwrap();
                assert_eq!(column(row, name), format!("{:?}", e.point));
                assert_eq!(column(row, &format!("{name}_lo")), format!("{:?}", e.lo));
                assert_eq!(column(row, &format!("{name}_hi")), format!("{:?}", e.hi));
            }
            compared += 1;
        }
    }
    assert_eq!(compared, rows.len(), "every merged row is a value's method");

    // The view, its paths and the failed cell's error (a temporary path) made steady.
    let mut screen = SweepScreen::new(SweepView::new(sweep, values));
    let bench = &mut screen.view;
    bench.sweep.dir = PathBuf::from("sweep");
    bench.sweep.cells[0].status = CellStatus::Failed(
        "cell 0000: the source library is missing (sapnet sweep prepare)".into(),
    );
    for size in SIZES {
        let (w, h) = size;
        let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
        terminal.draw(|f| screen.draw(f, Theme::plain())).unwrap();
        let drawn = text(&terminal);
        let first = &screen.view.values[0];
        let sapnet_row = &first.report.comparison[0];
        let shown = sapnet::report::comparison::interval(&sapnet_row.training.unwrap().iqm, 1);
        assert!(drawn.contains(&shown), "{shown} in\n{drawn}");
        insta::assert_snapshot!(format!("workbench_sweep_{w}x{h}"), terminal.backend());
    }

    // A cell being run: its process, from its protocol's lock, and its progress; the
    // cells not started are queued while it runs. Stopped (SIGSTOP) once its folder is
    // locked and its summary written, so that it holds still while read.
    let child = sapnet()
        .args(["sweep", "run"])
        .arg(&dir)
        .args(["--cell", "4", "--jobs", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let partial = dir.join("results/.0004.partial");
    let started = Instant::now();
    while !(partial.join("summary.json").exists() && partial.join(".sapnet.lock").exists()) {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "cell 4 never started"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    signal(&child, "STOP");
    let stat = format!("/proc/{}/stat", child.id());
    while !std::fs::read_to_string(&stat).is_ok_and(|s| s.contains(") T ")) {
        std::thread::sleep(Duration::from_millis(5));
    }
    let live = SweepState::read(&dir);
    let pid = child.id();
    end(child);
    let live = live.unwrap();
    let statuses: Vec<&str> = live.cells.iter().map(|c| c.status.name()).collect();
    if live.cells[4].status == CellStatus::Done {
        // The cell finished before it was stopped: nothing running to see.
        eprintln!("cell 4 finished before it could be stopped");
        return;
    }
    assert_eq!(statuses[4..], ["running", "queued"], "{statuses:?}");
    assert!(
        matches!(&live.cells[4].status, CellStatus::Running(holder) if holder.pid == pid),
        "{:?}",
        live.cells[4].status
    );
    // Two methods × two runs.
    assert_eq!(live.cells[4].progress.map(|(_, all)| all), Some(4));
}

/// The Curves view's legend with more methods (24) than it has lines: the picked one is
/// kept in view, the footer says how many lines are hidden above and below, and a click
/// lands on the method drawn where it clicks.
#[test]
fn the_curves_legend_scrolls_to_the_picked_method() {
    let tmp = tempfile::tempdir().unwrap();
    let methods: Vec<String> = (4..28)
        .map(|units| format!("Dqn(hidden: [{units}])"))
        .collect();
    let config = tmp.path().join("twelve.ron");
    std::fs::write(
        &config,
        format!(
            "(env: CartPole(), dqn: (replay_start_size: 20), protocol: (episodes: 12, moving_average: 3, runs: 1, \
             test_episodes: 1, methods: [{}]), seed: 0)",
            methods.join(", ")
        ),
    )
    .unwrap();
    let out = tmp.path().join("out");
    protocol_into(&config, &out);
    let size = (80, 24);
    let mut workbench = workbench(&out, "v");
    let drawn = text(&screen(&workbench, size));
    assert!(drawn.contains("dqn[4]"), "{drawn}");
    assert!(!drawn.contains("dqn[27]"), "{drawn}");
    assert!(drawn.contains("▼"), "{drawn}");
    for _ in 0..23 {
        workbench.on_key(key('j'));
    }
    let terminal = screen(&workbench, size);
    let drawn = text(&terminal);
    assert!(drawn.contains("dqn[27]"), "{drawn}");
    assert!(!drawn.contains("dqn[4] "), "{drawn}");
    assert!(drawn.contains("▲"), "{drawn}");
    // A click on the last line hides the method drawn there, the 24th.
    let (column, row) = drawn_at(&terminal, "dqn[27]");
    let event = crossterm::event::MouseEvent {
        kind: crossterm::event::MouseEventKind::Down(crossterm::event::MouseButton::Left),
        column,
        row,
        modifiers: KeyModifiers::NONE,
    };
    let screen_area = ratatui::layout::Rect::new(0, 0, size.0, size.1);
    assert!(workbench.on_mouse(event, screen_area));
    assert!(
        workbench.workbench.curves.hidden.contains(&23),
        "{:?}",
        workbench.workbench.curves.hidden
    );
}
