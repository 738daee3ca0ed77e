//! Teach mode's screen fixes (issue 39, item 6), each at 80×24 and 120×40: ratatui's
//! TestBackend, insta snapshots in tests/it/snapshots/, colours off (`NO_COLOR`'s theme).

use ratatui::backend::TestBackend;
use ratatui::Terminal;
use sapnet::teach::lesson::TeachConfig;
use sapnet::teach::Teach;
use sapnet::tui::teach_view;
use sapnet::tui::theme::Theme;

const SIZES: [(u16, u16); 2] = [(80, 24), (120, 40)];

fn fig2() -> Teach {
    let lesson = TeachConfig::load(None).unwrap();
    Teach::new(lesson.names, lesson.net)
}

fn table2() -> Teach {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/teach_table2.ron");
    let lesson = TeachConfig::load(Some(&path)).unwrap();
    let groups = lesson.groups.clone().unwrap();
    Teach::new(lesson.names, lesson.net).with_groups(groups)
}

fn draw(teach: &Teach, (w, h): (u16, u16)) -> Terminal<TestBackend> {
    let mut terminal = Terminal::new(TestBackend::new(w, h)).unwrap();
    terminal
        .draw(|f| teach_view::draw(f, teach, false, Theme::plain()))
        .unwrap();
    terminal
}

/// The screen's rows as text.
fn lines(terminal: &Terminal<TestBackend>) -> Vec<String> {
    let buffer = terminal.backend().buffer();
    (0..buffer.area.height)
        .map(|y| {
            (0..buffer.area.width)
                .map(|x| buffer[(x, y)].symbol())
                .collect()
        })
        .collect()
}

/// The text of the left-hand panels (the graph and the call), `width` columns of 45%.
fn left(line: &str, width: u16) -> String {
    line.chars().take(usize::from(width) * 45 / 100).collect()
}

fn right(line: &str, width: u16) -> String {
    line.chars().skip(usize::from(width) * 45 / 100).collect()
}

/// The row of the screen where the call panel's top border is.
fn call_panel_row(lines: &[String]) -> usize {
    lines
        .iter()
        .position(|l| l.contains("┌ the call "))
        .expect("the call panel")
}

