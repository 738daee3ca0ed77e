//! Drawing teach mode: one activation's spreading (Algorithms 1 and 2), every quantity
//! beside its equation, and the live edits' effect on the walk.

use ratatui::layout::{Constraint, Layout, Position, Rect};
use ratatui::style::{Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Cell, Paragraph, Row, Table, Wrap};
use ratatui::Frame;

use super::graph_layout;
use super::graph_view::{self, node_style, Scene};
use super::row_window::RowWindow;
use super::screen::{draw_help, probability_bar, too_small, MIN_HEIGHT, MIN_WIDTH};
use super::theme::Theme;
use crate::sapnet::TraceStep;
use crate::teach::knobs::{EditReport, Knob};
use crate::teach::labels;
use crate::teach::Teach;

/// Draws stand-alone teach mode (`sapnet teach`).
pub fn draw(frame: &mut Frame, teach: &Teach, help: bool, theme: Theme) {
    let area = frame.area();
    if too_small(frame, area) {
        return;
    }
    let [main, status] = Layout::vertical([Constraint::Min(0), Constraint::Length(1)]).areas(area);
    draw_body(frame, main, teach, theme);
    let mut spans = vec![
        Span::styled(" teach ", theme.title().add_modifier(Modifier::REVERSED)),
        Span::raw(" "),
    ];
    if let Some(numbering) = teach.numbering() {
        spans.push(Span::raw(format!("{numbering} (p) · ")));
    }
    // Narrow terminals drop the keys' words, not the keys.
    let hints = if area.width >= 100 {
        TEACH_HINTS
    } else {
        TEACH_HINTS_SHORT
    };
    spans.push(Span::styled(hints, theme.dim()));
    let line = Line::from(spans);
    frame.render_widget(Paragraph::new(line), status);
    if help {
        draw_help(frame, area, &teach_help(teach, false), theme);
    }
}

/// Teach mode's own keys, for its `?`. `p` is listed where it renumbers the policies (they
/// are called π0…); Esc quits stand-alone teach mode, and on the dashboard goes back to it.
pub(super) fn teach_help(
    teach: &Teach,
    on_the_dashboard: bool,
) -> Vec<(&'static str, &'static str)> {
    let mut keys = vec![
        ("↑↓←→ hjkl, click", "pick a policy (its node or its row)"),
        ("a", "activate the picked policy (A += 𝒜, eq. 8)"),
        ("s", "make the next spread call (eq. 9–11)"),
        ("r", "run the spreading to its end (s, u, c stop it)"),
        ("u", "undo the last call, then the activation"),
        ("c", "back to the starting activations"),
    ];
    if teach.numbering().is_some() {
        keys.push(("p", "number the policies π1…πN as the paper does, or π0…"));
    }
    keys.extend([
        (
            "1 … 5",
            "edit T_ω, 𝒜, τ, the path mode or the weight M of an edge",
        ),
        (
            "+ / −",
            "turn it a step: the walk restarts, the change is shown",
        ),
        ("e", "the picked policy's next edge (for 5)"),
        ("?", "this help (any key closes it)"),
    ]);
    if on_the_dashboard {
        keys.extend([
            ("t / Esc", "back to the paused dashboard"),
            ("q / Ctrl-C", "quit"),
        ]);
    } else {
        keys.push(("q / Esc / Ctrl-C", "quit"));
    }
    keys
}

const TEACH_HINTS: &str =
    "↑↓ pick · a activate · s step · r run · u undo · c reset · 1–5 +/− edit · ? help · q quit";
const TEACH_HINTS_SHORT: &str = "↑↓ a s r u c · 1–5 +/− e · ? help · q quit";

/// Where teach mode's panels go.
struct Panels {
    graph: Rect,
    call: Rect,
    values: Rect,
    stack: Rect,
    edits: Rect,
    trace: Rect,
}

/// Teach mode's panels in `area`, for hit-testing a click (drawing lays them out from the
/// paragraphs it draws, [`layout`]).
fn panels(area: Rect, teach: &Teach) -> Panels {
    let call = call_paragraph(teach, Theme::plain());
    let edits = edits_paragraph(teach, Theme::plain());
    layout(area, teach.net().len(), &call, &edits)
}

