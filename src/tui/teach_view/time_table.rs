//! A and P of every policy through time: a row per policy, a column per walk (after each
//! activation's walk, the decay D between two said in the title), the latest walks kept
//! where they do not all fit, and the picked policy's row where the rows do not (the
//! border counts the others); the walk in progress marked.

use ratatui::layout::{Constraint, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Cell, Paragraph, Row, Table};
use ratatui::Frame;

use super::figures::name_width;
use crate::teach::{labels, Teach};
use crate::tui::row_window::RowWindow;
use crate::tui::theme::Theme;

/// A walk's column: `A` to four decimals and `P` to two.
const COLUMN: u16 = 13;

/// Draws the table in `area`.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme, title: &str) {
    let (rows, in_progress) = teach.through_time();
    // `title` is `through time (v: trace)`: A and P go before it, D after the time.
    let title = format!(
        " A (P) {}",
        title.replacen(
            "through time",
            &format!("through time, D = {}", teach.decay()),
            1
        )
    ) + " ";
    let block = Block::bordered().title(Span::styled(title, theme.title()));
    if rows.is_empty() {
        let hint = "no walk yet: a activates the picked policy, each a after it adds a column";
        frame.render_widget(Paragraph::new(hint).style(theme.dim()).block(block), area);
        return;
    }
    let names = labels::labels(teach.names());
    let width = name_width(&names, 4, 12);
    let room = area.width.saturating_sub(2 + width + 1) / (COLUMN + 1);
    let shown = usize::from(room.max(1)).min(rows.len());
    let first = rows.len() - shown;
    let header = std::iter::once(Cell::from("")).chain((first..rows.len()).map(|t| {
        let mark = if in_progress && t + 1 == rows.len() {
            "…"
        } else {
            ""
        };
        Cell::from(format!("{}:{}{mark}", t + 1, names[rows[t].activated]))
    }));
    // The policies' rows that fit under the header, the picked one kept in view (the
    // arrows scroll it) and marked.
    let window = RowWindow::new(
        names.len(),
        usize::from(area.height.saturating_sub(3)),
        [teach.cursor()],
    );
    let body = window.rows().map(|i| {
        let row = Row::new(std::iter::once(Cell::from(names[i].clone())).chain(
            rows[first..].iter().map(|row| {
                Cell::from(format!(
                    "{:.4} ({:.2})",
                    row.activations[i], row.probabilities[i]
                ))
            }),
        ));
        if i == teach.cursor() {
            row.style(theme.cursor())
        } else {
            row
        }
    });
    let widths = std::iter::once(Constraint::Length(width))
        .chain(std::iter::repeat_n(Constraint::Length(COLUMN), shown));
    let left_out = left_out(first, &window);
    frame.render_widget(
        Table::new(body, widths)
            .header(Row::new(header).style(theme.title()))
            .block(block.title_bottom(Line::styled(left_out, theme.title()).right_aligned())),
        area,
    );
}

/// ` ◀ 1 earlier · ▼ 6 more `: the walks and the policies left out, for the bottom border.
fn left_out(earlier: usize, window: &RowWindow) -> String {
    let parts: Vec<String> = (earlier > 0)
        .then(|| format!("◀ {earlier} earlier"))
        .into_iter()
        .chain(window.marker().map(|m| m.trim().to_string()))
        .collect();
    if parts.is_empty() {
        String::new()
    } else {
        format!(" {} ", parts.join(" · "))
    }
}