/// Fig. 2's walk from π1 at its first call: `1/3 ÷ (1 × 0.4)`, written with `×` for the
/// product and never `·` (which read "A += 1·k = 3" in eq. 8's line).
#[test]
fn products_are_written_with_a_times_sign_and_nothing_else_is() {
    let mut teach = fig2();
    teach.move_cursor(1);
    teach.activate();
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = lines(&terminal);
        // The call panel, above the status line.
        let call: String = screen[call_panel_row(&screen)..screen.len() - 1]
            .iter()
            .map(|l| left(l, size.0))
            .collect::<Vec<_>>()
            .join("\n");
        // The text wraps at 80 columns: compare it without the wrapping.
        let flat: String = call
            .lines()
            .map(|l| l.trim_matches(|c| c == '│' || c == ' ' || c == '└' || c == '─'))
            .collect::<Vec<_>>()
            .join(" ");
        assert!(flat.contains("η/(h×Ω)"), "{call}");
        assert!(flat.contains("0.333333/(1×0.4000) = 0.833333"), "{call}");
        assert!(flat.contains("A[π1] += 𝒜 = 1; k = 3;"), "{call}");
        assert!(!call.contains('·'), "{call}");
        insta::assert_snapshot!(
            format!("teach_times_sign_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// Every step of Fig. 2's walk from π1 and of Table II's from π3: the call panel starts on
/// the same row and each node's label stays on its cell, from the first call to the
/// walk's end (the graph once grew and shrank with the call's text).
#[test]
fn the_graph_keeps_its_height_and_its_nodes_from_step_to_step() {
    for (mut teach, activated, nodes) in [(fig2(), 1, 4), (table2(), 3, 10)] {
        teach.move_cursor(activated as isize);
        for size in SIZES {
            let before = lines(&draw(&teach, size));
            let rows = call_panel_row(&before);
            let node_cells = |screen: &[String]| -> Vec<(usize, usize)> {
                (0..nodes)
                    .map(|i| {
                        let label = format!("π{i}");
                        screen
                            .iter()
                            .enumerate()
                            .find_map(|(row, l)| {
                                let graph = left(l, size.0);
                                let at = graph.find(&label)?;
                                // π1 is not π10's start: the label ends there.
                                let rest = &graph[at + label.len()..];
                                (!rest.starts_with(|c: char| c.is_ascii_digit()))
                                    .then(|| (row, graph[..at].chars().count()))
                            })
                            .unwrap_or_else(|| panic!("{label}: {}", screen.join("\n")))
                    })
                    .collect()
            };
            let first = node_cells(&before);
            let mut teach = teach.clone();
            teach.activate();
            let mut steps = 0;
            loop {
                let screen = lines(&draw(&teach, size));
                assert_eq!(call_panel_row(&screen), rows, "step {steps} at {size:?}");
                assert_eq!(node_cells(&screen), first, "step {steps} at {size:?}");
                if teach.step().is_none() {
                    break;
                }
                steps += 1;
            }
            assert!(steps > 5, "{steps}");
        }
    }
}

/// At 80×24 the trace once showed two calls: it shows four, the latest last.
#[test]
fn the_trace_shows_four_calls_at_the_smallest_size() {
    let mut teach = fig2();
    teach.move_cursor(1);
    teach.activate();
    for _ in 0..6 {
        teach.step();
    }
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = lines(&terminal);
        let header = screen
            .iter()
            .position(|l| right(l, size.0).contains("#    from to"))
            .expect("the trace's header");
        let calls: Vec<&str> = screen[header + 1..]
            .iter()
            .map(|l| l.as_str())
            .take_while(|l| !right(l, size.0).contains('└'))
            .filter(|l| {
                right(l, size.0)
                    .trim_start_matches('│')
                    .starts_with(|c: char| c.is_ascii_digit())
            })
            .collect();
        assert!(calls.len() >= 4, "{size:?}: {}", screen.join("\n"));
        assert!(
            right(calls[calls.len() - 1], size.0).starts_with("│6 "),
            "the latest call last: {calls:?}"
        );
        insta::assert_snapshot!(
            format!("teach_trace_rows_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// Table II's π3 activated: the policies the walk deposits on (π4, π5, π6, its category)
/// are in view beside π3. At 80×24 the activations table once had four rows for ten
/// policies and kept these in view; a grid now shows all ten.
#[test]
fn the_policies_receiving_delta_a_stay_in_the_table() {
    let mut teach = table2();
    teach.move_cursor(3);
    teach.activate();
    let deposited = |teach: &Teach| -> Vec<usize> {
        (0..10)
            .filter(|&i| teach.walk().unwrap().deposited[i] > 0.0 && i != 3)
            .collect()
    };
    while deposited(&teach).len() < 3 {
        teach.step().expect("the walk reaches π3's whole category");
    }
    assert_eq!(
        deposited(&teach),
        [4, 5, 6],
        "the hand count: π3's category is π3…π6"
    );
    assert!(!teach.walk().unwrap().done);
    for size in SIZES {
        let terminal = draw(&teach, size);
        let table: Vec<String> = lines(&terminal)
            .iter()
            .map(|l| right(l, size.0))
            .take_while(|l| !l.contains("pending spread calls"))
            .collect();
        let text = table.join("\n");
        // A row's first cell, or a cell of the grid's second column.
        let shows = |i: usize| {
            ["│π", "│ π"]
                .iter()
                .any(|at| text.contains(&format!("{at}{i} ")))
        };
        for i in [3, 4, 5, 6] {
            assert!(shows(i), "π{i} at {size:?}:\n{text}");
        }
        // Issue 51, item 5: at 80×24 a table of four rows once hid six policies; a grid
        // shows all ten.
        assert!((0..10).all(shows), "{size:?}:\n{text}");
        assert!(!text.contains("not shown"), "{text}");
        insta::assert_snapshot!(
            format!("teach_receivers_in_view_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// Fig. 2's two diagonals cross in the middle of the graph, where two `0.40`s once sat:
/// all four weights are written, none on the crossing.
#[test]
fn edge_weights_are_written_off_the_crossing() {
    let teach = fig2();
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = lines(&terminal);
        let graph_rows = call_panel_row(&screen);
        let graph: Vec<String> = screen[..graph_rows]
            .iter()
            .map(|l| left(l, size.0))
            .collect();
        let weights: usize = graph.iter().map(|l| l.matches("0.40").count()).sum();
        assert_eq!(weights, 4, "{}", graph.join("\n"));
        // The crossing: on the row of π3 and π1 (the horizontal diagonal), under π0's
        // label (centred on the vertical one).
        let crossing_column = graph
            .iter()
            .find_map(|l| l.find("π0").map(|at| l[..at].chars().count()))
            .expect("π0");
        let crossing_row = graph
            .iter()
            .find(|l| l.contains("π3") && l.contains("π1"))
            .expect("the horizontal diagonal");
        let cells: Vec<char> = crossing_row.chars().collect();
        let around: String = cells[crossing_column - 1..=crossing_column + 1]
            .iter()
            .collect();
        assert!(
            !around.contains(|c: char| c.is_ascii_digit() || c == '.'),
            "a weight on the crossing: {around:?}\n{}",
            graph.join("\n")
        );
        insta::assert_snapshot!(
            format!("teach_weights_off_crossing_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// Table II's graph: its weights (0.95, eq. 5 with δ = −0.5, ω = 0.1) are written, and
/// its ten nodes, three categories drawn together, each read whole at 80×24.
#[test]
fn table2_shows_its_weights_and_no_node_overlaps_another() {
    let mut teach = table2();
    teach.move_cursor(8);
    teach.activate();
    teach.step();
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = lines(&terminal);
        let graph: Vec<String> = screen[..call_panel_row(&screen)]
            .iter()
            .map(|l| left(l, size.0))
            .collect();
        let text = graph.join("\n");
        assert!(text.contains("0.95"), "{text}");
        for i in 0..10 {
            let label = format!("π{i}");
            let whole = graph.iter().any(|l| {
                l.match_indices(&label).any(|(at, _)| {
                    let before = l[..at].chars().last();
                    let after = l[at + label.len()..].chars().next();
                    before.is_some_and(|c| "○●◐◔◕×".contains(c))
                        && !after.is_some_and(|c| c.is_ascii_digit())
                })
            });
            assert!(whole, "{label} at {size:?}:\n{text}");
        }
        insta::assert_snapshot!(
            format!("teach_table2_graph_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// A click on a node's label picks it, where the label sits off its node to keep clear
/// of a neighbour's.
#[test]
fn a_click_on_a_node_label_picks_its_policy() {
    let teach = table2();
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = lines(&terminal);
        for i in 0..10 {
            let label = format!("π{i}");
            let (row, column) = screen
                .iter()
                .enumerate()
                .find_map(|(row, l)| {
                    let graph = left(l, size.0);
                    let at = graph.find(&label)?;
                    let rest = &graph[at + label.len()..];
                    (!rest.starts_with(|c: char| c.is_ascii_digit()))
                        .then(|| (row, graph[..at].chars().count()))
                })
                .unwrap();
            let screen_area = ratatui::layout::Rect::new(0, 0, size.0, size.1);
            assert_eq!(
                teach_view::clicked(&teach, screen_area, column as u16, row as u16),
                Some(i),
                "{label} at {size:?}"
            );
        }
    }
}

/// Two policies joined at 0.4 (the hand count is in src/teach/session.rs's
/// `one_decay_step_between_two_activations_by_hand`), with `extra` fields.
fn two_policies(extra: &str) -> Teach {
    let text = format!("(policies: 2, edges: [(0, 1, 0.4)]{extra})");
    let source = TeachConfig::lesson_from_ron(&text, "two.ron").unwrap();
    let config = sapnet::ron_file::parse_ron::<TeachConfig>(&text, "two.ron").unwrap();
    Teach::new(source.names, source.net).with_source(config)
}

fn text(terminal: &Terminal<TestBackend>) -> String {
    lines(terminal).join("\n")
}

/// Fig. 2 from π1 after three calls, `v` once: each call under the call that made it, two
/// spaces a level, with h, Ω, η and ΔA (1/3 ÷ (1 × 0.4) = 0.833333, then 1/6 ÷ (2 × 0.8) =
/// 0.104167, then Ω = 1.2 stopped), the next call marked.
#[test]
fn the_walk_as_a_tree_puts_each_call_under_its_caller() {
    let mut teach = fig2();
    teach.move_cursor(1);
    teach.activate();
    for _ in 0..3 {
        teach.step();
    }
    teach.next_panel();
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = text(&terminal);
        for line in [
            "tree (v: chart)",
            "└ π1→π0 h 1 Ω 0.40 η 0.3333 ΔA 0.833333",
            "  └ π0→π1 h 2 Ω 0.80 η 0.1667 ΔA 0.104167",
            "    └ π1→π0 h 3 Ω 1.20 η 0.0556 stopped",
            "    └ π1→π2 h 3 Ω 1.20 η 0.0556 ▶ next",
        ] {
            assert!(screen.contains(line), "{size:?} {line}:\n{screen}");
        }
        insta::assert_snapshot!(
            format!("teach_tree_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// `v` twice: A and P of every policy over the 21 calls of Fig. 2's walk from π1.
#[test]
fn a_chart_draws_a_and_p_over_the_calls() {
    let mut teach = fig2();
    teach.move_cursor(1);
    teach.activate();
    teach.run_to_end();
    teach.next_panel();
    teach.next_panel();
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = text(&terminal);
        assert!(screen.contains("chart (v: through time)"), "{screen}");
        // The x axis ends at the walk's last call.
        assert!(screen.contains("21"), "{screen}");
        insta::assert_snapshot!(
            format!("teach_chart_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// `v` thrice, after π0's walk and π1's with D = 0.5 between them: (1.625, 2.5), then
/// (3.3125, 2.875); P(π0) after the first is 1/(1 + e^0.875) = 0.29.
#[test]
fn a_and_p_through_time_a_column_per_walk() {
    let mut teach = two_policies(", decay: 0.5");
    teach.activate();
    teach.run_to_end();
    teach.move_cursor(1);
    teach.activate();
    teach.run_to_end();
    for _ in 0..3 {
        teach.next_panel();
    }
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = text(&terminal);
        for said in [
            "A (P) through time, D = 0.5 (v: trace)",
            "1:π0",
            "2:π1",
            "1.6250 (0.29)",
            "3.3125 (0.61)",
        ] {
            assert!(screen.contains(said), "{size:?} {said}:\n{screen}");
        }
        insta::assert_snapshot!(
            format!("teach_through_time_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// The status bar names the keys, the new ones too, and says what is on: M's clicks, the
/// exercise's score.
#[test]
fn the_status_bar_names_the_new_keys_and_the_modes_on() {
    let mut teach = fig2();
    teach.toggle_exercise();
    teach.toggle_linking();
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = lines(&terminal);
        let status = screen.last().unwrap();
        let modes = if size.0 >= 100 {
            ["M: click two policies", "exercise 0/0"]
        } else {
            ["M clicks", "ex 0/0"]
        };
        for said in modes
            .into_iter()
            .chain(["E x M", "n D C", "v", "w", "X", "? q"])
        {
            assert!(status.contains(said), "{size:?} {said}: {status}");
        }
        insta::assert_snapshot!(
            format!("teach_status_modes_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// A lesson's question at the walk's end: asked in the edit panel, its answer nowhere on
/// the screen until answered.
#[test]
fn a_question_is_asked_at_the_walks_end_and_its_answer_hidden() {
    let mut teach = two_policies(
        ", questions: [(ask: \"How much is 𝒜 × 7.25?\", answer: Number(value: 7.25, \
         tolerance: 0.01))]",
    );
    teach.activate();
    while teach.walk().is_some_and(|w| !w.done) {
        teach.step();
    }
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = text(&terminal);
        assert!(screen.contains("How much is 𝒜 ×"), "{size:?}:\n{screen}");
        assert_eq!(
            screen.matches("7.25").count(),
            1,
            "only in the question:\n{screen}"
        );
        insta::assert_snapshot!(
            format!("teach_question_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
    "7.25".chars().for_each(|c| teach.prompt_type(c));
    teach.prompt_submit();
    assert_eq!(teach.notice(), Some("right: 7.25 ± 0.01 · questions 1/1"));
}

/// Issue 51, item 5: the exercise once printed the answer beside its question. Fig. 2
/// from π1: the first call deposits (1/3)/(1×0.4) = 0.833333, the second
/// (1/6)/(2×0.8) = 0.104167, the third stops (Ω = 1.2 ≥ T_ω = 1). Each is nowhere on the
/// screen while it is asked, and said once answered.
#[test]
fn the_exercise_hides_the_answer_until_it_is_given() {
    let mut teach = fig2();
    teach.move_cursor(1);
    teach.activate();
    teach.toggle_exercise();
    let answer = |teach: &mut Teach, typed: &str| {
        typed.chars().for_each(|c| teach.prompt_type(c));
        teach.prompt_submit();
    };
    teach.step_or_ask();
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = text(&terminal);
        assert!(
            screen.contains("ΔA of the next call"),
            "{size:?}:\n{screen}"
        );
        assert!(!screen.contains("0.833"), "{size:?}:\n{screen}");
        assert!(!screen.contains("true"), "{size:?}:\n{screen}");
        insta::assert_snapshot!(
            format!("teach_exercise_asked_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
    answer(&mut teach, "0.8333");
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = text(&terminal);
        assert!(screen.contains("0.833333"), "{size:?}:\n{screen}");
        assert!(!screen.contains("0.104"), "the next answer:\n{screen}");
        insta::assert_snapshot!(
            format!("teach_exercise_answered_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
    teach.step_or_ask();
    answer(&mut teach, "0.1");
    teach.step_or_ask();
    for size in SIZES {
        let screen = text(&draw(&teach, size));
        assert!(
            !screen.contains("stop (") && !screen.contains("stopped"),
            "{screen}"
        );
        assert!(!screen.contains("the call stops"), "{size:?}:\n{screen}");
    }
    answer(&mut teach, "stop");
    for size in SIZES {
        let screen = text(&draw(&teach, size));
        assert!(screen.contains("stopped"), "{size:?}:\n{screen}");
        assert!(screen.contains("score 2/3"), "{size:?}:\n{screen}");
    }
}

/// At 80×24 Table II's activations are a grid of two columns: a click on a cell picks its
/// policy, a click on the gap between the columns picks none.
#[test]
fn a_click_on_a_cell_of_the_activations_grid_picks_its_policy() {
    let teach = table2();
    let size = (80, 24);
    let screen = lines(&draw(&teach, size));
    let screen_area = ratatui::layout::Rect::new(0, 0, size.0, size.1);
    let click = |column: usize, row: usize| {
        teach_view::clicked(&teach, screen_area, column as u16, row as u16)
    };
    for i in 0..10 {
        let (row, column) = screen
            .iter()
            .enumerate()
            .find_map(|(row, l)| {
                let table = right(l, size.0);
                let at = table.find(&format!("π{i} 0."))?;
                Some((
                    row,
                    usize::from(size.0) * 45 / 100 + table[..at].chars().count(),
                ))
            })
            .unwrap_or_else(|| panic!("π{i}'s cell:\n{}", screen.join("\n")));
        assert_eq!(click(column, row), Some(i), "π{i}");
        assert_eq!(click(column + 8, row), Some(i), "π{i}'s A");
    }
    let row = screen.iter().position(|l| l.contains("π0 0.")).unwrap();
    let gap = right(&screen[row], size.0).find(" │ ").unwrap();
    let gap = usize::from(size.0) * 45 / 100 + right(&screen[row], size.0)[..gap].chars().count();
    assert_eq!(click(gap + 1, row), None, "the gap");
}

/// Issue 51, item 5: Table II's chart had ten curves and no legend (no room for one).
/// Each curve's end is named beside it: π3's walk ends with π3 highest in A and P, π4…π6
/// (its category) sharing a row in A, the other six the bottom one; names that do not
/// fit are counted (`π4 +2`).
#[test]
fn the_charts_curves_are_named_at_their_ends() {
    let mut teach = table2();
    teach.move_cursor(3);
    teach.activate();
    teach.run_to_end();
    teach.next_panel();
    teach.next_panel();
    for size in SIZES {
        let terminal = draw(&teach, size);
        let screen = lines(&terminal);
        let chart: Vec<String> = screen
            .iter()
            .map(|l| right(l, size.0))
            .skip_while(|l| !l.contains("chart (v: through time)"))
            .collect();
        let text = chart.join("\n");
        // π3 ends highest in both charts, A's and P's, alone on its row.
        assert_eq!(text.matches(" π3 ").count(), 2, "{size:?}:\n{text}");
        for named in ["π4", "π0"] {
            assert!(text.contains(named), "{size:?} {named}:\n{text}");
        }
        insta::assert_snapshot!(
            format!("teach_table2_chart_{}x{}", size.0, size.1),
            terminal.backend()
        );
    }
}

/// Table II through time at 80×24 has room for four of ten policies' rows: it once cut
/// the rest silently. The picked policy's row stays in view as the arrows move, and the
/// border counts the rows left out.
#[test]
fn through_time_keeps_the_picked_policy_in_view_and_counts_the_rest() {
    let mut teach = table2();
    teach.move_cursor(3);
    teach.activate();
    teach.run_to_end();
    teach.move_cursor(5);
    for _ in 0..3 {
        teach.next_panel();
    }
    let terminal = draw(&teach, (80, 24));
    let panel: Vec<String> = lines(&terminal)
        .iter()
        .map(|l| right(l, 80))
        .skip_while(|l| !l.contains("through time"))
        .collect();
    let text = panel.join("\n");
    assert!(text.contains("│π8 "), "{text}");
    assert!(!text.contains("│π0 "), "{text}");
    assert!(text.contains("▲ 5 more · ▼ 1 more"), "{text}");
    insta::assert_snapshot!("teach_table2_through_time_80x24", terminal.backend());
}
