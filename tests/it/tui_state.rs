//! The dashboard's state under scripted events and key presses, without a terminal.

use std::time::Duration;

use crate::common::tui_script;
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::layout::Rect;
use sapnet::teach::lesson::TeachConfig;
use sapnet::teach::Teach;
use sapnet::trainer::Command;
use sapnet::tui::dashboard::{Action, Dashboard, Focus, Mode, CURVE_POINTS, SPEEDS};
use sapnet::tui::{dashboard_view as view, graph_layout, teach_view};

fn key(c: char) -> KeyEvent {
    KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE)
}

fn scripted(episodes: u32) -> Dashboard {
    let mut dashboard = Dashboard::new("CartPole-v1");
    // The baseline may announce itself first: SAP-Net still leads the display.
    dashboard.on_event(tui_script::baseline_start());
    dashboard.on_event(tui_script::sapnet_start());
    for event in tui_script::episodes(episodes) {
        dashboard.on_event(event);
    }
    dashboard
}

#[test]
fn events_fill_the_table_the_curves_and_the_status() {
    let d = scripted(30);
    let methods: Vec<&str> = d.runs.iter().map(|r| r.method.label()).collect();
    assert_eq!(methods, ["sapnet", "dqn[100]"]);
    let view = d.library.as_ref().unwrap();
    assert_eq!(view.acting, Some(6));
    assert_eq!(view.net.chosen(), 6);
    assert!((view.probabilities.iter().sum::<f64>() - 1.0).abs() < 1e-9);
    assert_eq!(d.runs[0].episode, 30);
    assert_eq!(d.runs[0].curve.returns.len(), 30);
    assert_eq!(
        d.runs[1].episode, 90,
        "the baseline runs three episodes to one"
    );
    assert_eq!(d.runs[1].curve.average.len(), 90);
    let expected_steps: u64 = (1..=30u32).map(|e| u64::from(20 + (e * 37 % 180))).sum();
    assert_eq!(d.step, expected_steps);
    assert!(view.glows(6, d.step), "source-6 just spread");
    assert!(!view.glows(6, d.step + 100), "the glow fades");
}

#[test]
fn memory_stays_bounded_over_a_long_run() {
    let d = scripted(20_000);
    for run in &d.runs {
        assert!(
            run.curve.returns.len() <= CURVE_POINTS,
            "{}",
            run.curve.returns.len()
        );
        assert!(run.statistic_loss.len() <= CURVE_POINTS);
    }
    assert_eq!(d.runs[0].episode, 20_000);
    assert_eq!(d.runs[1].episode, 60_000);
    // Thinning keeps the last episodes' moving average exact.
    let last = d.runs[1].curve.last_average().unwrap();
    let expected = (59_991..=60_000).map(|e| f64::from(9 + e % 3)).sum::<f64>() / 10.0;
    assert!((last - expected).abs() < 1e-12);
}

#[test]
fn space_pauses_and_resumes_every_run_and_n_steps_only_while_paused() {
    let mut d = scripted(3);
    assert_eq!(
        d.on_key(key('n')),
        Action::None,
        "n does nothing while running"
    );
    assert_eq!(d.on_key(key(' ')), Action::SendAll(Command::Pause));
    assert_eq!(d.mode, Mode::Paused);
    assert_eq!(d.on_key(key('n')), Action::Send(Command::Step));
    assert_eq!(d.on_key(key(' ')), Action::SendAll(Command::Resume));
    assert_eq!(d.mode, Mode::Running);
}

#[test]
fn plus_and_minus_throttle_the_trainer_within_bounds() {
    let mut d = scripted(1);
    // Already at full speed: nothing to send, and the status line says why (issue 27).
    assert_eq!(d.on_key(key('+')), Action::None);
    assert_eq!(d.notice, Some("already at full speed"));
    for _ in 0..10 {
        d.on_key(key('-'));
    }
    assert_eq!(d.speed, SPEEDS.len() - 1);
    assert_eq!(
        d.on_key(key('+')),
        Action::Send(Command::Throttle(SPEEDS[SPEEDS.len() - 2]))
    );
}

