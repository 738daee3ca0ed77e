//! Issue 51: `sapnet open` on a folder `sapnet compare` wrote. Its Comparison view is the
//! folder's `comparison.csv` (and the table compare printed), its pairs `improvement.csv`,
//! its sort keys a protocol folder's; its Curves view draws each method's runs' returns,
//! the points of its `sample_efficiency.csv`, on the step axis where every run has steps
//! and by episode where not. It is made from what compare recorded in the folder
//! (`run_episodes.csv`, `compare.json`), never from the files `runs.csv` names: a bad
//! record is refused naming the file and the place, and a folder of an older compare is
//! told what makes it openable. Drawn with TestBackend, `NO_COLOR`'s theme, at 120×40 and
//! 80×24 (insta).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::report::metric::{CurvePoint, Metric};
use sapnet::results::found::{self, Kind};
use sapnet::tui::event_loop::{Flow, Screen};
use sapnet::tui::theme::Theme;
use sapnet::tui::workbench::compare_folder::CompareFolder;
use sapnet::tui::workbench::screens::compared::CompareScreen;
use sapnet::tui::workbench::screens::folders::FoldersScreen;
use sapnet::tui::workbench::views::folders::FolderList;

use crate::common::cli::{ok, sapnet, stderr};
use crate::compare_cli::{dqn_and_ppo, rows};
use crate::workbench::{as_written, efficiency_rows};

const SIZES: [(u16, u16); 2] = [(120, 40), (80, 24)];

/// `sapnet compare` of SB3's DQN and PPO on CartPole, three seeds each (compare_cli's
/// monitor files), `more` flags after them, into `out`; what it printed.
fn compare_into(out: &Path, more: &[String]) -> String {
    let output = ok(dqn_and_ppo()
        .args(more)
        .args(["--range", "0", "500", "--out"])
        .arg(out)
        .output()
        .unwrap());
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The monitor files compared into `out` by step, every one giving its episodes'
/// lengths; what compare printed.
pub fn by_step(out: &Path) -> String {
    compare_into(out, &["--task".into(), "CartPole-v1".into()])
}

/// DQN's and PPO's monitor files beside `flat`, two CSV exports of episodes and returns
/// without a step: not every run has steps, so compared by episode, into `out`.
fn by_episode(tmp: &Path, out: &Path) {
    let flat: Vec<String> = (0..2)
        .map(|seed| {
            let path = tmp.join(format!("flat-{seed}.csv"));
            let rows: String = (1..=80)
                .map(|e| format!("{e},{}\n", 20 + (e * (seed + 3)) % 17))
                .collect();
            std::fs::write(&path, format!("episode,return\n{rows}")).unwrap();
            path.display().to_string()
        })
        .collect();
    let flat = format!("flat={}", flat.join(","));
    compare_into(
        out,
        &["--method".into(), flat, "--last".into(), "20".into()],
    );
}

/// What `sapnet open DIR` said, refusing it with exit 2 before it asks for a terminal.
fn refused(dir: &Path) -> String {
    let output = sapnet().arg("open").arg(dir).output().unwrap();
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    stderr(&output)
}

/// The screen on `dir` as `sapnet open` opens it, its report made.
fn opened(dir: &Path) -> CompareScreen {
    let mut screen = CompareScreen::start(dir).unwrap();
    screen.settle();
    screen
}

/// A folder of [`by_step`] in a new temporary folder, `compared/`, and its screen.
fn opened_by_step() -> (tempfile::TempDir, PathBuf, CompareScreen) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("compared");
    by_step(&out);
    let screen = opened(&out);
    (tmp, out, screen)
}

fn compare(screen: &CompareScreen) -> &CompareFolder {
    screen.workbench.compare.as_ref().unwrap()
}

fn key(code: KeyCode) -> KeyEvent {
    KeyEvent::new(code, KeyModifiers::NONE)
}

fn press(screen: &mut CompareScreen, keys: &str) {
    for c in keys.chars() {
        screen.on_key(key(match c {
            '\n' => KeyCode::Enter,
            c => KeyCode::Char(c),
        }));
    }
}

/// The screen drawn, once the Curves view's curves are made (in the background).
fn drawn(screen: &CompareScreen, (w, h): (u16, u16)) -> Terminal<TestBackend> {
    let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
    terminal.draw(|f| screen.draw(f, Theme::plain())).unwrap();
    screen.workbench.curves.settle();
    terminal.draw(|f| screen.draw(f, Theme::plain())).unwrap();
    terminal
}

