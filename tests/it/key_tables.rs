//! Issue 50, item 2: each view's `?`, status bar and key matcher come from one table, so
//! the walk here sends every key of every view's table, and of its screen's, to the screen
//! as a user would (its `on_key`), and checks what the table promises:
//!
//! - each key listed does something: in one of the states given (a cursor mid-list, a run
//!   paused, one method's runs shown), the screen drawn changes, it quits or asks to, or a
//!   run is sent a command;
//! - each key handled is listed: every other key (the printable characters, the keys
//!   with names, Control and a letter) changes nothing drawn and sends nothing;
//! - a view never takes a key of its screen's (the tabs, `?`, quitting), but Esc to go
//!   back from a mode of its own: the same key means the same thing in every view.
//!
//! Drawn at 120×40 without colour; a cursor moved shows as a row's style, which the
//! comparison of the buffers sees.

use std::path::Path;

use crossterm::event::{KeyCode, KeyEvent};
use ratatui::backend::TestBackend;
use ratatui::buffer::Buffer;
use ratatui::Terminal;
use sapnet::report::Report;
use sapnet::results::folder_state::FolderReader;
use sapnet::trainer::{command_channel, CommandReceiver};
use sapnet::tui::dashboard::Dashboard;
use sapnet::tui::event_loop::Flow;
use sapnet::tui::keys::{ch, code, ctrl, Binding, Key};
use sapnet::tui::theme::Theme;
use sapnet::tui::view::View;
use sapnet::tui::workbench::screens::compared::CompareScreen;
use sapnet::tui::workbench::screens::folders::{FoldersScreen, FOLDERS_KEYS};
use sapnet::tui::workbench::screens::opened::Opened;
use sapnet::tui::workbench::screens::session::{overlays, Phase, Request, Session};
use sapnet::tui::workbench::screens::sweep::{SweepScreen, SWEEP_KEYS};
use sapnet::tui::workbench::screens::workbench::{COMPARE_KEYS, OPEN_KEYS, SESSION_KEYS};
use sapnet::tui::workbench::sweep_folder::{CellRow, CellStatus, SweepState};
use sapnet::tui::workbench::views::comparison::ComparisonView;
use sapnet::tui::workbench::views::curves::CurvesView;
use sapnet::tui::workbench::views::folders::{FolderList, FoldersView};
use sapnet::tui::workbench::views::run::{LiveRun, RunView};
use sapnet::tui::workbench::views::runs::RunsView;
use sapnet::tui::workbench::views::sweep::SweepView;

use crate::common::cli::{configs, sapnet, stderr};
use crate::common::tui_script;

/// A screen as the walk drives it.
trait Walked {
    /// Sends `key`; whether the screen quits or asks to (the stop question is drawn too).
    fn press(&mut self, key: KeyEvent) -> bool;
    fn drawn(&self) -> Buffer;
    /// Whether a run was sent a command since the last look.
    fn sent(&mut self) -> bool {
        false
    }
}

fn draw(draw: impl FnOnce(&mut ratatui::Frame)) -> Buffer {
    let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
    terminal.draw(draw).unwrap();
    terminal.backend().buffer().clone()
}

/// Drawn once the Curves view's curves are made (in the background).
fn drawn_with_curves(screen: impl Fn(&mut ratatui::Frame), curves: &CurvesView) -> Buffer {
    draw(&screen);
    curves.settle();
    draw(&screen)
}

impl Walked for Opened {
    fn press(&mut self, key: KeyEvent) -> bool {
        self.on_key(key) == Flow::Quit
    }

    fn drawn(&self) -> Buffer {
        drawn_with_curves(|f| self.draw(f, Theme::plain()), &self.workbench.curves)
    }
}

impl Walked for CompareScreen {
    fn press(&mut self, key: KeyEvent) -> bool {
        self.on_key(key) == Flow::Quit
    }

    fn drawn(&self) -> Buffer {
        drawn_with_curves(|f| self.draw(f, Theme::plain()), &self.workbench.curves)
    }
}