#[test]
fn arrows_and_hjkl_move_the_cursor_around_and_tab_the_focus() {
    let mut d = scripted(1);
    d.on_key(KeyEvent::new(KeyCode::Up, KeyModifiers::NONE));
    assert_eq!(d.cursor, 9, "up from the first wraps to the last");
    d.on_key(key('j'));
    d.on_key(key('l'));
    assert_eq!(d.cursor, 1);
    d.on_key(KeyEvent::new(KeyCode::Tab, KeyModifiers::NONE));
    assert_eq!(d.focus, Focus::Graph);
}

/// In the graph an arrow goes where it points on screen: to the nearest node that way,
/// not to the next index.
#[test]
fn in_the_graph_arrows_move_to_the_nearest_node_that_way() {
    let mut d = scripted(1);
    d.on_key(KeyEvent::new(KeyCode::Tab, KeyModifiers::NONE));
    let view = d.library.as_ref().unwrap();
    let positions = graph_layout::positions(view.policies.len(), Some(&view.categories()));
    let start = d.cursor;
    d.on_key(key('j'));
    let below = d.cursor;
    assert!(positions[below].1 < positions[start].1, "j went down");
    d.on_key(key('k'));
    assert!(
        positions[d.cursor].1 > positions[below].1,
        "k went up again"
    );
    // Far right, l has nowhere to go.
    let rightmost = (0..positions.len())
        .max_by(|&a, &b| positions[a].0.total_cmp(&positions[b].0))
        .unwrap();
    d.cursor = rightmost;
    d.on_key(key('l'));
    assert_eq!(d.cursor, rightmost);
}

#[test]
fn z_enlarges_the_focused_panel_and_a_click_picks_a_row_or_a_node() {
    let mut d = scripted(1);
    let screen = Rect::new(0, 0, 120, 40);
    let layout = view::training_layout(screen, d.zoomed());
    // The third row of the table (below its border and header).
    sapnet::tui::click(&mut d, screen, layout.table.x + 3, layout.table.y + 4);
    assert_eq!((d.cursor, d.focus), (2, Focus::Table));
    // A click on a node of the graph picks it and focuses the graph.
    let view_state = d.library.as_ref().unwrap();
    let positions =
        graph_layout::positions(view_state.policies.len(), Some(&view_state.categories()));
    let target = 7;
    let cell = (0..layout.graph.width)
        .flat_map(|c| (0..layout.graph.height).map(move |r| (c, r)))
        .map(|(c, r)| (layout.graph.x + c, layout.graph.y + r))
        .find(|&(c, r)| {
            graph_layout::canvas_point(layout.graph, c, r)
                .and_then(|p| graph_layout::node_at(&positions, p, 0.25))
                == Some(target)
        })
        .expect("a cell over the node");
    sapnet::tui::click(&mut d, screen, cell.0, cell.1);
    assert_eq!((d.cursor, d.focus), (target, Focus::Graph));

    d.on_key(key('z'));
    assert_eq!(d.zoomed(), Some(Focus::Graph));
    let zoomed = view::training_layout(screen, d.zoomed());
    assert!(zoomed.table.is_empty() && zoomed.rewards.is_empty());
    assert_eq!(zoomed.graph.width, 120, "the graph takes the screen");
    d.on_key(key('z'));
    assert_eq!(d.zoomed(), None);
}