fn text(screen: &CompareScreen, size: (u16, u16)) -> String {
    format!("{}", drawn(screen, size).backend())
}

/// Every file under `dir` with its bytes.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .map(|p| (p.clone(), std::fs::read(&p).unwrap()))
        .collect()
}

/// Each method's IQM, mean, median and optimality gap of both scores, with intervals,
/// as comparison.csv holds them to the table's digits; the pairs as improvement.csv; the
/// report made again is the one compare printed; and nothing in the folder changes.
#[test]
fn the_comparison_view_shows_the_numbers_of_comparison_csv() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("compared");
    let printed = by_step(&out);
    let before = files(&out);
    let mut screen = opened(&out);
    let report = compare(&screen).report.clone().unwrap();
    assert_eq!(report.table().trim_end(), printed.trim_end());

    let comparison = rows(&out.join("comparison.csv"));
    assert_eq!(comparison.len(), 2);
    for (aggregate, digits) in [
        ("iqm", 1),
        ("mean", 1),
        ("median", 1),
        ("optimality_gap", 3),
    ] {
        let drawn = text(&screen, (120, 40));
        assert!(drawn.contains("over all 6 runs"), "{drawn}");
        for row in &comparison {
            let method = &row["method"];
            let line = drawn
                .lines()
                .find(|l| l.contains(&format!("│{method} ")))
                .unwrap_or_else(|| panic!("{method} in\n{drawn}"));
            assert!(line.contains(" 3/3 "), "{line}");
            for score in ["return", "test"] {
                let [point, lo, hi] = ["", "_lo", "_hi"].map(|end| {
                    row[&format!("{score}_{aggregate}{end}")]
                        .parse::<f64>()
                        .unwrap()
                });
                let expected = format!("{point:.digits$} [{lo:.digits$}, {hi:.digits$}]");
                assert!(
                    line.contains(&expected),
                    "{method} {score} {aggregate}: {expected} in {line}"
                );
            }
        }
        press(&mut screen, "a");
    }

    // The picked method's pairs, by improvement.csv, the training return's, then (s)
    // the final score's.
    let improvement = rows(&out.join("improvement.csv"));
    for (score, keys) in [("return", ""), ("test", "s")] {
        press(&mut screen, keys);
        let drawn = text(&screen, (120, 40));
        let pair = improvement
            .iter()
            .find(|r| r["score"] == score && r["method"] == "dqn")
            .unwrap();
        let p = |c: &str| pair[c].parse::<f64>().unwrap();
        let expected = format!(
            "vs ppo  P = {:.2} [{:.2}, {:.2}]  ppo over dqn, {}",
            p("p"),
            p("lo"),
            p("hi"),
            pair["verdict"]
        );
        assert!(drawn.contains(&expected), "{expected} in\n{drawn}");
    }

    // The sort keys a protocol's folder has: by the training return, the best first.
    press(&mut screen, "oo");
    let drawn = text(&screen, (120, 40));
    assert!(drawn.contains("runs ▼"), "{drawn}");
    press(&mut screen, "o");
    let drawn = text(&screen, (120, 40));
    assert!(drawn.contains("return IQM [95% CI] ▼"), "{drawn}");
    let ppo = drawn.find("│ppo ").unwrap();
    assert!(ppo < drawn.find("│dqn ").unwrap(), "{drawn}");
    assert_eq!(files(&out), before, "open wrote into the folder");
}

/// The Curves view by step (every monitor file gives its lengths): each method's curve is
/// `sample_efficiency.csv`'s, point for point, up to the steps every run reached; Enter
/// lists the picked method's runs; `y` shows the episodes' lengths, which the files hold.
#[test]
fn the_curves_view_draws_each_methods_runs_as_sample_efficiency_csv() {
    let (_tmp, out, mut screen) = opened_by_step();
    press(&mut screen, "v");
    let budget = match compare(&screen).scoring.alignment {
        sapnet::outside_runs::compare_folder::Alignment::Steps(n) => n,
        other => panic!("{other:?}: monitor files are compared by step"),
    };
    for (index, label) in ["dqn", "ppo"].iter().enumerate() {
        let points = screen.workbench.curves.curve(compare(&screen), index);
        for (statistic, of) in [
            ("iqm", (|p: &CurvePoint| p.iqm) as fn(&CurvePoint) -> _),
            ("mean", |p| p.mean),
        ] {
            let rows = efficiency_rows(&out, label, statistic);
            assert_eq!(rows.last().unwrap().0, budget.to_string());
            assert_eq!(as_written(&points, of), rows, "{label} {statistic}");
        }
    }
    let drawn = text(&screen, (120, 40));
    assert!(drawn.contains(&format!("step {budget}")), "{drawn}");
    assert!(
        drawn.contains("Curves return MA10 IQM over runs"),
        "{drawn}"
    );
    assert!(drawn.contains("all 6 runs"), "{drawn}");

    press(&mut screen, "\n");
    let drawn = text(&screen, (120, 40));
    assert!(drawn.contains("run  status   episodes  MA10"), "{drawn}");
    assert_eq!(drawn.matches(" done ").count(), 3, "{drawn}");
    press(&mut screen, "\ny");
    assert_eq!(screen.workbench.curves.metric, Metric::Length);
    assert!(text(&screen, (120, 40)).contains("Curves length"));
}