impl Walked for FoldersScreen<'_> {
    fn press(&mut self, key: KeyEvent) -> bool {
        self.on_key(key) == Flow::Quit
    }

    fn drawn(&self) -> Buffer {
        draw(|f| self.draw(f, Theme::plain()))
    }
}

impl Walked for SweepScreen {
    fn press(&mut self, key: KeyEvent) -> bool {
        self.on_key(key) == Flow::Quit
    }

    fn drawn(&self) -> Buffer {
        draw(|f| self.draw(f, Theme::plain()))
    }
}

/// A protocol's session, its runs' ends of their command channels.
struct Live {
    session: Session,
    receivers: Vec<CommandReceiver>,
}

impl Walked for Live {
    fn press(&mut self, key: KeyEvent) -> bool {
        self.session.on_key(key) != Request::None
    }

    fn drawn(&self) -> Buffer {
        draw(|f| overlays::draw(f, &self.session, Theme::plain()))
    }

    fn sent(&mut self) -> bool {
        // Every receiver read: a key may send to both runs (`m` lets one go, streams the
        // other).
        let sent: Vec<bool> = self
            .receivers
            .iter()
            .map(|r| !r.pending().is_empty())
            .collect();
        sent.contains(&true)
    }
}

/// Keys as the walk spells its states: `\n` Enter, `\t` Tab, any other character itself.
fn keys(spelled: &str) -> Vec<KeyEvent> {
    spelled
        .chars()
        .map(|c| match c {
            '\n' => code(KeyCode::Enter),
            '\t' => code(KeyCode::Tab),
            c => ch(c),
        })
        .map(Key::event)
        .collect()
}

/// Every key of `tables`.
fn listed<C>(tables: &[&[Binding<C>]]) -> Vec<Key> {
    tables
        .iter()
        .flat_map(|t| t.iter())
        .flat_map(|b| b.keys.iter().map(|&(k, _)| k))
        .collect()
}

/// The keys a user may press: the printable characters, the keys with names, Control
/// and a letter.
fn every_key() -> Vec<Key> {
    let mut keys: Vec<Key> = (' '..='~').map(ch).collect();
    keys.extend(
        [
            KeyCode::Enter,
            KeyCode::Esc,
            KeyCode::Tab,
            KeyCode::BackTab,
            KeyCode::Backspace,
            KeyCode::Up,
            KeyCode::Down,
            KeyCode::Left,
            KeyCode::Right,
            KeyCode::PageUp,
            KeyCode::PageDown,
            KeyCode::Home,
            KeyCode::End,
            KeyCode::Delete,
            KeyCode::Insert,
            KeyCode::F(1),
        ]
        .map(code),
    );
    keys.extend(('a'..='z').map(ctrl));
    keys
}

/// One view on its screen, the states its keys are tried in.
struct Case<'a, W> {
    name: &'a str,
    make: &'a dyn Fn() -> W,
    /// The view's keys and its screen's.
    listed: Vec<Key>,
    /// States (keys pressed first) in which each listed key must do something in one.
    acting: &'a [&'a str],
    /// States in which no other key may do anything.
    resting: &'a [&'a str],
}

fn walk<W: Walked>(case: &Case<W>) {
    let start = |state: &str| {
        let mut w = (case.make)();
        for key in keys(state) {
            w.press(key);
        }
        w.sent();
        w
    };
    for &key in &case.listed {
        let acts = case.acting.iter().any(|state| {
            let mut w = start(state);
            let before = w.drawn();
            let ends = w.press(key.event());
            ends || w.sent() || w.drawn() != before
        });
        assert!(
            acts,
            "{}: {key:?} is listed and does nothing in {:?}",
            case.name, case.acting
        );
    }
    for state in case.resting {
        let mut w = start(state);
        let before = w.drawn();
        for key in every_key().into_iter().filter(|k| !case.listed.contains(k)) {
            assert!(
                !w.press(key.event()) && !w.sent(),
                "{}: {key:?} is not listed and acts in {state:?}",
                case.name
            );
            assert!(
                w.drawn() == before,
                "{}: {key:?} is not listed and changes the screen in {state:?}",
                case.name
            );
        }
    }
}