#[test]
fn teach_mode_pauses_steps_a_copy_and_leaves_training_untouched() {
    let mut d = scripted(10);
    let live = d.library.as_ref().unwrap().net.activations().to_vec();
    d.on_key(key('j'));
    assert_eq!(d.on_key(key('t')), Action::SendAll(Command::Pause));
    assert_eq!(d.mode, Mode::Teach);
    let teach = d.teach.as_ref().unwrap();
    assert_eq!(teach.cursor(), 1, "teach starts on the dashboard's pick");
    d.on_key(key('a'));
    d.on_key(key('s'));
    let teach = d.teach.as_ref().unwrap();
    assert_eq!(teach.walk().unwrap().trace.len(), 1);
    assert_eq!(teach.net().activations()[1], live[1] + 1.0);
    assert_eq!(d.on_key(key(' ')), Action::None, "space is not a teach key");
    d.on_key(key('t'));
    assert_eq!(d.mode, Mode::Paused);
    assert!(d.teach.is_none());
    assert_eq!(
        d.library.as_ref().unwrap().net.activations(),
        live.as_slice()
    );
}

/// A terminal cell, `(column, row)`.
type Cell = (u16, u16);

/// Cells of `main` (teach mode's panels) over policy `target`, in the left part (the graph)
/// and the right (the activations table).
fn cells_over(main: Rect, teach: &Teach, target: usize) -> (Vec<Cell>, Vec<Cell>) {
    (main.x..main.right())
        .flat_map(|c| (main.y..main.bottom()).map(move |r| (c, r)))
        .filter(|&(c, r)| teach_view::policy_at(main, teach, c, r) == Some(target))
        .partition(|&(c, _)| c < main.x + main.width / 2)
}

#[test]
fn in_teach_mode_a_click_picks_a_node_or_a_row() {
    let mut d = scripted(10);
    d.on_key(key('t'));
    assert_eq!(d.mode, Mode::Teach);
    let screen = Rect::new(0, 0, 120, 40);
    let main = Rect::new(0, 0, 120, 39); // above the status line
    let n = d.teach.as_ref().unwrap().net().len();
    for target in (0..n).rev() {
        let (nodes, rows) = cells_over(main, d.teach.as_ref().unwrap(), target);
        assert!(!nodes.is_empty() && !rows.is_empty(), "policy {target}");
        // A row is one line of the table.
        assert!(rows.iter().all(|&(_, r)| r == rows[0].1));
        sapnet::tui::click(&mut d, screen, nodes[0].0, nodes[0].1);
        assert_eq!(d.teach.as_ref().unwrap().cursor(), target);
        sapnet::tui::click(&mut d, screen, rows[0].0, rows[0].1);
        assert_eq!(d.teach.as_ref().unwrap().cursor(), target);
    }
    // The status line, and the trace panel's corner, pick nothing.
    sapnet::tui::click(&mut d, screen, 5, 39);
    sapnet::tui::click(&mut d, screen, 119, 38);
    assert_eq!(d.teach.as_ref().unwrap().cursor(), 0);

    // Stand-alone teach mode: Fig. 2 on a small terminal.
    let lesson = TeachConfig::load(None).unwrap();
    let teach = Teach::new(lesson.names, lesson.net);
    let screen = Rect::new(0, 0, 80, 24);
    let (_, rows) = cells_over(Rect::new(0, 0, 80, 23), &teach, 3);
    assert_eq!(
        teach_view::clicked(&teach, screen, rows[0].0, rows[0].1),
        Some(3)
    );
    // Below the size the screen needs, a click lands on nothing.
    assert_eq!(
        teach_view::clicked(&teach, Rect::new(0, 0, 60, 20), 1, 1),
        None
    );
}

