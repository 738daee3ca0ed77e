//! The edit panel: the knobs `1`…`5` (T_ω, 𝒜, τ, paths, an edge's weight M), the chosen
//! one marked, and what the last turn changed, or why it was refused.

use ratatui::style::Modifier;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Wrap};

use super::figures::signed;
use crate::teach::knobs::{EditReport, Knob};
use crate::teach::Teach;
use crate::tui::theme::Theme;

/// The knobs (`1`…`5`, the chosen one marked), and the last edit's effect or the notice.
/// `compact` (a short screen): with an effect or a notice to say, the chosen knob moves to
/// the title and the line of all five gives way to it, so that the trace below keeps its
/// rows.
pub(super) fn paragraph(teach: &Teach, theme: Theme, compact: bool) -> Paragraph<'static> {
    let names = teach.names();
    let edge = teach.selected_edge();
    let knob_text = |knob: Knob| {
        let symbol = match (knob, edge) {
            (Knob::EdgeWeight, Some((i, j))) => format!("M({},{})", names[i], names[j]),
            _ => knob.symbol().to_string(),
        };
        format!("{} {symbol} {}", knob.key(), knob.value(teach.net(), edge))
    };
    let said = if let Some(prompt) = teach.prompt() {
        // A question asked after an answer: the verdict stays in view above it.
        let verdict = teach
            .notice()
            .map(|n| format!("{n} · "))
            .unwrap_or_default();
        Some(Line::styled(
            format!(
                "{verdict}{} {}█  (Enter, Esc cancels)",
                teach.prompt_question().unwrap_or_default(),
                prompt.text
            ),
            theme.active(),
        ))
    } else if let Some(notice) = teach.notice() {
        Some(Line::styled(notice.to_string(), theme.stopped()))
    } else {
        teach
            .last_edit()
            .map(|report| Line::from(edit_summary(report, names)))
    };
    if let (true, Some(said)) = (compact, said.clone()) {
        return Paragraph::new(vec![said]).wrap(Wrap { trim: false }).block(
            Block::bordered().title(Span::styled(
                format!(" edit · {} ", knob_text(teach.knob())),
                theme.title(),
            )),
        );
    }
    let mut knobs = Vec::new();
    for knob in Knob::ALL {
        let text = knob_text(knob);
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
    lines.extend(said);
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