/// A view's own keys are never its screen's, but Esc for going back from its own mode.
fn apart<C, S>(name: &str, view: &[Binding<C>], screen: &[Binding<S>]) {
    let screens = listed(&[screen]);
    for (key, _) in view.iter().flat_map(|b| b.keys) {
        assert!(
            key.code == KeyCode::Esc || !screens.contains(key),
            "{name} takes {key:?}, its screen's key"
        );
    }
}

/// The finished protocol of two_baselines.ron (two DQNs, three runs each) in `out`.
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

/// SAP-Net's scripted run (its library on the graph) and a baseline, both training.
fn two_runs(session: &mut Session) -> Vec<CommandReceiver> {
    let mut sapnet = Dashboard::new("CartPole-v1");
    sapnet.follow("sapnet");
    sapnet.on_event(tui_script::sapnet_start());
    for event in tui_script::episodes(20) {
        sapnet.on_event(event);
    }
    let mut baseline = Dashboard::new("CartPole-v1");
    baseline.on_event(tui_script::baseline_start());
    let mut receivers = Vec::new();
    for (key, dashboard) in [("sapnet", sapnet), ("dqn[100]", baseline)] {
        let (commands, receiver) = command_channel();
        receivers.push(receiver);
        session.workbench.run.runs.insert(
            (key.to_string(), 0),
            LiveRun {
                dashboard,
                commands: Some(commands),
            },
        );
    }
    receivers
}

/// The workbench's views on `sapnet open`'s screen and on a protocol's session.
#[test]
fn every_key_listed_acts_and_every_key_acting_is_listed() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    finished_folder(&out);
    let read = || FolderReader::new(&out).read().unwrap();
    let report: Report = read().report();
    let open = |tab: &str| {
        let mut opened = Opened::new(read(), Some(report.clone()));
        for key in keys(tab) {
            opened.on_key(key);
        }
        opened
    };
    let (runs, comparison, curves) = (
        RunsView::default(),
        ComparisonView::default(),
        CurvesView::default(),
    );
    apart("Runs", runs.keys(), OPEN_KEYS);
    apart("Comparison", comparison.keys(), SESSION_KEYS);
    apart("Curves", curves.keys(), SESSION_KEYS);
    let run = RunView::new("CartPole-v1", None);
    apart("Run", run.keys(), SESSION_KEYS);

    walk(&Case {
        name: "open: Runs",
        make: &|| open(""),
        listed: listed(&[runs.keys()])
            .into_iter()
            .chain(listed(&[OPEN_KEYS]))
            .collect(),
        // Mid-list: every move moves; on another tab, `r` shows this one.
        acting: &["", "jj", "c"],
        resting: &["", "jj"],
    });
    walk(&Case {
        name: "open: Comparison",
        make: &|| open("c"),
        listed: listed(&[comparison.keys()])
            .into_iter()
            .chain(listed(&[OPEN_KEYS]))
            .collect(),
        acting: &["", "j", "r"],
        resting: &["", "j"],
    });
    walk(&Case {
        name: "open: Curves",
        make: &|| open("v"),
        listed: listed(&[curves.keys()])
            .into_iter()
            .chain(listed(&[OPEN_KEYS]))
            .collect(),
        // Zoomed in (to move along), one method's runs (to move among them), the second.
        acting: &["", "+", "\n", "\n]", "j", "r"],
        resting: &["", "\n"],
    });

    // A protocol training, SAP-Net followed in the Run view, the other run training too.
    let session = || {
        let followed = Some(("sapnet".to_string(), 0));
        let mut session = Session::new(&out, "CartPole-v1", followed, Phase::Running);
        session.refreshed(read(), Some(Some(report.clone())));
        let receivers = two_runs(&mut session);
        Live { session, receivers }
    };
    walk(&Case {
        name: "session: Run",
        make: &session,
        listed: listed(&[run.keys()])
            .into_iter()
            .chain(listed(&[SESSION_KEYS]))
            .collect(),
        // Paused (to step), slowed (to go faster), the graph focused (its arrows), the Runs
        // view shown (to come back).
        acting: &["", " ", "-", "\t", "r"],
        resting: &["", " "],
    });
    walk(&Case {
        name: "session: Runs",
        make: &|| {
            let mut live = session();
            live.session.on_key(ch('r').event());
            live
        },
        listed: listed(&[runs.keys()])
            .into_iter()
            .chain(listed(&[SESSION_KEYS]))
            .collect(),
        acting: &["", "jj", "c"],
        resting: &[""],
    });
}

