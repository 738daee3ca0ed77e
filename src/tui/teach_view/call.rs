//! The call panel: the `spread` call about to be made, with eq. 10's test and the
//! arithmetic of eq. 9–10, beside the one just made.

use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Wrap};

use crate::teach::Teach;
use crate::tui::theme::Theme;

/// The call about to be made, with eq. 10's test, beside the one just made.
pub(super) fn paragraph(teach: &Teach, theme: Theme) -> Paragraph<'static> {
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
