//! Issue 51, item 2: `sapnet open PARENT` on a folder of folders lists every folder sapnet
//! wrote under it (TensorBoard's `--logdir`) with its task, methods, runs and state —
//! never through a link — filtered by what is typed after `/`; Enter opens one in its
//! views and Esc comes back to the list. Drawn at 120×40 and 80×24 (TestBackend, insta,
//! `NO_COLOR`'s theme).

use std::path::{Path, PathBuf};

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::experiment::RunOptions;
use sapnet::results::found::{self, Kind};
use sapnet::tui::event_loop::Flow;
use sapnet::tui::theme::Theme;
use sapnet::tui::workbench::screens::folders::FoldersScreen;
use sapnet::tui::workbench::screens::session::live::Settings;
use sapnet::tui::workbench::views::folders::FolderList;

use crate::common::cli::{configs, sapnet, stderr};

const SIZES: [(u16, u16); 2] = [(120, 40), (80, 24)];

/// A parent of three folders sapnet wrote, at different depths — a finished protocol
/// (two DQNs, three runs each), a stopped copy of it, a compare folder as an older compare
/// wrote it (its report only, no record of its runs) — beside a link to
/// the first (not listed) and a folder sapnet did not write.
pub fn parent(tmp: &Path) -> PathBuf {
    let parent = tmp.join("logs");
    let done = parent.join("cartpole/two_baselines");
    let output = sapnet()
        .args(["--headless", "--jobs", "2", "--config"])
        .arg(configs("two_baselines.ron"))
        .arg("--out")
        .arg(&done)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", stderr(&output));
    let stopped = parent.join("cartpole/stopped/again");
    std::fs::create_dir_all(&stopped).unwrap();
    let summary = std::fs::read_to_string(done.join("summary.json"))
        .unwrap()
        .replace("\"status\": \"complete\"", "\"status\": \"stopped\"");
    assert!(summary.contains("\"stopped\""), "{summary}");
    std::fs::write(stopped.join("summary.json"), summary).unwrap();
    let compared = parent.join("sb3-vs-sapnet");
    std::fs::create_dir_all(&compared).unwrap();
    std::fs::write(compared.join("comparison.csv"), "method\nppo\ndqn\n").unwrap();
    std::fs::write(
        compared.join("runs.csv"),
        "method,run,path\nppo,0,a\nppo,1,b\ndqn,0,c\n",
    )
    .unwrap();
    std::os::unix::fs::symlink(&done, parent.join("link-to-done")).unwrap();
    std::fs::create_dir_all(parent.join("notes/empty")).unwrap();
    parent
}

fn settings_load(_: &Path) -> anyhow::Result<sapnet::config::Config> {
    anyhow::bail!("no config is launched here")
}

pub fn settings() -> Settings<'static> {
    Settings {
        options: RunOptions {
            jobs: 1,
            library: sapnet::sources::LibraryRoot {
                path: PathBuf::from("saved_policies"),
                train_if_missing: false,
            },
            trace: false,
            copy_chosen: false,
            tensorboard: false,
        },
        python: Default::default(),
        load: &settings_load,
        reference: Vec::new(),
    }
}

fn key(code: KeyCode) -> KeyEvent {
    KeyEvent::new(code, KeyModifiers::NONE)
}

fn typed(screen: &mut FoldersScreen, text: &str) {
    for c in text.chars() {
        screen.on_key(key(KeyCode::Char(c)));
    }
}

fn drawn(screen: &FoldersScreen, (w, h): (u16, u16)) -> Terminal<TestBackend> {
    let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
    terminal.draw(|f| screen.draw(f, Theme::plain())).unwrap();
    terminal
}