/// Teach mode's panels in `area` for a net of `n` policies: the call's and the edit's
/// panels as tall as their wrapped text (at 80 columns both wrap to more lines than fixed
/// heights held), the graph and the trace taking what is left.
fn layout(area: Rect, n: usize, call: &Paragraph, edits: &Paragraph) -> Panels {
    let [left, right] =
        Layout::horizontal([Constraint::Percentage(45), Constraint::Percentage(55)]).areas(area);
    let rows = |paragraph: &Paragraph, width: u16| {
        u16::try_from(paragraph.line_count(width.saturating_sub(2))).unwrap_or(u16::MAX)
    };
    let call_rows = rows(call, left.width).clamp(9, left.height.saturating_sub(GRAPH_MIN_ROWS));
    let [graph, call] = Layout::vertical([
        Constraint::Min(GRAPH_MIN_ROWS),
        Constraint::Length(call_rows),
    ])
    .areas(left);
    let short = area.height < 30;
    let values_rows = (n as u16 + 3).min(right.height / 3);
    let stack_rows = if short { 5 } else { 7 };
    let edit_rows = rows(edits, right.width).clamp(
        6,
        right
            .height
            .saturating_sub(values_rows + stack_rows + TRACE_MIN_ROWS),
    );
    let [values, stack, edits, trace] = Layout::vertical([
        Constraint::Length(values_rows),
        Constraint::Length(stack_rows),
        Constraint::Length(edit_rows),
        Constraint::Min(TRACE_MIN_ROWS),
    ])
    .areas(right);
    Panels {
        graph,
        call,
        values,
        stack,
        edits,
        trace,
    }
}

/// Rows the graph keeps however long the call's text, and the trace however long the edit's.
const GRAPH_MIN_ROWS: u16 = 8;
const TRACE_MIN_ROWS: u16 = 3;

/// The policy under the cell `(column, row)` of teach mode's panels drawn in `area`: a node
/// of the graph, or a row of the activations table.
pub fn policy_at(area: Rect, teach: &Teach, column: u16, row: u16) -> Option<usize> {
    let n = teach.net().len();
    let panels = panels(area, teach);
    let at = Position::new(column, row);
    if panels.graph.contains(at) {
        let positions = graph_layout::positions(n, teach.groups());
        return graph_layout::canvas_point(panels.graph, column, row)
            .and_then(|point| graph_layout::node_at(&positions, point, graph_layout::CLICK_REACH));
    }
    if panels.values.contains(at) && row < panels.values.bottom() - 1 {
        // The rows as drawn, below the border and the header row.
        let line = usize::from(row.checked_sub(panels.values.y + 2)?);
        return values_rows(panels.values, teach).row_at(line);
    }
    None
}

/// The rows of the activations table that a panel of `area` shows: the picked policy's
/// always, and the activated one's beside it if they fit.
fn values_rows(area: Rect, teach: &Teach) -> RowWindow {
    let room = usize::from(area.height.saturating_sub(3));
    let activated = teach.walk().map(|w| w.policy);
    RowWindow::new(
        teach.net().len(),
        room,
        std::iter::once(teach.cursor()).chain(activated),
    )
}

/// The policy a left click at `(column, row)` of a `screen` showing teach mode (its panels
/// above the status line, in the dashboard or on their own) lands on, if any.
pub fn clicked(teach: &Teach, screen: Rect, column: u16, row: u16) -> Option<usize> {
    if screen.width < MIN_WIDTH || screen.height < MIN_HEIGHT {
        return None;
    }
    let [main, _status] =
        Layout::vertical([Constraint::Min(0), Constraint::Length(1)]).areas(screen);
    policy_at(main, teach, column, row)
}

