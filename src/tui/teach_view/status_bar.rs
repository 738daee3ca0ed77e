//! Stand-alone teach mode's bottom line: the policies' numbering, if `p` changes it, and
//! the keys (on the dashboard, the dashboard's status bar stands in its place).

use ratatui::layout::Rect;
use ratatui::style::Modifier;
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;
use ratatui::Frame;

use crate::teach::Teach;
use crate::tui::theme::Theme;

const TEACH_HINTS: &str =
    "↑↓ pick · a activate · s step · r run · u undo · c reset · 1–5 +/− edit · ? help · q quit";
const TEACH_HINTS_SHORT: &str = "↑↓ a s r u c · 1–5 +/− e · ? help · q quit";

/// Draws the status line of `teach` in `area`, a row as wide as the screen.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
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
    frame.render_widget(Paragraph::new(line), area);
}
