//! The recursion's stack (Algorithm 2): the pending `spread` calls, the next on top.

use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph};
use ratatui::Frame;

use crate::teach::Teach;
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;

/// The recursion's stack: pending calls, the next on top.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
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