/// Teach mode's panels, in the dashboard or on their own.
pub fn draw_body(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let call = call_paragraph(teach, theme);
    let edits = edits_paragraph(teach, theme);
    let panels = layout(area, teach.net().len(), &call, &edits);

    let walk = teach.walk();
    let next = walk.as_ref().and_then(|w| w.pending.last().copied());
    let lit: Vec<(usize, usize)> = walk
        .as_ref()
        .map(|w| w.path.windows(2).map(|e| (e[0], e[1])).collect())
        .unwrap_or_default();
    let scene = Scene {
        net: teach.net(),
        names: teach.names(),
        groups: teach.groups(),
        group_names: &[],
        cursor: Some(teach.cursor()),
        active: walk.as_ref().map(|w| w.policy),
        lit: &lit,
        walking: next.map(|c| (c.from, c.to)),
        excluded: teach.excluded(),
    };
    let params = teach.net().params();
    let title = format!(
        "SAP-Net · T_ω {} · 𝒜 {} · τ {}",
        params.threshold, params.coefficient, params.temperature
    );
    graph_view::draw(
        frame,
        panels.graph,
        Block::bordered().title(Span::styled(format!(" {title} "), theme.title())),
        scene,
        theme,
    );

    frame.render_widget(call, panels.call);
    frame.render_widget(edits, panels.edits);
    draw_values(frame, panels.values, teach, theme);
    draw_stack(frame, panels.stack, teach, theme);
    draw_trace(frame, panels.trace, teach, theme);
}

/// The call about to be made, with eq. 10's test, beside the one just made.
fn call_paragraph(teach: &Teach, theme: Theme) -> Paragraph<'static> {
    let walk = teach.walk();
    let names = teach.names();
    let next = walk.as_ref().and_then(|w| w.pending.last().copied());
    let params = teach.net().params();
    let threshold = params.threshold;
    let mut lines = Vec::new();
    if let Some(made) = walk.as_ref().and_then(|w| w.trace.last()) {
        let outcome = if made.stopped {
            "stopped (Ω ≥ T_ω)".to_string()
        } else {
            format!("ΔA {:.6}", made.delta)
        };
        lines.push(Line::styled(
            format!(
                "made: spread({}, h {}, Ω {:.4}) from {}: {outcome}",
                names[made.to], made.h, made.omega, names[made.from]
            ),
            theme.dim(),
        ));
    }
    match (&walk, next) {
        (None, _) => lines.push(Line::from(
            "Pick a policy with ↑↓ and press a to activate it: A[i] += 𝒜 (eq. 8).",
        )),
        (Some(w), Some(call)) => {
            lines.push(Line::from(format!(
                "next (Alg. 2): spread({}, h {}, Ω {:.4}, η {:.6}) from {}",
                names[call.to], call.h, call.omega, call.eta, names[call.from]
            )));
            let passes = call.omega < threshold;
            lines.push(Line::from(vec![
                Span::raw(format!(
                    "eq. 10: Ω < T_ω: {:.4} < {threshold} is ",
                    call.omega
                )),
                if passes {
                    Span::styled("true", theme.active())
                } else {
                    Span::styled("false: the call stops (eq. 10)", theme.stopped())
                },
            ]));
            if passes {
                lines.push(Line::from(format!(
                    "eq. 10: ΔA[{}] = η/(h·Ω) = {:.6}/({}·{:.4}) = {:.6}",
                    names[call.to],
                    call.eta,
                    call.h,
                    call.omega,
                    call.eta / (call.h as f64 * call.omega)
                )));
                lines.push(Line::from(format!(
                    "eq. 9: then η/k = {:.6}/{} to each neighbour of {}",
                    call.eta,
                    teach.net().graph().degree(call.to),
                    names[call.to]
                )));
            }
            lines.push(Line::styled(
                format!(
                    "eq. 8: A[{}] += {} · k = {} · calls {} made, {} pending",
                    names[w.policy],
                    params.coefficient,
                    teach.net().graph().degree(w.policy),
                    w.trace.len(),
                    w.pending.len()
                ),
                theme.dim(),
            ));
        }
        (Some(w), None) => lines.push(Line::from(format!(
            "spreading from {} is done: {} calls. a activates again, u undoes, c resets.",
            names[w.policy],
            w.trace.len()
        ))),
    }
    Paragraph::new(lines)
        .wrap(Wrap { trim: false })
        .block(Block::bordered().title(Span::styled(" the call ", theme.title())))
}