/// A view walked: its name, the keys that show it, its own keys, its acting and resting
/// states.
type ViewCase<'a> = (&'a str, &'a str, Vec<Key>, &'a [&'a str], &'a [&'a str]);

/// A compare folder's Comparison and Curves on `sapnet open`'s screen: its keys are the
/// two views' and the screen's, none of a protocol's (Runs, Run, `R`).
#[test]
fn every_compare_key_listed_acts_and_every_key_acting_is_listed() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("compared");
    crate::open_compare::by_step(&out);
    let open = |tab: &str| {
        let mut screen = CompareScreen::start(&out).unwrap();
        screen.settle();
        for key in keys(tab) {
            screen.on_key(key);
        }
        screen
    };
    let (comparison, curves) = (ComparisonView::default(), CurvesView::default());
    apart("Comparison", comparison.keys(), COMPARE_KEYS);
    apart("Curves", curves.keys(), COMPARE_KEYS);
    // Each view's keys and states: the Curves' as on a protocol's folder.
    let views: [ViewCase; 2] = [
        (
            "compare: Comparison",
            "",
            listed(&[comparison.keys()]),
            &["", "j", "v"],
            &["", "j"],
        ),
        (
            "compare: Curves",
            "v",
            listed(&[curves.keys()]),
            &["", "+", "\n", "\n]", "j", "c"],
            &["", "\n"],
        ),
    ];
    for (name, tab, own, acting, resting) in views {
        walk(&Case {
            name,
            make: &|| open(tab),
            listed: own.into_iter().chain(listed(&[COMPARE_KEYS])).collect(),
            acting,
            resting,
        });
    }
}

/// The Sweep view, on a sweep of three cells, none done: the arrows move among the cells.
#[test]
fn every_sweep_key_listed_acts_and_every_key_acting_is_listed() {
    let sweep = || {
        let cells = (0..3)
            .map(|id| CellRow {
                id,
                axes: format!("seed={id}"),
                status: CellStatus::NotRun,
                progress: None,
            })
            .collect();
        let state = SweepState {
            dir: "sweep".into(),
            axes: vec!["seed".into()],
            cells,
        };
        SweepScreen::new(SweepView::new(state, Vec::new()))
    };
    let view = sweep().view;
    apart("Sweep", view.keys(), SWEEP_KEYS);
    walk(&Case {
        name: "Sweep",
        make: &sweep,
        listed: listed(&[view.keys()])
            .into_iter()
            .chain(listed(&[SWEEP_KEYS]))
            .collect(),
        acting: &["", "\t", "\tj"],
        resting: &["", "\tj"],
    });
}

/// The Folders view of `sapnet open PARENT`, on a parent of a finished protocol, a stopped
/// one and a compare folder: mid-list, filtered, and with a folder opened (Esc comes back).
#[test]
fn every_folders_key_listed_acts_and_every_key_acting_is_listed() {
    let tmp = tempfile::tempdir().unwrap();
    let parent = crate::open_parent::parent(tmp.path());
    let settings = crate::open_parent::settings();
    let screen = || {
        let list = FolderList {
            parent: parent.clone(),
            search: sapnet::results::found::find(&parent),
        };
        FoldersScreen::new(list, &settings)
    };
    let view = FoldersView::default();
    apart("Folders", view.keys(), FOLDERS_KEYS);
    walk(&Case {
        name: "Folders",
        make: &screen,
        listed: listed(&[view.keys()])
            .into_iter()
            .chain(listed(&[FOLDERS_KEYS]))
            .collect(),
        // Mid-list (to move either way), filtered (Esc clears it).
        acting: &["", "j", "/again\n"],
        resting: &["", "j"],
    });
}
