//! Which rows of a table too long for its panel are shown: the rows that matter (the
//! picked policy, then the acting one) are kept in view, and the panel says how many rows
//! it hides.
//!
//! The window is a pure function of the table's length, its room and the rows to keep, so
//! drawing and mouse clicks compute the same one and a click picks the row it lands on.

/// A run of consecutive rows of a table, `first..first + shown` of `total`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowWindow {
    pub first: usize,
    pub shown: usize,
    pub total: usize,
}

impl RowWindow {
    /// The rows of a table of `total` rows that fit in `room` lines, keeping in view as
    /// many of `keep` as fit together, in their order of priority (the first always). The
    /// window starts as high as it can, so that it moves only when a kept row would leave it.
    pub fn new(total: usize, room: usize, keep: impl IntoIterator<Item = usize>) -> Self {
        let shown = total.min(room);
        let mut span: Option<(usize, usize)> = None;
        for row in keep.into_iter().filter(|&r| r < total) {
            let (low, high) = span.map_or((row, row), |(l, h)| (l.min(row), h.max(row)));
            if high - low < shown {
                span = Some((low, high));
            }
        }
        let first = span.map_or(0, |(_, high)| (high + 1).saturating_sub(shown));
        Self {
            first,
            shown,
            total,
        }
    }

    /// The shown rows' indices.
    pub fn rows(&self) -> std::ops::Range<usize> {
        self.first..self.first + self.shown
    }

    pub fn hidden_above(&self) -> usize {
        self.first
    }

    pub fn hidden_below(&self) -> usize {
        self.total - self.first - self.shown
    }

    /// The row shown on the `line`-th line of the window (from 0), if any.
    pub fn row_at(&self, line: usize) -> Option<usize> {
        (line < self.shown).then_some(self.first + line)
    }

    /// `▲ 2 more · ▼ 3 more`, or nothing when every row is shown: for the panel's bottom
    /// border.
    pub fn marker(&self) -> Option<String> {
        let mut parts = Vec::new();
        if self.hidden_above() > 0 {
            parts.push(format!("▲ {} more", self.hidden_above()));
        }
        if self.hidden_below() > 0 {
            parts.push(format!("▼ {} more", self.hidden_below()));
        }
        (!parts.is_empty()).then(|| format!(" {} ", parts.join(" · ")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_that_fits_shows_every_row_and_no_marker() {
        let window = RowWindow::new(4, 9, [3]);
        assert_eq!(window.rows(), 0..4);
        assert_eq!(window.marker(), None);
    }

    #[test]
    fn the_kept_row_scrolls_into_view_and_the_rest_is_counted() {
        // Ten rows, nine lines: row 9 kept pushes row 0 out.
        let window = RowWindow::new(10, 9, [9]);
        assert_eq!(window.rows(), 1..10);
        assert_eq!(window.marker().as_deref(), Some(" ▲ 1 more "));
        // A kept row already in view leaves the window at the top.
        let window = RowWindow::new(10, 4, [2]);
        assert_eq!(window.rows(), 0..4);
        assert_eq!(window.marker().as_deref(), Some(" ▼ 6 more "));
        let window = RowWindow::new(10, 4, [6]);
        assert_eq!(window.marker().as_deref(), Some(" ▲ 3 more · ▼ 3 more "));
        assert_eq!((window.row_at(3), window.row_at(4)), (Some(6), None));
    }

    #[test]
    fn the_second_kept_row_is_shown_only_beside_the_first() {
        // Rows 2 and 5 fit in four lines together.
        assert_eq!(RowWindow::new(10, 4, [2, 5]).rows(), 2..6);
        // Rows 0 and 9 do not: the first wins.
        assert_eq!(RowWindow::new(10, 4, [0, 9]).rows(), 0..4);
        assert_eq!(RowWindow::new(10, 4, [9, 0]).rows(), 6..10);
        // Out of range is ignored; no room shows nothing.
        assert_eq!(RowWindow::new(10, 4, [12]).rows(), 0..4);
        assert_eq!(RowWindow::new(10, 0, [3]).rows(), 0..0);
    }
}