/// Runs of a file without steps: the methods compared by episode, the curves drawn by
/// episode, `x` saying why no other axis, `y` offering the returns alone.
#[test]
fn runs_without_steps_are_compared_and_drawn_by_episode() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("compared");
    by_episode(tmp.path(), &out);
    let mut screen = opened(&out);
    let drawn = text(&screen, (120, 40));
    assert!(drawn.contains("compared by episode"), "{drawn}");
    assert!(
        drawn
            .lines()
            .any(|l| l.contains("│flat ") && l.contains(" 2/2 ")),
        "{drawn}"
    );
    press(&mut screen, "v");
    let drawn = text(&screen, (120, 40));
    assert!(drawn.contains("episode "), "{drawn}");
    press(&mut screen, "x");
    let drawn = text(&screen, (120, 40));
    assert!(
        drawn.contains("the episode is the only x axis here"),
        "{drawn}"
    );
    press(&mut screen, "y");
    assert_eq!(screen.workbench.curves.metric, Metric::Return);
}

/// The files of `from` copied into a new folder `to`.
fn copy(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for (path, bytes) in files(from) {
        std::fs::write(to.join(path.file_name().unwrap()), bytes).unwrap();
    }
}

/// What a case does to a copy of a good folder.
type Doctor<'a> = Box<dyn Fn(&Path) + 'a>;

/// A received compare folder's record read as a folder from elsewhere: a planted link, a
/// return that is not a number, a step going back, a file longer than compare.json says,
/// a line longer than any row — each refused, before a terminal is taken, naming the
/// file and the place.
#[test]
fn a_bad_record_is_refused_naming_the_file_and_the_place() {
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("good");
    by_step(&good);
    let episodes = std::fs::read_to_string(good.join("run_episodes.csv")).unwrap();
    // The file's line 3: dqn run 0's second episode.
    let third = episodes.lines().nth(2).unwrap().to_string();
    let cases: Vec<(&str, Doctor, Vec<&str>)> = vec![
        (
            "link",
            Box::new(|dir: &Path| {
                let elsewhere = tmp.path().join("elsewhere.csv");
                std::fs::write(&elsewhere, &episodes).unwrap();
                std::fs::remove_file(dir.join("run_episodes.csv")).unwrap();
                std::os::unix::fs::symlink(&elsewhere, dir.join("run_episodes.csv")).unwrap();
            }),
            vec!["run_episodes.csv", "symbolic link"],
        ),
        (
            "json-link",
            Box::new(|dir: &Path| {
                let elsewhere = tmp.path().join("elsewhere.json");
                std::fs::rename(dir.join("compare.json"), &elsewhere).unwrap();
                std::os::unix::fs::symlink(&elsewhere, dir.join("compare.json")).unwrap();
            }),
            vec!["compare.json", "symbolic link"],
        ),
        (
            "nan",
            Box::new(|dir: &Path| {
                let fields: Vec<&str> = third.split(',').collect();
                let doctored = format!(
                    "{},{},{},NaN,{}",
                    fields[0], fields[1], fields[2], fields[4]
                );
                let text = episodes.replacen(&third, &doctored, 1);
                std::fs::write(dir.join("run_episodes.csv"), text).unwrap();
            }),
            vec![
                "run_episodes.csv",
                "line 3, column 4 (return)",
                "not finite",
            ],
        ),
        (
            "back",
            Box::new(|dir: &Path| {
                let fields: Vec<&str> = third.split(',').collect();
                let doctored = format!("{},{},{},{},1", fields[0], fields[1], fields[2], fields[3]);
                let text = episodes.replacen(&third, &doctored, 1);
                std::fs::write(dir.join("run_episodes.csv"), text).unwrap();
            }),
            vec!["run_episodes.csv", "line 3, column 5 (step)"],
        ),
        (
            "longer",
            Box::new(|dir: &Path| {
                let text = format!("{episodes}ppo,2,9999,1.0,99999\n");
                std::fs::write(dir.join("run_episodes.csv"), text).unwrap();
            }),
            vec![
                "run_episodes.csv",
                "more than the",
                "episodes compare.json lists",
            ],
        ),
        (
            "endless-line",
            Box::new(|dir: &Path| {
                let doctored = format!("{third}{}", "9".repeat(5 << 20));
                let text = episodes.replacen(&third, &doctored, 1);
                std::fs::write(dir.join("run_episodes.csv"), text).unwrap();
            }),
            vec!["run_episodes.csv", "line 3 is longer than the"],
        ),
    ];
    for (name, doctor, said) in &cases {
        let dir = tmp.path().join(name);
        copy(&good, &dir);
        doctor(&dir);
        let error = format!("{:#}", CompareScreen::start(&dir).err().unwrap());
        for words in said {
            assert!(error.contains(words), "{name}: {words:?} in {error}");
        }
    }
    // The binary says the same, with exit 2, before it asks for a terminal.
    let said = refused(&tmp.path().join("nan"));
    assert!(said.contains("not finite"), "{said}");
}

