//! The call panel: the `spread` call about to be made, with eq. 10's test and the
//! arithmetic of eq. 9–10, beside the one just made. In the exercise the test's outcome
//! and ΔA are what the student is asked: they are held back until answered (the call is
//! then made, and the edit panel and the trace say them).
//!
//! Products are written `×` and nothing else is: `·` would read as one too (`A += 1 · k`
//! read "A += 1·k").

use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Wrap};

use crate::sapnet::{Call, TraceStep};
use crate::teach::Teach;
use crate::tui::theme::Theme;

/// The call about to be made, with eq. 10's test, beside the one just made (where the
/// panel of `width` columns is wide enough: on a narrow one the trace's last row says it).
pub(super) fn paragraph(teach: &Teach, theme: Theme, width: u16) -> Paragraph<'static> {
    let walk = teach.walk();
    let state = walk.as_ref().map(|w| WalkState {
        policy: w.policy,
        made: w.trace.last().copied(),
        next: w.pending.last().copied(),
        calls_made: w.trace.len(),
        calls_pending: w.pending.len(),
    });
    let hide = teach.hides_next_answer();
    framed(lines(teach, state, theme, says_made(width), hide), theme)
}

/// Whether a call panel of `width` columns, its border included, says the call just made.
fn says_made(width: u16) -> bool {
    width >= 50
}

/// Rows the panel needs at `width` (its border included) for the tallest text any call of
/// this lesson can give: the call made and the next one each depositing or stopped,
/// between the longest-named policies, with three-digit counts (a longer walk may take a
/// row more), the exercise's question or not. The panel keeps this height whatever the
/// call on screen, so that the graph above it does not change height (and its nodes do
/// not jump) from step to step, nor when the exercise starts.
pub(super) fn tallest_rows(teach: &Teach, width: u16) -> u16 {
    let names = teach.names();
    let mut by_length: Vec<usize> = (0..names.len()).collect();
    by_length.sort_by_key(|&i| std::cmp::Reverse(names[i].chars().count()));
    let (longest, next_longest) = match by_length[..] {
        [a, b, ..] => (a, b),
        [a] => (a, a),
        [] => return 2,
    };
    let call = Call {
        from: next_longest,
        to: longest,
        h: 9,
        omega: 0.987_654,
        eta: 0.123_456,
    };
    let made = TraceStep {
        from: call.from,
        to: call.to,
        h: call.h,
        omega: call.omega,
        eta: call.eta,
        delta: 0.123_456,
        stopped: false,
    };
    let threshold = teach.net().params().threshold;
    // Below any threshold the net accepts, so the test passes and every line is written;
    // or at it, so the test fails and says so at length.
    let passing = Call {
        omega: threshold / 2.0,
        ..call
    };
    let stopping = Call {
        omega: threshold,
        ..call
    };
    let stopped = TraceStep {
        stopped: true,
        delta: 0.0,
        ..made
    };
    let rows = |p: &Paragraph| p.line_count(width.saturating_sub(2));
    let mut tallest = rows(&paragraph(teach, Theme::plain(), width));
    for made in [made, stopped] {
        for next in [passing, stopping] {
            for hide in [false, true] {
                let state = WalkState {
                    policy: longest,
                    made: Some(made),
                    next: Some(next),
                    calls_made: 999,
                    calls_pending: 999,
                };
                let text = lines(teach, Some(state), Theme::plain(), says_made(width), hide);
                tallest = tallest.max(rows(&framed(text, Theme::plain())));
            }
        }
    }
    u16::try_from(tallest).unwrap_or(u16::MAX)
}

/// What the panel writes of a walk.
#[derive(Debug, Clone, Copy)]
struct WalkState {
    policy: usize,
    made: Option<TraceStep>,
    next: Option<Call>,
    calls_made: usize,
    calls_pending: usize,
}