#[test]
fn a_parent_lists_its_folders_filters_them_and_opens_one() {
    let tmp = tempfile::tempdir().unwrap();
    let parent = parent(tmp.path());
    let search = found::find(&parent);
    let listed: Vec<(String, Kind, usize, &str)> = search
        .found
        .iter()
        .map(|f| {
            let name = f.dir.strip_prefix(&parent).unwrap().display().to_string();
            (name, f.kind, f.runs, f.state.as_str())
        })
        .collect();
    assert_eq!(
        listed,
        [
            ("sb3-vs-sapnet".to_string(), Kind::Compare, 3, "compared"),
            (
                "cartpole/two_baselines".to_string(),
                Kind::Protocol,
                6,
                "complete"
            ),
            (
                "cartpole/stopped/again".to_string(),
                Kind::Protocol,
                6,
                "stopped"
            ),
        ]
    );
    assert_eq!(search.found[1].task, "CartPole-v1");
    assert_eq!(search.found[1].methods, ["dqn[16]", "dqn[8]"]);

    let settings = settings();
    // The parent's path is the test's own: the list names it `logs`.
    let list = |search: found::Search| FolderList {
        parent: PathBuf::from("logs"),
        search: found::Search {
            found: search
                .found
                .into_iter()
                .map(|mut f| {
                    f.dir = Path::new("logs").join(f.dir.strip_prefix(&parent).unwrap());
                    f
                })
                .collect(),
            cut: None,
        },
    };
    let mut screen = FoldersScreen::new(list(search), &settings);
    for size in SIZES {
        let (w, h) = size;
        let terminal = drawn(&screen, size);
        let text = format!("{}", terminal.backend());
        assert!(text.contains("Folders · 3 found"), "{text}");
        assert!(!text.contains("link-to-done"), "{text}");
        insta::assert_snapshot!(format!("open_parent_list_{w}x{h}"), terminal.backend());
    }

    // `/` and words: the folders whose path, task, methods or state hold every one.
    screen.on_key(key(KeyCode::Char('/')));
    typed(&mut screen, "cartpole stop");
    assert_eq!(screen.view.shown(&screen.list), [2]);
    screen.on_key(key(KeyCode::Enter));
    for size in SIZES {
        let (w, h) = size;
        let terminal = drawn(&screen, size);
        let text = format!("{}", terminal.backend());
        assert!(text.contains("1 of 3 kept by /cartpole stop"), "{text}");
        insta::assert_snapshot!(format!("open_parent_filtered_{w}x{h}"), terminal.backend());
    }
    // Esc clears the filter; a second Esc would quit.
    screen.on_key(key(KeyCode::Esc));
    assert_eq!(screen.view.shown(&screen.list).len(), 3);

    // The older compare folder says what makes it openable, and stays on the list.
    screen.on_key(key(KeyCode::Enter));
    assert!(!screen.is_inside());
    assert!(
        screen
            .notice
            .as_deref()
            .is_some_and(|n| n.contains("comparison.csv")),
        "{:?}",
        screen.notice
    );

    // The finished protocol in the workbench's views (its real path, this time); Esc
    // comes back, q quits.
    let real = FolderList {
        parent: parent.clone(),
        search: found::find(&parent),
    };
    let mut screen = FoldersScreen::new(real, &settings);
    screen.on_key(key(KeyCode::Down));
    screen.on_key(key(KeyCode::Enter));
    assert!(screen.is_inside(), "{:?}", screen.notice);
    let text = format!("{}", drawn(&screen, (120, 40)).backend());
    assert!(text.contains("Runs · 6 runs: done 6"), "{text}");
    assert_eq!(screen.on_key(key(KeyCode::Esc)), Flow::Continue);
    assert!(!screen.is_inside());
    assert_eq!(screen.on_key(key(KeyCode::Char('q'))), Flow::Quit);
}

/// Refused before a terminal is taken, saying what `open` reads: a folder under which
/// sapnet wrote nothing, and a compare folder of an older compare.
#[test]
fn open_says_what_it_cannot_show() {
    let tmp = tempfile::tempdir().unwrap();
    let parent = parent(tmp.path());
    let output = sapnet()
        .arg("open")
        .arg(parent.join("notes"))
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("no folder sapnet wrote"),
        "{}",
        stderr(&output)
    );
    let output = sapnet()
        .arg("open")
        .arg(parent.join("sb3-vs-sapnet"))
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("`sapnet compare` folder"),
        "{}",
        stderr(&output)
    );
    // The parent itself passes the search, then needs a terminal.
    let output = sapnet().arg("open").arg(&parent).output().unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("terminal"), "{}", stderr(&output));
}
