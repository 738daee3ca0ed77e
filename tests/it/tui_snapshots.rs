//! What each view draws, at 120×40 and 80×24, from scripted state (ratatui's TestBackend,
//! insta snapshots in tests/it/snapshots/). Colours are off (`NO_COLOR`'s theme), so the
//! snapshots show the symbols a user without colour reads.

use crate::common::tui_script;
use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::teach::lesson::TeachConfig;
use sapnet::teach::Teach;
use sapnet::trainer::Event;
use sapnet::tui::dashboard::Dashboard;
use sapnet::tui::theme::Theme;
use sapnet::tui::workbench::screens::session::{overlays, Phase, Session};
use sapnet::tui::{dashboard_view as view, teach_view};
use std::path::Path;

const SIZES: [(u16, u16); 2] = [(120, 40), (80, 24)];

fn key(c: char) -> KeyEvent {
    KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE)
}

fn dashboard() -> Dashboard {
    let mut d = Dashboard::new("CartPole-v1");
    d.on_event(tui_script::sapnet_start());
    d.on_event(tui_script::baseline_start());
    for event in tui_script::episodes(60) {
        d.on_event(event);
    }
    d
}

fn draw_dashboard(d: &Dashboard, (w, h): (u16, u16)) -> Terminal<TestBackend> {
    let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
    terminal
        .draw(|f| view::draw_dashboard(f, d, Theme::plain()))
        .unwrap();
    terminal
}

#[test]
fn dashboard_running() {
    let d = dashboard();
    for size in SIZES {
        insta::assert_snapshot!(
            format!("dashboard_{}x{}", size.0, size.1),
            draw_dashboard(&d, size).backend()
        );
    }
}

/// The reward chart's legend is its title: at 80×24 (where ratatui's legend box was hidden)
/// and at 120×40 (where it covered the newest episodes) each curve is named with its own
/// symbol without colour, and in its colour with a line before it in colour.
#[test]
fn the_reward_chart_names_its_curves_in_its_title_at_every_size() {
    let d = dashboard();
    for size in SIZES {
        for (theme, sapnet, dqn) in [
            (Theme::plain(), "• sapnet 111.5", "█ dqn[100] 9.9"),
            (Theme { color: true }, "━ sapnet 111.5", "━ dqn[100] 9.9"),
        ] {
            let mut terminal = Terminal::new(TestBackend::new(size.0, size.1)).unwrap();
            terminal
                .draw(|f| view::draw_dashboard(f, &d, theme))
                .unwrap();
            let buffer = terminal.backend().buffer().clone();
            let title = (0..buffer.area.height)
                .map(|y| {
                    (0..buffer.area.width)
                        .map(|x| buffer[(x, y)].symbol().to_string())
                        .collect::<String>()
                })
                .find(|row| row.contains("MA10"))
                .expect("the chart's title");
            assert!(
                title.contains(sapnet) && title.contains(dqn),
                "{size:?}: {title}"
            );
            if theme.color {
                let y = (0..buffer.area.height)
                    .find(|&y| (0..buffer.area.width).any(|x| buffer[(x, y)].symbol() == "━"))
                    .unwrap();
                let colours: Vec<_> = (0..buffer.area.width)
                    .filter(|&x| buffer[(x, y)].symbol() == "━")
                    .map(|x| buffer[(x, y)].fg)
                    .collect();
                assert_eq!(colours.len(), 2, "{title}");
                assert_ne!(colours[0], colours[1], "each name in its curve's colour");
            }
        }
    }
}