/// `?` is the Run view's screen's (the dashboard draws in the workbench's frame): any key
/// closes it and does nothing else, Esc included; `q` and Ctrl-C still quit.
#[test]
fn help_opens_on_question_mark_and_any_key_closes_it_but_q_quits_always() {
    use sapnet::results::Status;
    use sapnet::tui::workbench::screens::session::{Phase, Request, Session};
    use sapnet::tui::workbench::screens::workbench::Tab;
    // The dashboard in the Run view of a protocol that ended (q then quits at once).
    let session = || {
        let ended = Phase::Ended(Status::Complete);
        let mut s = Session::new(std::path::Path::new("out"), "CartPole-v1", None, ended);
        s.workbench
            .run
            .show_recorded(("sapnet".into(), 0), scripted(1));
        s.workbench.tab = Tab::Run;
        s
    };
    let mode = |s: &Session| s.workbench.run.followed_run().unwrap().dashboard.mode;
    let mut s = session();
    s.on_key(key('?'));
    assert!(s.workbench.help);
    assert_eq!(
        s.on_key(key(' ')),
        Request::None,
        "closing the help is all it does"
    );
    assert!(!s.workbench.help);
    assert_eq!(mode(&s), Mode::Running);
    s.on_key(key('?'));
    assert_eq!(s.on_key(key('q')), Request::Quit);
    let ctrl_c = KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL);
    assert_eq!(session().on_key(ctrl_c), Request::Quit);
    let esc = KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE);
    assert_eq!(session().on_key(esc), Request::Quit);
    // Esc on the overlay closes it and never quits.
    let mut s = session();
    s.on_key(key('?'));
    assert_eq!(s.on_key(esc), Request::None);
    assert!(!s.workbench.help);
}

#[test]
fn m_follows_the_next_method_and_late_events_of_the_old_one_are_left_out() {
    let mut d = scripted(10);
    d.follow("sapnet");
    assert_eq!(d.on_key(key('m')), Action::FollowNext);
    // The UI stops SAP-Net's run and starts UCB1's: the old run leaves the screen.
    d.follow("ucb1");
    assert!(d.library.is_none());
    let methods: Vec<&str> = d.runs.iter().map(|r| r.method.label()).collect();
    assert_eq!(methods, ["dqn[100]"]);
    // SAP-Net's late events change nothing.
    for event in tui_script::episodes(3) {
        d.on_event(event);
    }
    d.on_event(tui_script::sapnet_start());
    assert!(d.library.is_none());
    assert_eq!(d.runs.len(), 1);
    // UCB1's start takes the followed place, under its own scores.
    let mut start = tui_script::sapnet_start();
    if let sapnet::trainer::Event::RunStarted {
        method,
        library: sapnet,
        ..
    } = &mut start
    {
        *method = sapnet::trainer::MethodId::new(7, &sapnet::reuse::Method::Ucb1);
        sapnet.as_mut().unwrap().score = sapnet::reuse::ucb1::SCORE;
    }
    d.on_event(start);
    let view = d.library.as_ref().unwrap();
    assert_eq!((view.method.as_str(), view.score.name), ("ucb1", "mean"));
    assert_eq!(d.runs[0].method.label(), "ucb1");
    // A paused dashboard starts the new run paused, at its speed.
    d.on_key(key(' '));
    d.on_key(key('-'));
    assert_eq!(d.settings(), [Command::Throttle(SPEEDS[1]), Command::Pause]);
}

#[test]
fn a_step_count_that_goes_back_restarts_the_speedometer() {
    let mut d = scripted(10);
    let t0 = std::time::Instant::now();
    d.tick(t0);
    d.tick(t0 + Duration::from_secs(1));
    assert!(d.steps_per_second.is_some());
    // The next method's run starts at step 1, while late steps of the old one came last.
    d.step = 3;
    d.tick(t0 + Duration::from_millis(1500));
    assert_eq!(d.steps_per_second, None);
}

/// The collapsed-softmax notice: the policy above P = 0.99 and the step since which it has
/// been there, forgotten when it drops below or another takes its place.
#[test]
fn lock_in_is_dated_from_the_first_snapshot_above_the_threshold() {
    let mut d = Dashboard::new("CartPole-v1");
    d.on_event(tui_script::sapnet_start());
    let snapshot = |step: u64, top: usize, p: f64| {
        let n = tui_script::HIDDEN.len();
        let mut probabilities = vec![(1.0 - p) / (n - 1) as f64; n];
        probabilities[top] = p;
        tui_script::probabilities_at(tui_script::method("sapnet"), step, probabilities)
    };
    let locked = |d: &Dashboard| d.library.as_ref().unwrap().locked;
    d.on_event(snapshot(5, 6, 0.9));
    assert_eq!(locked(&d), None);
    d.on_event(snapshot(10, 6, 0.995));
    d.on_event(snapshot(20, 6, 0.999));
    assert_eq!(locked(&d), Some((6, 10)));
    d.on_event(snapshot(30, 6, 0.5));
    assert_eq!(locked(&d), None);
    d.on_event(snapshot(40, 2, 0.9999));
    assert_eq!(locked(&d), Some((2, 40)));
}