/// The recursion's stack: pending calls, the next on top.
fn draw_stack(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let walk = teach.walk();
    let names = teach.names();
    let pending = walk.as_ref().map_or(0, |w| w.pending.len());
    // The next calls, on top; the marker counts those below.
    let window = RowWindow::new(pending, usize::from(area.height.saturating_sub(2)), [0]);
    let stack_lines: Vec<Line> = walk
        .as_ref()
        .map(|w| {
            w.pending
                .iter()
                .rev()
                .take(window.shown)
                .enumerate()
                .map(|(k, c)| {
                    let text = format!(
                        "{} → {}  h {}  Ω {:.2}  η {:.4}",
                        names[c.from], names[c.to], c.h, c.omega, c.eta
                    );
                    if k == 0 {
                        Line::styled(format!("▶ {text}"), theme.active())
                    } else {
                        Line::from(format!("  {text}"))
                    }
                })
                .collect()
        })
        .unwrap_or_default();
    let block = Block::bordered()
        .title(Span::styled(
            " pending spread calls (next on top) ",
            theme.title(),
        ))
        .title_bottom(
            Line::styled(window.marker().unwrap_or_default(), theme.title()).right_aligned(),
        );
    frame.render_widget(Paragraph::new(stack_lines).block(block), area);
}

/// The trace: the calls made so far, the latest last.
fn draw_trace(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let walk = teach.walk();
    let names = teach.names();
    let trace_steps = walk.as_ref().map_or(&[][..], |w| w.trace);
    // The latest calls; the marker counts the earlier ones.
    let window = RowWindow::new(
        trace_steps.len(),
        usize::from(area.height.saturating_sub(3)),
        trace_steps.len().checked_sub(1),
    );
    // Wide enough for the last call's number: long walks make hundreds of thousands.
    let number_width = trace_steps.len().max(1).to_string().len().max(4) as u16;
    // #, h, Ω, η, ΔA ("0.526316") and the six gaps between the seven columns.
    let fixed = number_width + 2 + 5 + 7 + 8 + 6;
    let room = area.width.saturating_sub(2 + fixed) / 2;
    // The names where both columns have room for them, else the graph's labels.
    let short: Vec<String>;
    let names = if name_width(names, 4, usize::MAX) <= room {
        names
    } else {
        short = labels::labels(names);
        short.as_slice()
    };
    let name_width = name_width(names, 4, usize::MAX);
    let rows = trace_steps[window.rows()]
        .iter()
        .zip(window.rows())
        .map(|(s, k)| trace_row(k + 1, s, names, theme));
    frame.render_widget(
        Table::new(
            rows,
            [
                Constraint::Length(number_width),
                Constraint::Length(name_width),
                Constraint::Length(name_width),
                Constraint::Length(2),
                Constraint::Length(5),
                Constraint::Length(7),
                Constraint::Min(8),
            ],
        )
        .header(Row::new(["#", "from", "to", "h", "Ω", "η", "ΔA"]).style(theme.title()))
        .block(
            Block::bordered()
                .title(Span::styled(" trace ", theme.title()))
                .title_bottom(
                    Line::styled(window.marker().unwrap_or_default(), theme.title())
                        .right_aligned(),
                ),
        ),
        area,
    );
}

fn trace_row(k: usize, s: &TraceStep, names: &[String], theme: Theme) -> Row<'static> {
    let delta = if s.stopped {
        Span::styled("stopped", theme.stopped())
    } else {
        Span::raw(format!("{:.6}", s.delta))
    };
    Row::new(vec![
        Cell::from(k.to_string()),
        Cell::from(names[s.from].clone()),
        Cell::from(names[s.to].clone()),
        Cell::from(s.h.to_string()),
        Cell::from(format!("{:.2}", s.omega)),
        Cell::from(format!("{:.4}", s.eta)),
        Cell::from(delta),
    ])
    .style(Style::new())
}

