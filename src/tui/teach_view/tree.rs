//! The walk as a tree: each `spread` call under the call that made it (Algorithm 2's
//! recursion), with h, Ω, η and ΔA; the latest call highlighted, the next marked, the
//! calls still pending listed after the made ones in the order they will be made.

use ratatui::layout::Rect;
use ratatui::style::Modifier;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph};
use ratatui::Frame;

use crate::sapnet::{Call, TraceStep};
use crate::teach::{labels, Teach};
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;

/// Draws the walk's calls as a tree in `area`.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme, title: &str) {
    let block = Block::bordered().title(Span::styled(format!(" {title} "), theme.title()));
    let Some(walk) = teach.walk() else {
        let hint = Line::styled("no walk yet: a activates the picked policy", theme.dim());
        frame.render_widget(Paragraph::new(hint).block(block), area);
        return;
    };
    let names = labels::labels(teach.names());
    // Depth first: every pending call comes after every made one, the top of the
    // recursion's stack (its last) first.
    let pending: Vec<&Call> = walk.pending.iter().rev().collect();
    let made = walk.trace.len();
    let total = 1 + made + pending.len();
    let latest = made; // row 0 is the activation itself
    let window = RowWindow::new(
        total,
        usize::from(area.height.saturating_sub(2)),
        [latest, (latest + 1).min(total - 1)],
    );
    let lines: Vec<Line> = window
        .rows()
        .map(|row| match row {
            0 => Line::styled(
                format!("{} activated: A += 𝒜 (eq. 8)", names[walk.policy]),
                theme.active(),
            ),
            r if r <= made => {
                let line = made_line(&walk.trace[r - 1], &names, theme);
                if r == latest {
                    line.style(theme.title().add_modifier(Modifier::REVERSED))
                } else {
                    line
                }
            }
            r => pending_line(pending[r - made - 1], &names, r == made + 1, theme),
        })
        .collect();
    let marker = window.marker().unwrap_or_default();
    frame.render_widget(
        Paragraph::new(lines)
            .block(block.title_bottom(Line::styled(marker, theme.title()).right_aligned())),
        area,
    );
}

/// Two spaces a level, so that a call sits under the call that made it.
fn indent(h: usize) -> String {
    "  ".repeat(h.saturating_sub(1).min(12))
}

fn made_line(step: &TraceStep, names: &[String], theme: Theme) -> Line<'static> {
    let head = format!(
        "{}└ {}→{} h {} Ω {:.2} η {:.4} ",
        indent(step.h),
        names[step.from],
        names[step.to],
        step.h,
        step.omega,
        step.eta
    );
    let delta = if step.stopped {
        Span::styled("stopped", theme.stopped())
    } else {
        Span::raw(format!("ΔA {:.6}", step.delta))
    };
    Line::from(vec![Span::raw(head), delta])
}

fn pending_line(call: &Call, names: &[String], next: bool, theme: Theme) -> Line<'static> {
    let mark = if next { "▶ next" } else { "… pending" };
    Line::styled(
        format!(
            "{}└ {}→{} h {} Ω {:.2} η {:.4} {mark}",
            indent(call.h),
            names[call.from],
            names[call.to],
            call.h,
            call.omega,
            call.eta
        ),
        theme.dim(),
    )
}
