//! What every screen of the terminal UI shares, the dashboard and teach mode alike: the
//! smallest terminal the layouts fit and the note drawn on a smaller one, the keys'
//! overlay (`?`), and the bar a probability is drawn as.

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Wrap};
use ratatui::Frame;

use super::theme::Theme;

/// The smallest terminal the layouts fit.
pub const MIN_WIDTH: u16 = 80;
pub const MIN_HEIGHT: u16 = 24;

/// Draws a note instead of the screen when `area` is smaller than the layouts fit, and says
/// whether it did.
pub fn too_small(frame: &mut Frame, area: Rect) -> bool {
    if area.width >= MIN_WIDTH && area.height >= MIN_HEIGHT {
        return false;
    }
    let text = format!(
        "This terminal is {}×{}; sapnet needs at least {MIN_WIDTH}×{MIN_HEIGHT}. Enlarge it, or press q to quit.",
        area.width, area.height
    );
    let [middle] = Layout::vertical([Constraint::Length(3)])
        .flex(ratatui::layout::Flex::Center)
        .areas(area);
    frame.render_widget(
        Paragraph::new(text)
            .wrap(Wrap { trim: true })
            .alignment(ratatui::layout::Alignment::Center),
        middle,
    );
    true
}

/// `P` as a bar of `width` cells and its value, e.g. `██████░░░░ 0.61`.
pub fn probability_bar(p: f64, width: usize) -> String {
    let filled = ((p.clamp(0.0, 1.0) * width as f64).round() as usize).min(width);
    format!(
        "{}{} {p:.2}",
        "█".repeat(filled),
        "░".repeat(width - filled)
    )
}

/// The width of the help's key column, with the two spaces after it.
const HELP_KEYS: usize = 20;

/// The keys' overlay over `area`: each key beside what it does, centred.
pub fn draw_help(frame: &mut Frame, area: Rect, keys: &[(&str, &str)], theme: Theme) {
    let width = 76.min(area.width);
    // What a key does wraps under itself, beside the keys' column.
    let room = usize::from(width.saturating_sub(2)).saturating_sub(HELP_KEYS);
    let mut lines: Vec<Line> = Vec::new();
    for (key, what) in keys {
        for (k, part) in wrap_words(what, room).into_iter().enumerate() {
            let key = if k == 0 { *key } else { "" };
            lines.push(Line::from(vec![
                Span::styled(format!("{key:>w$}  ", w = HELP_KEYS - 2), theme.title()),
                Span::raw(part),
            ]));
        }
    }
    let height = (lines.len() as u16 + 4).min(area.height);
    let [row] = Layout::vertical([Constraint::Length(height)])
        .flex(ratatui::layout::Flex::Center)
        .areas(area);
    let [popup] = Layout::horizontal([Constraint::Length(width)])
        .flex(ratatui::layout::Flex::Center)
        .areas(row);
    frame.render_widget(Clear, popup);
    frame.render_widget(
        Paragraph::new(lines).block(
            Block::bordered()
                .title(Span::styled(" keys ", theme.title()))
                .border_style(theme.title()),
        ),
        popup,
    );
}

/// `text` in lines of at most `width` columns, broken between words (a word longer than
/// the width has a line of its own).
fn wrap_words(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split(' ') {
        let line = lines.last_mut().expect("one line at least");
        let wanted = Line::from(line.as_str()).width() + 1 + Line::from(word).width();
        if line.is_empty() {
            line.push_str(word);
        } else if wanted <= width {
            line.push(' ');
            line.push_str(word);
        } else {
            lines.push(word.to_string());
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::wrap_words;

    #[test]
    fn help_lines_wrap_between_words() {
        assert_eq!(
            wrap_words("the weight M of an edge", 14),
            ["the weight M", "of an edge"]
        );
        assert_eq!(wrap_words("quit", 14), ["quit"]);
        assert_eq!(wrap_words("", 14), [""]);
    }
}