/// A and P of every policy, with what the walk has deposited (eq. 11) and, after an edit,
/// how the walk's end moved.
fn draw_values(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let names = teach.names();
    let net = teach.net();
    let probabilities = net.probabilities();
    let top = graph_view::highest(net.activations().iter().copied());
    let deposited = teach.walk().map(|w| w.deposited);
    // The edit's columns where the panel has room; the edit panel sums them up anyway.
    let edit = teach
        .last_edit()
        .filter(|_| area.width >= 60)
        .map(|r| (r.activation_change(), r.probability_change()));
    // The figures' columns, then the names in the room left (the names are cut only
    // where there is none), then the lesson's descriptions where they fit whole; where
    // they do not, the title gives the picked policy's.
    let mut widths = vec![
        Constraint::Length(VALUE_WIDTH as u16),
        Constraint::Length(VALUE_WIDTH as u16),
        Constraint::Length(11),
    ];
    let mut header = vec!["A (eq. 8)", "ΣΔA eq.11", "P (eq. 6)"];
    if edit.is_some() {
        widths.extend([Constraint::Length(9), Constraint::Min(6)]);
        header.extend(["edit: ΔA", "ΔP"]);
    }
    let figures: u16 = widths.iter().map(|w| constraint_width(*w) + 1).sum();
    let room = area.width.saturating_sub(2 + figures);
    let name_width = name_width(names, 6, usize::from(room));
    let descriptions = teach.descriptions();
    let description_width = descriptions.map_or(0, name_width_of);
    let beside = descriptions.filter(|_| description_width < room.saturating_sub(name_width));
    if beside.is_some() {
        widths.insert(0, Constraint::Length(description_width));
        header.insert(0, "name");
    }
    widths.insert(0, Constraint::Length(name_width));
    header.insert(0, "policy");
    let mut title = " activations ".to_string();
    if let (Some(descriptions), None) = (descriptions, beside) {
        let i = teach.cursor();
        title = format!(" activations · {} = {} ", names[i], descriptions[i]);
    }
    let window = values_rows(area, teach);
    let rows = names[window.rows()]
        .iter()
        .zip(window.rows())
        .map(|(name, i)| {
            let a = net.activations()[i];
            let mut cells = vec![Cell::from(Span::styled(
                name.clone(),
                node_style(theme, a, top),
            ))];
            if let Some(descriptions) = beside {
                cells.push(Cell::from(descriptions[i].clone()));
            }
            cells.extend([
                Cell::from(fit(a, VALUE_WIDTH)),
                Cell::from(deposited.map_or(String::new(), |d| fit(d[i], VALUE_WIDTH))),
                Cell::from(probability_bar(probabilities[i], 6)),
            ]);
            if let Some((da, dp)) = &edit {
                cells.push(Cell::from(signed(da[i], 4)));
                cells.push(Cell::from(signed(dp[i], 3)));
            }
            let row = Row::new(cells);
            if i == teach.cursor() {
                row.style(theme.cursor())
            } else {
                row
            }
        });
    frame.render_widget(
        Table::new(rows, widths)
            .header(Row::new(header).style(theme.title()))
            .block(
                Block::bordered()
                    .title(Span::styled(title, theme.title()))
                    .title_bottom(
                        Line::styled(window.marker().unwrap_or_default(), theme.title())
                            .right_aligned(),
                    ),
            ),
        area,
    );
}

/// The cells a fixed column takes (a `Min` column its minimum).
fn constraint_width(constraint: Constraint) -> u16 {
    match constraint {
        Constraint::Length(n) | Constraint::Min(n) => n,
        _ => 0,
    }
}

/// The characters of the longest of `names`.
fn name_width_of(names: &[String]) -> u16 {
    names.iter().map(|n| n.chars().count()).max().unwrap_or(0) as u16
}

/// A column for the longest of `names`, within `least..=most` characters (`least` where
/// `most` is smaller).
fn name_width(names: &[String], least: usize, most: usize) -> u16 {
    usize::from(name_width_of(names)).min(most).max(least) as u16
}

/// Characters of an activation in the table.
const VALUE_WIDTH: usize = 10;