fn framed(lines: Vec<Line<'static>>, theme: Theme) -> Paragraph<'static> {
    Paragraph::new(lines)
        .wrap(Wrap { trim: false })
        .block(Block::bordered().title(Span::styled(" the call ", theme.title())))
}

/// The panel's text: the call just made (where `says_made`), then the next call (its
/// outcome held back where `hide`), or what to do without one.
fn lines(
    teach: &Teach,
    walk: Option<WalkState>,
    theme: Theme,
    says_made: bool,
    hide: bool,
) -> Vec<Line<'static>> {
    let names = teach.names();
    let mut lines = Vec::new();
    if let Some(made) = walk.and_then(|w| w.made).filter(|_| says_made) {
        lines.push(made_line(made, names, theme));
    }
    match walk {
        None => lines.push(Line::from(
            "Pick a policy with ↑↓ and press a to activate it: A[i] += 𝒜 (eq. 8).",
        )),
        Some(walk) => match walk.next {
            Some(call) => lines.extend(next_lines(teach, walk, call, theme, hide)),
            None => lines.push(Line::from(format!(
                "spreading from {} is done: {} calls. a activates again, u undoes, c resets.",
                names[walk.policy], walk.calls_made
            ))),
        },
    }
    lines
}

/// `made: spread(π0, h 1, Ω 0.4000) from π1: ΔA 0.833333`, or `stopped`.
fn made_line(made: TraceStep, names: &[String], theme: Theme) -> Line<'static> {
    let outcome = if made.stopped {
        "stopped (Ω ≥ T_ω)".to_string()
    } else {
        format!("ΔA {:.6}", made.delta)
    };
    Line::styled(
        format!(
            "made: spread({}, h {}, Ω {:.4}) from {}: {outcome}",
            names[made.to], made.h, made.omega, names[made.from]
        ),
        theme.dim(),
    )
}

/// The call about to be made (Algorithm 2), eq. 10's test and deposit (or, in the
/// exercise, the question they answer), and eq. 8's activation it comes from.
fn next_lines(
    teach: &Teach,
    walk: WalkState,
    call: Call,
    theme: Theme,
    hide: bool,
) -> Vec<Line<'static>> {
    let names = teach.names();
    let params = teach.net().params();
    let mut lines = vec![Line::from(format!(
        "next (Alg. 2): spread({}, h {}, Ω {:.4}, η {:.6}) from {}",
        names[call.to], call.h, call.omega, call.eta, names[call.from]
    ))];
    if hide {
        lines.extend(asked_lines(teach, call, theme));
    } else {
        lines.extend(outcome_lines(teach, call, theme));
    }
    lines.push(Line::styled(
        format!(
            "eq. 8: A[{}] += 𝒜 = {}; k = {}; calls {} made, {} pending",
            names[walk.policy],
            params.coefficient,
            teach.net().graph().degree(walk.policy),
            walk.calls_made,
            walk.calls_pending,
        ),
        theme.dim(),
    ));
    lines
}

/// Eq. 10's test, and the deposit it allows: ΔA = η/(h×Ω), then η/k onward (eq. 9).
fn outcome_lines(teach: &Teach, call: Call, theme: Theme) -> Vec<Line<'static>> {
    let names = teach.names();
    let threshold = teach.net().params().threshold;
    let passes = call.omega < threshold;
    let mut lines = vec![Line::from(vec![
        Span::raw(format!(
            "eq. 10: Ω < T_ω: {:.4} < {threshold} is ",
            call.omega
        )),
        if passes {
            Span::styled("true", theme.active())
        } else {
            Span::styled("false: the call stops (eq. 10)", theme.stopped())
        },
    ])];
    if passes {
        lines.push(Line::from(format!(
            "eq. 10: ΔA[{}] = η/(h×Ω) = {:.6}/({}×{:.4}) = {:.6}",
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
    lines
}

/// In the exercise: eq. 10's test and deposit as the question `s` asks, their outcome
/// left for the student.
fn asked_lines(teach: &Teach, call: Call, theme: Theme) -> Vec<Line<'static>> {
    let threshold = teach.net().params().threshold;
    vec![
        Line::from(vec![
            Span::raw(format!(
                "eq. 10: Ω < T_ω: {:.4} < {threshold} is ",
                call.omega
            )),
            Span::styled("?", theme.active()),
        ]),
        Line::styled(
            format!(
                "exercise: ΔA[{}] = η/(h×Ω) = ?, or does the call stop?",
                teach.names()[call.to]
            ),
            theme.active(),
        ),
    ]
}
