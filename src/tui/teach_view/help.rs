//! Teach mode's keys, for its `?` overlay (drawn by [`crate::tui::screen::draw_help`]),
//! alone or on the dashboard.

use crate::teach::Teach;
use crate::tui::teach_keys;

/// Teach mode's keys for its `?`: its table's lines ([`crate::tui::teach_keys`]), then
/// what the screen adds. Esc quits stand-alone teach mode, and on the dashboard goes back
/// to it.
pub(crate) fn teach_help(
    teach: &Teach,
    on_the_dashboard: bool,
) -> Vec<(&'static str, &'static str)> {
    let mut keys = teach_keys::help_lines(teach);
    keys.push(("?", "this help (any key closes it)"));
    if on_the_dashboard {
        keys.extend([
            ("t / Esc", "back to the paused dashboard"),
            ("q / Ctrl-C", "quit"),
        ]);
    } else {
        keys.push(("q / Esc / Ctrl-C", "quit"));
    }
    keys
}
