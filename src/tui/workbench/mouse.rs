//! The mouse in the workbench: a left click on a view's name in the status bar shows
//! that view; on a run's line (Runs) or a method's row (Comparison) picks it; on a
//! method's line of the Curves view's legend picks it and shows or hides it. Where a
//! click lands is worked out by the views' own layouts, so it picks what was drawn there.

use crossterm::event::{MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;

use super::state::{View, Workbench};
use super::{comparison_view, curves_view, runs_view};

/// Acts on a mouse event on a screen of `screen`'s size; whether it changed anything.
pub fn on_mouse(workbench: &mut Workbench, event: MouseEvent, screen: Rect) -> bool {
    if event.kind != MouseEventKind::Down(MouseButton::Left) || workbench.help {
        return false;
    }
    let (column, row) = (event.column, event.row);
    if row + 1 == screen.height {
        return match view_at(column) {
            Some(view) => {
                workbench.view = view;
                true
            }
            None => false,
        };
    }
    // The views' body: below the folder's line, above the status bar.
    let body = Rect {
        x: screen.x,
        y: screen.y + 1,
        width: screen.width,
        height: screen.height.saturating_sub(2),
    };
    match workbench.view {
        View::Runs => match runs_view::run_at(body, workbench, column, row) {
            Some(run) => {
                workbench.run_cursor = run;
                true
            }
            None => false,
        },
        View::Comparison => match comparison_view::method_at(body, workbench, column, row) {
            Some(method) => {
                workbench.method_cursor = method;
                true
            }
            None => false,
        },
        View::Curves => match curves_view::legend_method_at(body, workbench, column, row) {
            Some(method) => {
                workbench.curves.cursor = method;
                workbench.curves.toggle(method);
                true
            }
            None => false,
        },
    }
}

/// The view whose name in the status bar is at `column`: the bar starts with a space,
/// then each view's key, a space, its name and two spaces ([`super::view`]).
pub fn view_at(column: u16) -> Option<View> {
    let mut start = 1u16;
    for view in View::ALL {
        let (_, name) = view.key();
        let end = start + 2 + name.chars().count() as u16;
        if (start..end).contains(&column) {
            return Some(view);
        }
        start = end + 2;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_status_bar_names_each_view_where_it_is_drawn() {
        // " r runs  c comparison  v curves  │ …"
        assert_eq!(view_at(0), None);
        assert_eq!(view_at(1), Some(View::Runs));
        assert_eq!(view_at(6), Some(View::Runs));
        assert_eq!(view_at(7), None);
        assert_eq!(view_at(9), Some(View::Comparison));
        assert_eq!(view_at(20), Some(View::Comparison));
        assert_eq!(view_at(23), Some(View::Curves));
        assert_eq!(view_at(30), Some(View::Curves));
        assert_eq!(view_at(31), None);
    }
}
