//! A run that ended before the screen opened, shown on a dashboard made from its files
//! (`results::recorded_run`, Enter in the Runs view): what the dashboard of the same run,
//! followed live while it trained, showed at its end.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::mpsc;

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::config::Config;
use sapnet::experiment::{self, OpenedOutput, OutputOptions, RunOptions, Tap, Watched};
use sapnet::results::folder_state::FolderReader;
use sapnet::trainer::{Event, MethodId};
use sapnet::tui::dashboard::Dashboard;
use sapnet::tui::event_loop::Flow;
use sapnet::tui::theme::Theme;
use sapnet::tui::workbench::recorded;
use sapnet::tui::workbench::screens::opened::Opened;
use sapnet::tui::workbench::screens::workbench::Tab;

/// The embedded CartPole config on the shipped library, cut to 60 episodes of one run of
/// SAP-Net, UCB1, GPI and a DQN: a protocol of seconds with a library, past SAP-Net's
/// warm-up (10 sources × 50 steps), so that its judgments are made.
fn protocol() -> Config {
    let embedded = sapnet::assets::CARTPOLE;
    let start = embedded.find("methods: [").unwrap();
    let end = start + embedded[start..].find("],").unwrap() + 2;
    let text = format!(
        "{}methods: [SapNet, Ucb1, Gpi(), Dqn(hidden: [8])],{}",
        &embedded[..start],
        &embedded[end..]
    );
    let mut config = Config::from_ron(&text, "embedded, cut").unwrap();
    config.protocol.budget = sapnet::config::Budget::Episodes(60);
    config.protocol.runs = 1;
    config.protocol.test_episodes = 1;
    config
}

/// Trains `config` into `out` as the workbench does (headless's code with a tap), each
/// run's events folded into a dashboard of its own as the session folds them.
fn trained_live(config: &Config, out: &Path) -> BTreeMap<(String, u32), Dashboard> {
    let output = OutputOptions {
        dir: out.to_path_buf(),
        force: false,
    };
    let options = RunOptions {
        jobs: 2,
        library: sapnet::sources::LibraryRoot {
            path: Path::new(env!("CARGO_MANIFEST_DIR")).join("saved_policies"),
            train_if_missing: false,
        },
        trace: false,
        copy_chosen: false,
        tensorboard: false,
    };
    let (to, watched) = mpsc::channel();
    let (_stop, stop) = mpsc::channel();
    let tap = Tap { to, live: None };
    experiment::run_opened(
        config,
        &output,
        OpenedOutput::open(&output).unwrap(),
        &options,
        &stop,
        Some(&tap),
    )
    .unwrap();
    drop(tap);
    let mut boards: BTreeMap<(String, u32), Dashboard> = BTreeMap::new();
    for watched in watched {
        let Watched::Event(event) = watched else {
            continue;
        };
        let (method, run) = match &event {
            Event::RunStarted { method, run, .. } => (method.clone(), *run),
            Event::Activations(s) => (s.method.clone(), s.run),
            Event::EpisodeEnded(r) => (r.method.clone(), r.run),
            Event::RunEnded(r) => (r.method.clone(), r.run),
            _ => continue,
        };
        boards
            .entry((method.label().to_string(), run))
            .or_insert_with(|| {
                let mut board = Dashboard::new(config.env.gym_id());
                board.follow(method.label());
                board
            })
            .on_event(event);
    }
    boards
}

#[test]
fn a_finished_runs_dashboard_from_its_files_is_the_one_followed_live_at_its_end() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let config = protocol();
    let live = trained_live(&config, &out);
    assert_eq!(live.len(), 4);
    let folder = FolderReader::new(&out).read().unwrap();
    for ((label, run), shown) in &live {
        let method: MethodId = MethodId::all(&config.protocol.methods)
            .into_iter()
            .find(|m| m.label() == label)
            .unwrap();
        let read = recorded::dashboard(&folder, &method, *run, &config.env.gym_id(), &[])
            .unwrap_or_else(|e| panic!("{label}: {e:#}"));
        let files = read.from_files.expect("made from files");
        assert!(files.learner, "{label}");
        assert_eq!(files.activations, method.kind.reuses, "{label}");
        assert_eq!(read.library.is_some(), method.kind.reuses, "{label}");
        assert_eq!(read.library, shown.library, "{label}: the library view");
        assert_eq!(read.step, shown.step, "{label}: the steps");
        assert_eq!(read.runs.len(), 1, "{label}");
        let (read_run, shown_run) = (&read.runs[0], &shown.runs[0]);
        assert_eq!(read_run.curve.returns, shown_run.curve.returns, "{label}");
        assert_eq!(read_run.episode, shown_run.episode, "{label}");
        assert_eq!(read_run.epsilon, shown_run.epsilon, "{label}");
        assert_eq!(read_run.statistic_loss, shown_run.statistic_loss, "{label}");
        assert_eq!(read_run.ended, shown_run.ended, "{label}: the record");
    }
    // A reusing method's view holds what the run did: its steps acted by the sources.
    let sapnet = live[&("sapnet".to_string(), 0)].library.as_ref().unwrap();
    assert!(sapnet.selections.iter().sum::<u64>() > 0);
    assert!(sapnet.positive.iter().sum::<u64>() > 0);
    assert_eq!(sapnet.history.len(), 40);
}