/// A folder of a compare from before it recorded its runs: `open` says to run compare
/// again, from the command line and from a parent's list; a recorded one opens from the
/// list, and Esc comes back to it.
#[test]
fn an_older_compare_folder_says_what_makes_it_openable() {
    let tmp = tempfile::tempdir().unwrap();
    let parent = tmp.path().join("logs");
    let older = parent.join("a-older");
    by_step(&older);
    for file in ["compare.json", "run_episodes.csv"] {
        std::fs::remove_file(older.join(file)).unwrap();
    }
    let recorded = parent.join("b-recorded");
    by_step(&recorded);
    let said = refused(&older);
    assert!(
        said.contains("run `sapnet compare` again") && said.contains("comparison.csv"),
        "{said}"
    );

    let search = found::find(&parent);
    let kinds: Vec<Kind> = search.found.iter().map(|f| f.kind).collect();
    assert_eq!(kinds, [Kind::Compare, Kind::Compare]);
    let settings = crate::open_parent::settings();
    let list = FolderList {
        parent: parent.clone(),
        search,
    };
    let mut screen = FoldersScreen::new(list, &settings);
    screen.on_key(key(KeyCode::Enter));
    assert!(!screen.is_inside());
    let notice = screen.notice.clone().unwrap_or_default();
    assert!(notice.contains("run `sapnet compare` again"), "{notice}");
    screen.on_key(key(KeyCode::Down));
    screen.on_key(key(KeyCode::Enter));
    assert!(screen.is_inside(), "{:?}", screen.notice);
    // The report, made on its thread, is drawn once it comes.
    let drawn = loop {
        let (changed, _) = screen.drain();
        let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
        terminal.draw(|f| screen.draw(f, Theme::plain())).unwrap();
        let drawn = format!("{}", terminal.backend());
        if changed || drawn.contains("over all 6 runs") {
            break drawn;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    assert!(drawn.contains("b-recorded"), "{drawn}");
    assert!(drawn.contains("c comparison  v curves"), "{drawn}");
    assert_eq!(screen.on_key(key(KeyCode::Esc)), Flow::Continue);
    assert!(!screen.is_inside());
}

/// The Comparison and Curves of a compare folder at both sizes, and their keys: the
/// status bar and `?` offer the two views and none of a protocol's (no Runs, no Run, no
/// `R`).
#[test]
fn the_views_at_both_sizes() {
    let (_tmp, _, mut screen) = opened_by_step();
    // The folder's path is the test's temporary one.
    screen.workbench.compare.as_mut().unwrap().dir = PathBuf::from("compared");
    for (name, keys) in [("comparison", ""), ("curves", "v"), ("keys", "?")] {
        press(&mut screen, keys);
        for size in SIZES {
            let (w, h) = size;
            let terminal = drawn(&screen, size);
            let drawn = format!("{}", terminal.backend());
            // Neither the Runs nor the Run tab, nor a protocol's resuming.
            let bar = drawn.lines().last().unwrap();
            for tab in ["\" r ", " f ", "R "] {
                assert!(!bar.contains(tab), "{tab:?} in {bar}");
            }
            for absent in ["resume", "r c v f", "1–4"] {
                assert!(!drawn.contains(absent), "{absent:?} in\n{drawn}");
            }
            insta::assert_snapshot!(format!("open_compare_{name}_{w}x{h}"), terminal.backend());
        }
    }
}
