//! The terminal UI: a protocol run in the workbench (its views, and the live dashboard of
//! the run it follows, over the trainer's event stream), a results or sweep folder opened
//! in it, and teach mode.
//!
//! The UI thread only reads keys, drains events and draws; training runs on the trainer's
//! threads and never waits for the screen. Each frame drains the whole channel (never
//! parking on it, so a send never has to wake this thread) and draws at most
//! [`FRAME`]ly.
//!
//! - [`event_loop`]: the one loop every workbench screen runs in; [`view`]: the shape of a
//!   view (draw, keys, commands, intents); [`keys`]: a view's one key table, which its
//!   matcher, its status bar and its `?` are all made from.
//! - [`dashboard`]: what the UI keeps of a run's stream and what its keys do (teach mode's
//!   keys too: its state, [`Teach`], lives in [`crate::teach`], which draws nothing).
//! - [`reference`]: a finished protocol's bands beside the live run (`--compare`).
//! - [`row_window`]: which rows a table too long for its panel shows.
//! - [`dashboard_view`], [`teach_view`]: drawing each screen, a file per panel, as pure
//!   functions of that state; they also tell what a click landed on
//!   ([`dashboard_view::clicked`]), in the rectangles they draw in. Both draw the graph
//!   with [`graph_view`] and share [`screen`] (the smallest terminal, the keys' overlay);
//!   the dashboard's view draws teach mode on the live graph with `teach_view`, never the
//!   reverse.
//! - [`workbench`]: `sapnet` (a protocol trained and watched in views, one run followed
//!   in the Run view), `sapnet open DIR` (a results folder, live or not) and `sapnet open
//!   SWEEP` (a sweep's cells), as views on screens.
//! - [`graph_layout`]: the graph's geometry, which the state (moving the cursor) and the
//!   views share. The state modules import no view.
//!
//! - [`teach_screen`]: stand-alone teach mode ([`run_teach`]), a screen of the same loop;
//!   [`teach_keys`]: teach mode's one key table, alone or on the dashboard.

pub mod background;
pub mod dashboard;
pub mod dashboard_view;
pub mod event_loop;
pub mod follow;
pub mod graph_layout;
pub mod graph_view;
pub mod keys;
pub mod reference;
pub mod row_window;
pub mod screen;
pub mod teach_keys;
pub mod teach_screen;
pub mod teach_view;
pub mod theme;
pub mod view;
pub mod workbench;

use std::time::Duration;

use anyhow::{Context, Result};

use crate::teach::Teach;
use dashboard::Dashboard;
use teach_screen::TeachScreen;
use theme::Theme;

/// The time between frames: about 30 per second.
pub const FRAME: Duration = Duration::from_millis(33);

/// Leaves the alternate screen and raw mode, and stops mouse reporting, however the UI
/// ends; ratatui's panic hook restores the screen for panics, and the unwinding drops this.
pub(crate) struct TerminalGuard;

impl Drop for TerminalGuard {
    fn drop(&mut self) {
        crate::signals::set_interactive(false);
        let _ = crossterm::execute!(std::io::stdout(), crossterm::event::DisableMouseCapture);
        ratatui::restore();
    }
}

/// Raw mode, the alternate screen and mouse reporting (clicks pick a node or a row),
/// with the guard that leaves them. If opening fails half-way, raw mode is undone here
/// (nothing else was changed yet).
pub(crate) fn open_terminal() -> Result<(ratatui::DefaultTerminal, TerminalGuard)> {
    match ratatui::try_init() {
        Ok(terminal) => {
            crate::signals::set_interactive(true);
            let guard = TerminalGuard;
            crossterm::execute!(std::io::stdout(), crossterm::event::EnableMouseCapture)
                .context("turning on mouse reporting")?;
            Ok((terminal, guard))
        }
        Err(err) => {
            let _ = crossterm::terminal::disable_raw_mode();
            Err(err).context(
                "opening the terminal UI (without a terminal, use --headless, or teach --headless)",
            )
        }
    }
}

/// A left click on a screen of `area` showing `dashboard`: the view that drew it tells
/// what the click landed on, the dashboard acts on it.
pub fn click(dashboard: &mut Dashboard, area: ratatui::layout::Rect, column: u16, row: u16) {
    if let Some(clicked) = dashboard_view::clicked(dashboard, area, column, row) {
        dashboard.on_click(clicked);
    }
}

/// Runs stand-alone teach mode until the user quits.
pub fn run_teach(teach: Teach) -> Result<()> {
    event_loop::show(&mut TeachScreen::new(teach, Theme::from_env()))
}

#[cfg(test)]
mod tests {
    /// The state owns the data and the views draw it: no state module reaches into a view
    /// (they once imported each other in a ring, dashboard ↔ view ↔ teach_view ↔ step_line).
    #[test]
    fn the_state_modules_import_no_view() {
        let state = [
            ("dashboard/mod.rs", include_str!("dashboard/mod.rs")),
            ("dashboard/keys.rs", include_str!("dashboard/keys.rs")),
            (
                "dashboard/live_curve.rs",
                include_str!("dashboard/live_curve.rs"),
            ),
            (
                "dashboard/run_views.rs",
                include_str!("dashboard/run_views.rs"),
            ),
            ("follow.rs", include_str!("follow.rs")),
            ("reference.rs", include_str!("reference.rs")),
            ("row_window.rs", include_str!("row_window.rs")),
            ("graph_layout.rs", include_str!("graph_layout.rs")),
            ("teach_keys.rs", include_str!("teach_keys.rs")),
        ];
        for (file, text) in state {
            for view in ["dashboard_view", "teach_view", "graph_view", "screen"] {
                for path in [format!("super::{view}"), format!("tui::{view}")] {
                    assert!(
                        !text.contains(&format!("{path}::")) && !text.contains(&format!("{path};")),
                        "{file} uses {path}"
                    );
                }
            }
        }
    }

    /// The screens' views meet in one direction only: the dashboard's draws teach mode on
    /// the live graph with teach mode's. Teach mode's panels, and what both views draw with,
    /// name neither screen above them (`view.rs` and `teach_view.rs` once imported each
    /// other).
    #[test]
    fn the_views_import_each_other_one_way() {
        let below_the_dashboard = [
            ("screen.rs", include_str!("screen.rs")),
            ("graph_view.rs", include_str!("graph_view.rs")),
            ("theme.rs", include_str!("theme.rs")),
            ("teach_view/mod.rs", include_str!("teach_view/mod.rs")),
            ("teach_view/call.rs", include_str!("teach_view/call.rs")),
            ("teach_view/edits.rs", include_str!("teach_view/edits.rs")),
            (
                "teach_view/figures.rs",
                include_str!("teach_view/figures.rs"),
            ),
            (
                "teach_view/graph_panel.rs",
                include_str!("teach_view/graph_panel.rs"),
            ),
            ("teach_view/help.rs", include_str!("teach_view/help.rs")),
            ("teach_view/stack.rs", include_str!("teach_view/stack.rs")),
            (
                "teach_view/status_bar.rs",
                include_str!("teach_view/status_bar.rs"),
            ),
            ("teach_view/trace.rs", include_str!("teach_view/trace.rs")),
            ("teach_view/values.rs", include_str!("teach_view/values.rs")),
        ];
        for (file, text) in below_the_dashboard {
            let mut above = vec!["dashboard_view"];
            if !file.starts_with("teach_view/") {
                above.push("teach_view");
            }
            for view in above {
                assert!(!text.contains(&format!("{view}::")), "{file} uses {view}");
                assert!(!text.contains(&format!("::{view};")), "{file} uses {view}");
            }
        }
    }
}