/// UCB1 picks by rule: its view gives the next pick probability 1, which is no collapsed
/// softmax. The headless comparison measures no lock-in for it ("-"), and neither does the
/// dashboard.
#[test]
fn a_method_that_picks_by_rule_never_shows_a_lock_in() {
    let ucb1 = sapnet::trainer::MethodId::new(7, &sapnet::reuse::Method::Ucb1);
    let mut start = tui_script::sapnet_start();
    if let sapnet::trainer::Event::RunStarted {
        method,
        library: sapnet,
        ..
    } = &mut start
    {
        *method = ucb1.clone();
        sapnet.as_mut().unwrap().score = sapnet::reuse::ucb1::SCORE;
    }
    let mut d = Dashboard::new("CartPole-v1");
    d.on_event(start);
    let n = tui_script::HIDDEN.len();
    let mut probabilities = vec![0.0; n];
    probabilities[2] = 1.0;
    d.on_event(tui_script::probabilities_at(ucb1, 102_244, probabilities));
    assert_eq!(d.library.as_ref().unwrap().locked, None);
}

/// Issue 27: plain `sapnet` showed "P(source-6) > 0.99 since step" 645, 640 or 624 from
/// launch to launch, where the headless run of the same seeds records 623: the screen dated
/// the lock-in from the first frame that noticed it. It now shows the trainer's figure.
/// Run 0 of the embedded config's SAP-Net, on the shipped library, streamed as the
/// dashboard streams it and folded into its state, against the run's own record and the
/// same run streamed as headless mode streams it.
#[test]
fn the_dashboard_shows_the_lock_in_step_the_headless_run_records() {
    use sapnet::trainer::{Event, StreamOptions};
    let config = sapnet::config::Config::from_ron(sapnet::assets::CARTPOLE, "embedded").unwrap();
    let library = sapnet::sources::LibraryRoot {
        path: std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("saved_policies"),
        train_if_missing: false,
    };
    let (_stop, stop) = std::sync::mpsc::channel();
    let plan = sapnet::experiment::plan(&config, &library, 2, &stop).unwrap();
    let mut spec = plan
        .specs
        .into_iter()
        .find(|s| s.run == 0 && s.method.label() == "sapnet")
        .unwrap();
    // Lock-in comes within the first few hundred steps; 40 episodes are past it.
    spec.budget = sapnet::config::Budget::Episodes(40);
    let run = |stream: StreamOptions, dashboard: &mut Dashboard| {
        let mut spec = spec.clone();
        spec.stream = stream;
        let (events, received) = std::sync::mpsc::channel();
        let handle = sapnet::trainer::spawn(spec, events).unwrap();
        let mut record = None;
        for event in received {
            if let Event::RunEnded(r) = &event {
                record = Some(r.clone());
            }
            dashboard.on_event(event);
        }
        handle.thread.join().unwrap().unwrap();
        record.expect("the run ends")
    };
    let mut live = Dashboard::new("CartPole-v1");
    let shown = run(StreamOptions::live(), &mut live);
    let headless = run(
        StreamOptions::episodes(),
        &mut Dashboard::new("CartPole-v1"),
    );
    let step = headless
        .lock_in_step
        .expect("SAP-Net locks in within 40 episodes");
    assert_eq!(shown.lock_in_step, Some(step));
    let (_, since) = live.library.as_ref().unwrap().locked.expect("shown locked");
    assert_eq!(since, step);
    assert_eq!(
        shown.chosen.map(|c| c.name),
        headless.chosen.map(|c| c.name)
    );
}