fn key(code: KeyCode) -> KeyEvent {
    KeyEvent::new(code, KeyModifiers::NONE)
}

fn drawn(opened: &Opened) -> String {
    let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
    terminal.draw(|f| opened.draw(f, Theme::plain())).unwrap();
    let buffer = terminal.backend().buffer();
    (0..buffer.area.height)
        .map(|y| {
            (0..buffer.area.width)
                .map(|x| buffer[(x, y)].symbol())
                .collect::<String>()
                + "\n"
        })
        .collect()
}

/// `sapnet open`: Enter on a finished run shows its dashboard, `r` comes back; a folder
/// shipped without its records and with its episodes cut (as `docs/`'s) says what its
/// files lack.
#[test]
fn enter_in_the_runs_view_shows_a_finished_runs_dashboard() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let config = protocol();
    trained_live(&config, &out);
    let open = |dir: &Path| {
        let folder = FolderReader::new(dir).read().unwrap();
        Opened::new(folder, None)
    };
    let mut opened = open(&out);
    assert_eq!(opened.on_key(key(KeyCode::Enter)), Flow::Continue);
    let screen = drawn(&opened);
    assert!(screen.contains("▶ sapnet run 0"), "{screen}");
    assert!(
        screen.contains("\n from its files, no steps kept  "),
        "{screen}"
    );
    assert!(screen.contains("ep 60/60"), "{screen}");
    opened.on_key(key(KeyCode::Char('r')));
    assert_eq!(opened.workbench.tab, Tab::Runs);
    assert!(drawn(&opened).contains("Runs"));
    // A damaged file: said, naming it, and the views stay.
    let activations = out.join("runs/sapnet-run0/activations.csv");
    std::fs::write(
        &activations,
        "run,method,episode,A_source-0\n0,sapnet,1,x\n",
    )
    .unwrap();
    opened.on_key(key(KeyCode::Enter));
    assert_eq!(opened.workbench.tab, Tab::Runs);
    let notice = opened.workbench.notice.clone().unwrap_or_default();
    assert!(notice.contains("activations.csv"), "{notice}");
    assert!(drawn(&opened).contains("activations.csv"));

    // As docs/ ships a folder: no runs/, no activations.csv, episodes.csv cut to six
    // columns and compressed.
    let shipped = tmp.path().join("shipped");
    std::fs::create_dir(&shipped).unwrap();
    for file in ["summary.json", "tests.csv"] {
        std::fs::copy(out.join(file), shipped.join(file)).unwrap();
    }
    let mut reader = csv::Reader::from_path(out.join("episodes.csv")).unwrap();
    let mut cut = csv::Writer::from_writer(Vec::new());
    let columns = ["run", "method", "episode", "reward", "steps", "policy"];
    cut.write_record(columns).unwrap();
    let headers = reader.headers().unwrap().clone();
    for row in reader.records().map(Result::unwrap) {
        cut.write_record(
            columns
                .iter()
                .map(|c| &row[headers.iter().position(|h| h == *c).unwrap()]),
        )
        .unwrap();
    }
    let mut xz = Vec::new();
    lzma_rs::xz_compress(&mut &cut.into_inner().unwrap()[..], &mut xz).unwrap();
    std::fs::write(shipped.join("episodes.csv.xz"), xz).unwrap();
    let mut opened = open(&shipped);
    opened.on_key(key(KeyCode::Enter));
    let screen = drawn(&opened);
    assert!(
        screen.contains("no activations.csv: scores shown as at the start"),
        "{screen}"
    );
    assert!(
        screen.contains("no ε, losses on file: shown as 0"),
        "{screen}"
    );
    // What the record keeps is shown: the steps each source acted.
    let record = &opened.folder().state.runs[0];
    assert_eq!(record.method.label(), "sapnet");
    let dashboard = &opened.workbench.run.followed_run().unwrap().dashboard;
    let library = dashboard.library.as_ref().unwrap();
    let live = trained_steps(&out);
    assert_eq!(library.selections, live);
}

/// The steps each source acted in SAP-Net's run 0, as its record says.
fn trained_steps(out: &Path) -> Vec<u64> {
    let record: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("runs/sapnet-run0/run.json")).unwrap(),
    )
    .unwrap();
    record["source_steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect()
}