/// `x` in at most `width` characters: six decimals as the hand computations have them
/// (0.833333), fewer as the integer part grows (1639.5420), then an exponent (2.3600e5).
fn fit(x: f64, width: usize) -> String {
    for decimals in (1..=6).rev() {
        let text = format!("{x:.decimals$}");
        if text.chars().count() <= width {
            return text;
        }
    }
    format!("{x:.3e}")
}

/// `+0.8333`, `−0.0120`, ` 0` : a change, signed, 0 plain.
fn signed(x: f64, decimals: usize) -> String {
    if x == 0.0 {
        "0".to_string()
    } else {
        format!("{x:+.decimals$}").replace('-', "−")
    }
}

/// The knobs (`1`…`5`, the chosen one marked), and the last edit's effect or the notice.
fn edits_paragraph(teach: &Teach, theme: Theme) -> Paragraph<'static> {
    let names = teach.names();
    let edge = teach.selected_edge();
    let mut knobs = Vec::new();
    for knob in Knob::ALL {
        let symbol = match (knob, edge) {
            (Knob::EdgeWeight, Some((i, j))) => format!("M({},{})", names[i], names[j]),
            _ => knob.symbol().to_string(),
        };
        let text = format!("{} {symbol} {}", knob.key(), knob.value(teach.net(), edge));
        if !knobs.is_empty() {
            knobs.push(Span::raw(" · "));
        }
        knobs.push(if knob == teach.knob() {
            Span::styled(text, theme.title().add_modifier(Modifier::REVERSED))
        } else {
            Span::raw(text)
        });
    }
    let mut lines = vec![Line::from(knobs)];
    if let Some(notice) = teach.notice() {
        lines.push(Line::styled(notice.to_string(), theme.stopped()));
    } else if let Some(report) = teach.last_edit() {
        lines.push(Line::from(edit_summary(report, names)));
    }
    Paragraph::new(lines)
        .wrap(Wrap { trim: false })
        .block(Block::bordered().title(Span::styled(
            " edit (1–5 choose, +/− turn, e edge) ",
            theme.title(),
        )))
}

/// `T_ω 1 → 0.9: π1's walk 21 → 9 calls, restarted · at its end A moved most at π0
/// (−0.83), P(π1) 0.45 → 0.52`.
fn edit_summary(report: &EditReport, names: &[String]) -> String {
    let what = match report.edge {
        Some((i, j)) => format!("M({},{})", names[i], names[j]),
        None => report.knob.symbol().to_string(),
    };
    let mut text = format!("{what} {} → {}", report.from, report.to);
    let Some(policy) = report.policy else {
        let (i, dp) = largest(&report.probability_change());
        if dp != 0.0 {
            text.push_str(&format!(": P({}) moved {}", names[i], signed(dp, 3)));
        }
        return text;
    };
    text.push_str(&format!(
        ": {}'s walk {} → {} calls, restarted",
        names[policy], report.calls.0, report.calls.1
    ));
    let (i, da) = largest(&report.activation_change());
    if da != 0.0 {
        text.push_str(&format!(" · at its end A[{}] {}", names[i], signed(da, 4)));
    }
    let (j, dp) = largest(&report.probability_change());
    if dp != 0.0 {
        text.push_str(&format!(", P({}) {}", names[j], signed(dp, 3)));
    }
    text
}

/// The index and value of the change largest in size.
fn largest(changes: &[f64]) -> (usize, f64) {
    changes
        .iter()
        .copied()
        .enumerate()
        .fold(
            (0, 0.0),
            |best, (i, x)| if x.abs() > best.1.abs() { (i, x) } else { best },
        )
}

#[cfg(test)]
mod tests {
    use super::fit;

    #[test]
    fn activations_fit_their_column() {
        assert_eq!(fit(0.833_333_3, 10), "0.833333");
        assert_eq!(fit(1639.542, 10), "1639.54200");
        assert_eq!(fit(-1639.542, 10), "-1639.5420");
        assert_eq!(fit(236_000.5, 10), "236000.500");
        assert_eq!(fit(2.36e12, 10), "2.360e12");
    }
}