/// A category out of the candidates (`SapNetWith(exclusion: …)`): its nodes are drawn `×`
/// and the graph's title counts them, on the dashboard and in teach mode on the live net.
#[test]
fn an_excluded_category_is_shown_on_the_graph_and_in_teach() {
    let mut d = dashboard();
    // The one-hidden-layer sources 0, 4 and 9, as the trainer's snapshot gives them.
    let excluded: Vec<bool> = (0..10).map(|i| [0, 4, 9].contains(&i)).collect();
    let Event::Activations(mut snapshot) = tui_script::probabilities_at(
        tui_script::method("sapnet"),
        6_500,
        (0..10).map(|i| if i == 6 { 1.0 } else { 0.0 }).collect(),
    ) else {
        unreachable!()
    };
    snapshot.excluded = excluded.clone();
    d.on_event(Event::Activations(snapshot));
    assert_eq!(d.library.as_ref().unwrap().excluded, excluded);
    for size in SIZES {
        let terminal = draw_dashboard(&d, size);
        let screen = format!("{}", terminal.backend());
        assert!(screen.contains("SAP-Net graph · × 3 excluded"), "{screen}");
        for node in ["×0", "×4", "×9"] {
            assert!(screen.contains(node), "{size:?}: {node} in\n{screen}");
        }
        insta::assert_snapshot!(
            format!("dashboard_excluded_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
    d.on_key(key('t'));
    let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
    terminal
        .draw(|f| view::draw_dashboard(f, &d, Theme::plain()))
        .unwrap();
    let screen = format!("{}", terminal.backend());
    assert!(screen.contains("×0") && screen.contains("×9"), "{screen}");
}

#[test]
fn dashboard_after_the_run_names_the_chosen_policy_and_its_tests() {
    let mut d = dashboard();
    d.on_event(tui_script::sapnet_end(60));
    for size in SIZES {
        insta::assert_snapshot!(
            format!("dashboard_done_{}x{}", size.0, size.1),
            draw_dashboard(&d, size).backend()
        );
    }
}

#[test]
fn a_failed_sapnet_run_takes_the_status_bar() {
    let mut d = dashboard();
    d.on_event(sapnet::trainer::Event::RunFailed {
        run: 0,
        method: tui_script::method("sapnet"),
        error: "policy sapnet (source-3) (run 0) diverged: the loss is NaN at step 5120".into(),
    });
    assert!(d.runs[0].failed.is_some());
    let terminal = draw_dashboard(&d, (120, 40));
    insta::assert_snapshot!("failed_status_120x40", status_line(&terminal));
}

#[test]
fn a_failed_baseline_is_a_note_while_sapnet_goes_on() {
    let mut d = dashboard();
    d.on_event(sapnet::trainer::Event::RunFailed {
        run: 0,
        method: tui_script::method("dqn[100]"),
        error: "policy dqn[100] (run 0) diverged: the loss is NaN at step 5120".into(),
    });
    let terminal = draw_dashboard(&d, (80, 24));
    insta::assert_snapshot!("failed_baseline_status_80x24", status_line(&terminal));
}

#[test]
fn a_run_that_fails_before_it_starts_still_shows() {
    // SAP-Net's networks would not build: no RunStarted ever came.
    let mut d = Dashboard::new("CartPole-v1");
    d.on_event(tui_script::baseline_start());
    d.on_event(sapnet::trainer::Event::RunFailed {
        run: 0,
        method: tui_script::method("sapnet"),
        error: "building SAP-Net over the source policies: no policies".into(),
    });
    assert_eq!(d.main_run().unwrap().method.label(), "sapnet");
    let line = status_line(&draw_dashboard(&d, (80, 24)));
    assert!(line.contains("FAILED  sapnet: building SAP-Net"), "{line}");
}

/// A followed run that reuses no library says so once it has started, not that it is
/// loading one.
#[test]
fn a_followed_run_without_a_library_says_it_reuses_none() {
    let mut d = Dashboard::new("CartPole-v1");
    d.follow("dqn[100]");
    let text = screen_lines(&draw_dashboard(&d, (120, 40))).join("\n");
    assert!(text.contains("dqn[100]: loading the library"), "{text}");
    d.on_event(tui_script::baseline_start());
    let text = screen_lines(&draw_dashboard(&d, (120, 40))).join("\n");
    assert!(text.contains("dqn[100] reuses no library"), "{text}");
    assert!(!text.contains("loading"), "{text}");
}

/// A run followed after it ended streamed no steps: its step line says so instead of
/// waiting for one.
#[test]
fn a_run_followed_after_it_ended_says_it_has_no_steps() {
    let mut d = Dashboard::new("CartPole-v1");
    d.follow("sapnet");
    d.on_event(tui_script::sapnet_start());
    let lines = screen_lines(&draw_dashboard(&d, (120, 40)));
    assert!(
        lines[lines.len() - 2].contains("waiting for the first step"),
        "{lines:?}"
    );
    d.on_event(tui_script::sapnet_end(60));
    let lines = screen_lines(&draw_dashboard(&d, (120, 40)));
    assert!(lines[lines.len() - 2].contains("no steps: this run ended before it was followed"));
}

/// The bottom row of the screen.
fn status_line(terminal: &Terminal<TestBackend>) -> String {
    let buffer = terminal.backend().buffer();
    let y = buffer.area.height - 1;
    (0..buffer.area.width)
        .map(|x| buffer[(x, y)].symbol())
        .collect()
}

/// `dashboard` in the Run view of a protocol training, as `sapnet` shows it: `?` is the
/// Run view's (its keys are the dashboard's table, its screen's tabs and controls).
fn in_the_run_view(dashboard: Dashboard) -> Session {
    let followed = Some(("sapnet".to_string(), 0));
    let mut session = Session::new(Path::new("out"), "CartPole-v1", followed, Phase::Running);
    session
        .workbench
        .run
        .show_recorded(("sapnet".into(), 0), dashboard);
    session
}

fn draw_session(session: &Session, (w, h): (u16, u16)) -> Terminal<TestBackend> {
    let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
    terminal
        .draw(|f| overlays::draw(f, session, Theme::plain()))
        .unwrap();
    terminal
}

#[test]
fn dashboard_help_overlay() {
    let mut session = in_the_run_view(dashboard());
    session.on_key(key('?'));
    for size in SIZES {
        insta::assert_snapshot!(
            format!("help_{}x{}", size.0, size.1),
            draw_session(&session, size).backend()
        );
    }
}

#[test]
fn teach_on_the_live_graph() {
    let mut d = dashboard();
    d.on_key(key(' '));
    d.on_key(key('t'));
    d.on_key(key('a'));
    d.on_key(key('s'));
    for size in SIZES {
        insta::assert_snapshot!(
            format!("live_teach_{}x{}", size.0, size.1),
            draw_dashboard(&d, size).backend()
        );
    }
}

#[test]
fn teach_fig2_mid_walk() {
    let lesson = TeachConfig::load(None).unwrap();
    let mut teach = Teach::new(lesson.names, lesson.net);
    teach.move_cursor(1);
    teach.activate();
    for _ in 0..4 {
        teach.step();
    }
    for (w, h) in SIZES {
        let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
        terminal
            .draw(|f| teach_view::draw(f, &teach, false, Theme::plain()))
            .unwrap();
        insta::assert_snapshot!(format!("teach_fig2_{w}x{h}"), terminal.backend());
    }
}

#[test]
fn a_small_terminal_is_told_the_size_needed() {
    let terminal = draw_dashboard(&dashboard(), (60, 20));
    let text = format!("{}", terminal.backend());
    assert!(text.contains("60×20"), "{text}");
    assert!(text.contains("80×24"), "{text}");
    insta::assert_snapshot!("too_small_60x20", terminal.backend());
}

#[test]
fn another_selector_is_drawn_under_its_own_scores() {
    // UCB1 followed instead of SAP-Net: the graph and table name its scores.
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
    let mut d = Dashboard::new("CartPole-v1");
    d.on_event(start);
    d.on_event(tui_script::baseline_start());
    let terminal = draw_dashboard(&d, (120, 40));
    let buffer = terminal.backend().buffer();
    let lines: Vec<String> = (0..buffer.area.height)
        .map(|y| {
            (0..buffer.area.width)
                .map(|x| buffer[(x, y)].symbol())
                .collect()
        })
        .collect();
    let text = lines.join("\n");
    assert!(text.contains("library graph · ucb1 (mean)"), "{text}");
    assert!(!text.contains("SAP-Net graph"), "{text}");
    let header = lines
        .iter()
        .find(|l| l.contains("P(π)"))
        .expect("the table's header");
    let columns: Vec<&str> = header.split([' ', '│']).filter(|w| !w.is_empty()).collect();
    assert!(
        columns.windows(2).any(|w| w == ["mean", "P(π)"]),
        "{header}"
    );
}

#[test]
fn a_library_over_several_tasks_is_grouped_and_labelled_by_task() {
    // The scripted library with its ten sources spread over three source tasks, and the
    // SourceTask prototype first: the graph groups by task and names each group, the
    // table gives each source's task.
    let tasks = ["cartpole(length=1.0)", "cartpole(length=0.25)", "mirrored"];
    let descriptions: Vec<sapnet::sapnet::PolicyDescription> = tui_script::HIDDEN
        .iter()
        .enumerate()
        .map(|(i, h)| sapnet::sapnet::PolicyDescription::new(h.to_vec(), tasks[i % 3]))
        .collect();
    let mut params = sapnet::config::Config::default().sapnet;
    params.prototypes.insert(
        0,
        sapnet::sapnet::WeightedPrototype {
            prototype: sapnet::sapnet::Prototype::SourceTask,
            omega: 0.1,
        },
    );
    let net = sapnet::sapnet::SapNet::from_policies(&descriptions, params).unwrap();
    let mut start = tui_script::sapnet_start();
    if let sapnet::trainer::Event::RunStarted {
        library: sapnet, ..
    } = &mut start
    {
        let start = sapnet.as_mut().unwrap();
        for (policy, description) in start.policies.iter_mut().zip(descriptions) {
            policy.description = description;
        }
        start.net = net;
    }
    let mut d = Dashboard::new("CartPole-v1");
    d.on_event(start);
    d.on_event(tui_script::baseline_start());
    let terminal = draw_dashboard(&d, (140, 40));
    let text = format!("{}", terminal.backend());
    // Variants of one family are named by what differs.
    for task in ["length=1.0", "length=0.25", "mirrored"] {
        assert!(
            text.matches(task).count() >= 2,
            "{task} in graph and table: {text}"
        );
    }
    insta::assert_snapshot!("dashboard_tasks_140x40", terminal.backend());
}

#[test]
fn d_shows_each_score_less_the_highest() {
    let mut d = dashboard();
    d.on_key(key('d'));
    let terminal = draw_dashboard(&d, (120, 40));
    let text = format!("{}", terminal.backend());
    assert!(text.contains("A−max"), "{text}");
    // The locked-in source reads 0, every other one below it.
    let row = text
        .lines()
        .find(|l| l.contains("source-6  "))
        .expect("source-6's row");
    assert!(row.contains(" 0.000 "), "{row}");
    insta::assert_snapshot!("dashboard_relative_120x40", terminal.backend());
    d.on_key(key('d'));
    assert!(!format!("{}", draw_dashboard(&d, (120, 40)).backend()).contains("A−max"));
}

#[test]
fn teach_help_lists_the_teach_keys_only() {
    let lesson = TeachConfig::load(None).unwrap();
    let teach = Teach::new(lesson.names, lesson.net);
    let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
    terminal
        .draw(|f| teach_view::draw(f, &teach, true, Theme::plain()))
        .unwrap();
    let text = format!("{}", terminal.backend());
    assert!(text.contains("activate the picked policy"), "{text}");
    assert!(text.contains("run the spreading to its end"), "{text}");
    assert!(!text.contains("pause / resume training"), "{text}");
    insta::assert_snapshot!("teach_help_120x40", terminal.backend());
}

#[test]
fn p_numbers_the_policies_as_the_paper_does_and_says_so() {
    let lesson = TeachConfig::load(None).unwrap();
    let mut teach = Teach::new(lesson.names, lesson.net);
    let draw = |teach: &Teach| {
        let mut terminal = Terminal::new(TestBackend::new(120, 40)).unwrap();
        terminal
            .draw(|f| teach_view::draw(f, teach, false, Theme::plain()))
            .unwrap();
        format!("{}", terminal.backend())
    };
    let zero = draw(&teach);
    assert!(zero.contains("π0… (p)") && zero.contains("π0 ") && !zero.contains("π4"));
    assert!(sapnet::tui::dashboard::apply_teach_key(
        &mut teach,
        key('p')
    ));
    let paper = draw(&teach);
    assert!(paper.contains("π1… (p)"), "{paper}");
    assert!(paper.contains("π4") && !paper.contains("π0 "), "{paper}");
}

/// A teacher lowers T_ω in the middle of π1's walk: the walk restarts from the same
/// activations, fewer calls reach as far, and the screen says by how much.
#[test]
fn teach_edits_restart_the_walk_and_show_the_difference() {
    let lesson = TeachConfig::load(None).unwrap();
    let mut teach = Teach::new(lesson.names, lesson.net);
    let press = |teach: &mut Teach, c: char| {
        assert!(
            sapnet::tui::dashboard::apply_teach_key(teach, key(c)),
            "{c}"
        );
    };
    press(&mut teach, 'j');
    press(&mut teach, 'a');
    for _ in 0..4 {
        press(&mut teach, 's');
    }
    press(&mut teach, '1');
    press(&mut teach, '-');
    press(&mut teach, '-');
    let report = teach.last_edit().expect("an edit");
    assert_eq!((report.from.as_str(), report.to.as_str()), ("0.9", "0.8"));
    assert_eq!(teach.net().params().threshold, 0.8);
    assert!(report.calls.1 < report.calls.0, "{:?}", report.calls);
    assert_eq!(teach.walk().unwrap().trace.len(), 0, "restarted");
    for (w, h) in SIZES {
        let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
        terminal
            .draw(|f| teach_view::draw(f, &teach, false, Theme::plain()))
            .unwrap();
        // The call's and the edit's last lines, which 80×24 once cut off.
        let screen: String = format!("{}", terminal.backend())
            .lines()
            .map(|l| l.trim_matches(|c| c == '"' || c == '│').trim().to_string())
            .collect::<Vec<_>>()
            .join(" ");
        for last in ["pending", "P(π1) −0.075"] {
            assert!(screen.contains(last), "{w}x{h} lost {last:?}:\n{screen}");
        }
        insta::assert_snapshot!(format!("teach_edit_{w}x{h}"), terminal.backend());
    }
}

/// `z` gives the table the screen: wide enough for each policy's activation over the last
/// episodes, beside the figures.
#[test]
fn the_zoomed_table_shows_each_policys_activation_over_time() {
    let mut d = dashboard();
    d.on_key(key('z'));
    let terminal = draw_dashboard(&d, (120, 40));
    let screen = format!("{}", terminal.backend());
    assert!(screen.contains("A per episode"), "{screen}");
    insta::assert_snapshot!("dashboard_zoomed_table_120x40", terminal.backend());
    // Issue 27: at 80 columns the zoomed table showed no sparkline; it now gives up the
    // hidden layers and the +/− counts for it.
    let terminal = draw_dashboard(&d, (80, 24));
    let screen = format!("{}", terminal.backend());
    assert!(screen.contains("A per episode"), "{screen}");
    insta::assert_snapshot!("dashboard_zoomed_table_80x24", terminal.backend());
}

/// `--compare DIR`: a finished protocol's mean and its 95% interval under the live curves of the same
/// methods, named in the legend.
#[test]
fn a_finished_protocol_is_drawn_as_bands_under_the_live_curves() {
    let mut d = dashboard();
    let runs = |base: f64| -> Vec<Vec<f64>> {
        (0..3)
            .map(|r| {
                (0..60)
                    .map(|e| base + f64::from(e) + 10.0 * f64::from(r))
                    .collect()
            })
            .collect()
    };
    d.reference = vec![
        sapnet::tui::reference::Band::from_runs("sapnet", &runs(40.0), 10),
        sapnet::tui::reference::Band::from_runs("dqn[100]", &runs(5.0), 10),
        sapnet::tui::reference::Band::from_runs("ucb1", &runs(0.0), 10),
    ];
    let terminal = draw_dashboard(&d, (120, 40));
    let screen = format!("{}", terminal.backend());
    assert!(
        screen.contains("dim: --compare's mean and 95% CI · sapnet 3 runs · dqn[100] 3 runs"),
        "{screen}"
    );
    assert!(
        !screen.contains("ucb1"),
        "a method not on screen has no band: {screen}"
    );
    insta::assert_snapshot!("dashboard_reference_120x40", terminal.backend());
}

#[test]
fn a_run_other_than_the_first_is_named_in_the_status_line() {
    let d = dashboard();
    assert!(!status_line(&draw_dashboard(&d, (120, 40))).contains(" run "));
    // `--follow-run 2`: the runs announce themselves as run 2, as the results' files do.
    let mut d = Dashboard::new("CartPole-v1");
    for event in [tui_script::sapnet_start(), tui_script::baseline_start()] {
        let event = match event {
            Event::RunStarted {
                method,
                budget,
                library,
                ..
            } => Event::RunStarted {
                run: 2,
                method,
                budget,
                library,
            },
            other => other,
        };
        d.on_event(event);
    }
    let line = status_line(&draw_dashboard(&d, (120, 40)));
    assert!(line.contains("sapnet run 2 ep 0/5000"), "{line}");
}

/// The screen's rows as text.
fn screen_lines(terminal: &Terminal<TestBackend>) -> Vec<String> {
    let buffer = terminal.backend().buffer();
    (0..buffer.area.height)
        .map(|y| {
            (0..buffer.area.width)
                .map(|x| buffer[(x, y)].symbol())
                .collect()
        })
        .collect()
}

/// The cell `(column, row)` where `needle` first starts on the screen, at or right of
/// `from_column`.
fn cell_of(terminal: &Terminal<TestBackend>, needle: &str, from_column: u16) -> Option<(u16, u16)> {
    let buffer = terminal.backend().buffer();
    (0..buffer.area.height).find_map(|y| {
        (from_column..buffer.area.width)
            .find(|&x| {
                let rest: String = (x..buffer.area.width)
                    .map(|c| buffer[(c, y)].symbol())
                    .collect();
                rest.starts_with(needle)
            })
            .map(|x| (x, y))
    })
}

/// At 80×24 the policy table has nine rows for ten sources: it scrolls to the picked one,
/// says how many rows it hides, and a click picks the row it lands on.
#[test]
fn the_policy_table_scrolls_to_the_picked_row_at_the_smallest_size() {
    let mut d = dashboard();
    let terminal = draw_dashboard(&d, (80, 24));
    let text = screen_lines(&terminal).join("\n");
    assert!(!text.contains("source-9"), "{text}");
    assert!(
        text.contains("▼ 1 more"),
        "the hidden row is counted: {text}"
    );
    // Up from the first row: the last, scrolled into view.
    d.on_key(KeyEvent::new(KeyCode::Up, KeyModifiers::NONE));
    assert_eq!(d.cursor, 9);
    let terminal = draw_dashboard(&d, (80, 24));
    let text = screen_lines(&terminal).join("\n");
    assert!(text.contains("source-9"), "{text}");
    assert!(text.contains("▲ 1 more"), "{text}");
    assert!(!text.contains("source-0 "), "{text}");
    insta::assert_snapshot!("dashboard_scrolled_80x24", terminal.backend());
    // A click on the row that reads source-1 picks source-1.
    let (column, row) = cell_of(&terminal, "source-1 ", 31).expect("source-1's row");
    sapnet::tui::click(
        &mut d,
        ratatui::layout::Rect::new(0, 0, 80, 24),
        column,
        row,
    );
    assert_eq!(d.cursor, 1);
}

/// Teach mode on the live graph at 80×24: the activations table has room for four of ten
/// rows; it shows the picked and activated source-9 and source-0, which its first call
/// deposited on (issue 39: the rows nearest by index hid it), and the trace's names fit.
#[test]
fn live_teach_keeps_the_picked_policy_in_view_at_the_smallest_size() {
    let mut d = dashboard();
    d.on_key(key(' '));
    d.on_key(KeyEvent::new(KeyCode::Up, KeyModifiers::NONE));
    d.on_key(key('t'));
    d.on_key(key('a'));
    d.on_key(key('s'));
    let terminal = draw_dashboard(&d, (80, 24));
    let lines = screen_lines(&terminal);
    let text = lines.join("\n");
    assert!(text.contains("│source-9 "), "{text}");
    assert!(text.contains("│source-0 "), "{text}");
    assert!(text.contains("6 of 10 not shown"), "{text}");
    // The trace row of the call made: from source-9 to its first neighbour, by label.
    let trace: String = lines
        .iter()
        .find(|l| l.contains("│1    "))
        .expect("the trace's first row")
        .chars()
        .skip(36) // the right-hand panels
        .collect();
    assert!(!trace.contains("sour"), "{trace}");
    assert!(trace.contains("│1    9    "), "{trace}");
    insta::assert_snapshot!("live_teach_source_9_80x24", terminal.backend());
    // A click on the row that reads source-0 picks it.
    let (column, row) = cell_of(&terminal, "source-0 ", 37).expect("source-0's row");
    sapnet::tui::click(
        &mut d,
        ratatui::layout::Rect::new(0, 0, 80, 24),
        column,
        row,
    );
    assert_eq!(d.teach.as_ref().unwrap().cursor(), 0);
}

/// Table II's lesson names its policies by their layers: `1×100`, `2×100`, `3×100` and
/// `3×50-150-100` would all read `100` on the graph. The nodes read π0…π9 instead, and
/// the table gives each π its name, whole where there is room.
#[test]
fn a_lesson_whose_names_end_alike_is_labelled_by_index() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/teach_table2.ron");
    let lesson = TeachConfig::load(Some(&path)).unwrap();
    let mut teach = Teach::new(lesson.names, lesson.net);
    teach.move_cursor(8);
    for (w, h) in SIZES {
        let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
        terminal
            .draw(|f| teach_view::draw(f, &teach, false, Theme::plain()))
            .unwrap();
        let text = screen_lines(&terminal).join("\n");
        for node in ["○100", "●100", "◐100"] {
            assert!(!text.contains(node), "{node} at {w}×{h}: {text}");
        }
        for i in 0..10 {
            assert!(text.contains(&format!("○π{i}")), "π{i} at {w}×{h}: {text}");
        }
        // The picked policy's name, whole: in its column, or in the title where the
        // column has no room.
        assert!(text.contains("3×50-150-100"), "{w}×{h}: {text}");
        insta::assert_snapshot!(format!("teach_table2_{w}x{h}"), terminal.backend());
    }
}

/// `?` in teach mode on the live graph: Esc goes back there, so the help says so and
/// lists q and Ctrl-C alone for quitting; `p` renumbers π-named policies only, so it is
/// left out for source-0…; a line too long for the box wraps instead of being cut.
#[test]
fn live_teach_help_tells_the_keys_as_they_are() {
    let mut session = in_the_run_view(dashboard());
    session.on_key(key(' '));
    session.on_key(key('t'));
    session.on_key(key('?'));
    let terminal = draw_session(&session, (80, 24));
    let lines = screen_lines(&terminal);
    let text = lines.join("\n");
    assert!(
        text.contains("t / Esc  back to the paused dashboard"),
        "{text}"
    );
    assert!(text.contains("q / Ctrl-C  quit"), "{text}");
    assert!(!text.contains("q / Esc"), "{text}");
    assert!(!text.contains("number the policies"), "{text}");
    let wrapped = lines
        .iter()
        .position(|l| l.contains("the weight M of an"))
        .expect("the edit line");
    assert!(lines[wrapped + 1].contains("edge"), "{text}");
    insta::assert_snapshot!("live_teach_help_80x24", terminal.backend());
}

/// Paused for teaching, training makes no steps: the status shows no rate, not the last
/// one measured.
#[test]
fn the_status_shows_no_rate_while_training_is_paused() {
    let mut d = dashboard();
    d.steps_per_second = Some(15_001.0);
    assert!(status_line(&draw_dashboard(&d, (120, 40))).contains("15001 steps/s"));
    d.on_key(key(' '));
    d.on_key(key('t'));
    let line = status_line(&draw_dashboard(&d, (120, 40)));
    assert!(!line.contains("steps/s"), "{line}");
    assert!(line.contains(" · paused"), "{line}");
    d.on_key(key('t'));
    let line = status_line(&draw_dashboard(&d, (120, 40)));
    assert!(!line.contains("steps/s"), "{line}");
}

/// The first step of episode 61 came: the step line and the status both say episode 61,
/// the one being played.
#[test]
fn the_step_line_and_the_status_count_episodes_alike() {
    let mut d = dashboard();
    let Some(mut step) = d.last_step else {
        panic!("the script's steps")
    };
    step.episode = 61;
    step.step += 1;
    d.on_event(Event::Step(step));
    let terminal = draw_dashboard(&d, (120, 40));
    let lines = screen_lines(&terminal);
    let step_line = &lines[lines.len() - 2];
    assert!(step_line.contains("· ep 61 return"), "{step_line}");
    let status = status_line(&terminal);
    assert!(status.contains("ep 61/5000"), "{status}");
}

/// However long the figures, at least two spaces part them from the keys: "paused ? keys"
/// read as one phrase.
#[test]
fn the_status_figures_keep_apart_from_the_keys() {
    let mut d = dashboard();
    d.on_key(key(' '));
    d.on_key(key('t'));
    for step in [6_450, 241_747, 12_345_678] {
        d.step = step;
        for size in SIZES {
            let line = status_line(&draw_dashboard(&d, size));
            // The teach keys on a wide terminal, else the way back and ?.
            let keys = line
                .find("a s r")
                .or_else(|| line.find("Esc/t back"))
                .expect("the keys");
            assert!(
                !line.contains("q quit"),
                "teach mode's keys offer no quit: {line}"
            );
            assert!(line[..keys].ends_with("  "), "{line}");
        }
    }
}

/// Issue 27: `+` at full speed, `-` at the slowest and leaving teach mode (training stays
/// paused) said nothing; the status line now says it, at 80×24 and at 120×40, until the
/// next key.
#[test]
fn a_key_that_does_nothing_or_leaves_training_paused_says_so() {
    let mut d = dashboard();
    for size in [(80, 24), (120, 40)] {
        for _ in 0..=sapnet::tui::dashboard::SPEEDS.len() {
            d.on_key(key('+'));
        }
        let line = status_line(&draw_dashboard(&d, size));
        assert!(line.contains("already at full speed"), "{line}");
        for _ in 0..sapnet::tui::dashboard::SPEEDS.len() {
            d.on_key(key('-'));
        }
        let line = status_line(&draw_dashboard(&d, size));
        assert!(line.contains("already at the slowest speed"), "{line}");
        d.on_key(key('d'));
        let line = status_line(&draw_dashboard(&d, size));
        assert!(!line.contains("already"), "the next key clears it: {line}");
        d.on_key(key('t'));
        d.on_key(key('t'));
        let line = status_line(&draw_dashboard(&d, size));
        assert!(line.contains("PAUSED"), "{line}");
        assert!(
            line.contains("training is still paused: space resumes it"),
            "{line}"
        );
        d.on_key(key(' '));
        d.on_key(key('d'));
    }
}
