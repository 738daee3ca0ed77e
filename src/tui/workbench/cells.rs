//! What the workbench's views share: a cell of a fixed width, a panel's inside, each
//! method's colour.

use ratatui::layout::Rect;
use ratatui::style::Style;

use crate::results::folder_state::FolderState;
use crate::tui::theme::Theme;

/// `text` cut or padded to exactly `width` columns (a cut ends in `…`).
pub fn fit(text: &str, width: usize) -> String {
    let count = text.chars().count();
    if count <= width {
        format!("{text:<width$}")
    } else if width == 0 {
        String::new()
    } else {
        let cut: String = text.chars().take(width - 1).collect();
        format!("{cut}…")
    }
}

/// `1 run`, `20 runs`: a count and its noun, singular for one.
pub fn counted(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// `3 of 20 runs finished`, `0 of 1 run finished`.
pub fn runs_finished(finished: usize, planned: usize) -> String {
    format!("{finished} of {} finished", counted(planned, "run"))
}

/// The kind of each method of the folder's protocol, in its order.
pub fn method_kinds(folder: &FolderState) -> Vec<crate::reuse::MethodKind> {
    folder
        .config
        .protocol
        .methods
        .iter()
        .map(|m| m.kind())
        .collect()
}

/// The style of each method of `kinds`, in its order: its family's hue, members of a
/// family in turn a shade apart ([`Theme::method`]).
pub fn method_styles(kinds: &[crate::reuse::MethodKind], theme: Theme) -> Vec<Style> {
    kinds
        .iter()
        .enumerate()
        .map(|(i, kind)| {
            let member = kinds[..i]
                .iter()
                .filter(|k| k.family == kind.family)
                .count();
            theme.method(*kind, member)
        })
        .collect()
}

/// A rectangle's inside, below a one-line title row and within its borders.
pub fn inner(area: Rect) -> Rect {
    Rect {
        x: area.x + 1,
        y: area.y + 1,
        width: area.width.saturating_sub(2),
        height: area.height.saturating_sub(2),
    }
}
