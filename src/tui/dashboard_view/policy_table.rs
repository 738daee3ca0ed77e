//! The policy table: each source's name, its category or task, its score (A, or A − max A
//! with `v`), P(π) as a bar, how often it acted, its +/− judgments and its scores over the
//! last episodes; the columns give way as the panel narrows.

use ratatui::layout::{Constraint, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Cell, Row, Table};
use ratatui::Frame;

use super::figures::{count, format_score, sparkline};
use crate::reuse::lock_in;
use crate::teach::labels;
use crate::tui::dashboard::{Dashboard, LibraryView, Mode, HISTORY};
use crate::tui::graph_view::{self, node_style};
use crate::tui::row_window::RowWindow;
use crate::tui::screen::probability_bar;
use crate::tui::theme::Theme;

/// "policies", and once the followed run has ended, the source it chose (SAP-Net: the
/// highest activation) and that policy's greedy test returns (their mean, if the list does
/// not fit in `width`).
pub(super) fn title(dashboard: &Dashboard, width: u16) -> String {
    let ended = dashboard.main_run().and_then(|r| r.ended.as_ref());
    match ended.and_then(|record| Some((record, record.chosen.as_ref()?))) {
        Some((record, chosen)) if record.test_returns.is_empty() => format!(
            "policies · chosen {} ({})",
            chosen.name,
            if record.stopped {
                "stopped, not tested"
            } else {
                "not tested"
            }
        ),
        Some((record, chosen)) => {
            let tests: Vec<String> = record
                .test_returns
                .iter()
                .map(|r| format!("{r:.0}"))
                .collect();
            let all = format!(
                "policies · chosen {} · greedy tests {}",
                chosen.name,
                tests.join(" ")
            );
            if all.chars().count() + 4 <= usize::from(width) {
                return all;
            }
            let mean = record.test_returns.iter().sum::<f64>() / record.test_returns.len() as f64;
            format!("policies · chosen {} · test mean {mean:.1}", chosen.name)
        }
        // Lock-in as the table and comparison.csv say it ([`lock_in`]), where it fits.
        None => {
            let measured = dashboard
                .main_run()
                .is_some_and(|r| lock_in::measured(r.method.kind));
            let locked = dashboard.library.as_ref().and_then(|view| {
                let (i, since) = view.locked?;
                Some((view.policies.get(i)?.name.as_str(), since))
            });
            let full = format!(
                "policies · lock-in step {}",
                lock_in::of_run(measured, locked)
            );
            if full.chars().count() + 4 <= usize::from(width) {
                full
            } else {
                "policies".to_string()
            }
        }
    }
}

/// The rows of the policy table that a panel of `area` shows: the cursor's row always,
/// and while paused the acting policy's too. Running, the acting policy changes from frame
/// to frame: a window that followed it would jitter, and a click could land on another row
/// than the one seen, so the bottom border names it when it is hidden instead.
pub(super) fn policy_rows(area: Rect, dashboard: &Dashboard) -> RowWindow {
    let (total, acting) = dashboard
        .library
        .as_ref()
        .map_or((0, None), |v| (v.policies.len(), v.acting));
    // Below the top border and the header, above the bottom border.
    let room = usize::from(area.height.saturating_sub(3));
    let acting = acting.filter(|_| dashboard.mode == Mode::Paused);
    RowWindow::new(total, room, std::iter::once(dashboard.cursor).chain(acting))
}

/// The policy table's width with every column but the history, borders and spacing
/// included, and with the fewest; the narrowest history worth drawing.
const FULL_TABLE_WIDTH: u16 = 72;
const COMPACT_TABLE_WIDTH: u16 = 43;
const MIN_HISTORY_WIDTH: u16 = 10;

/// Draws the table of `view`'s policies in `area`, inside `block`.
pub(super) fn draw(
    frame: &mut Frame,
    area: Rect,
    block: Block,
    view: &LibraryView,
    dashboard: &Dashboard,
    theme: Theme,
) {
    let (cursor, relative) = (dashboard.cursor, dashboard.relative);
    let window = policy_rows(area, dashboard);
    // `v`: each score less the highest, so that saturated activations (2.360e5 beside
    // 2.359e5) still read apart.
    let highest = view
        .net
        .activations()
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let score_header = if relative {
        format!("{}−max", view.score.name)
    } else {
        view.score.name.to_string()
    };
    let top = graph_view::highest(view.net.activations().iter().copied());
    // Columns give way from the right of the wish list as the panel narrows: the graph
    // already shows categories, the counts matter least. Zoomed (`z`), the scores over
    // time come before them: at 80 columns the table keeps the sparkline (as docs/guide/running.md
    // says `z` does) and gives up the hidden layers and the +/− counts.
    let full = area.width >= FULL_TABLE_WIDTH
        && !(dashboard.zoom && area.width < FULL_TABLE_WIDTH + 1 + MIN_HISTORY_WIDTH);
    // A library over several tasks shows each source's task where one task shows the
    // number of hidden layers.
    let tasks = view
        .policies
        .iter()
        .any(|p| p.description.source_task != view.policies[0].description.source_task);
    let bar_width = 8;
    // Each policy's score over the last episodes, on one scale for all (the highest in the
    // window), zoomed (`z`) or on a wide terminal, as many of the last episodes as fit.
    let used = if full {
        FULL_TABLE_WIDTH
    } else {
        COMPACT_TABLE_WIDTH
    };
    let history_width = usize::from(area.width.saturating_sub(used + 1)).min(HISTORY);
    let history = (area.width >= 90 || dashboard.zoom) && history_width >= MIN_HISTORY_WIDTH.into();
    let skipped = view.history.len().saturating_sub(history_width);
    let history_top = graph_view::highest(view.history.iter().flatten().copied());
    let rows = view.policies[window.rows()]
        .iter()
        .zip(window.rows())
        .map(|(p, i)| {
            let a = view.net.activations()[i];
            let probability = view.probabilities.get(i).copied().unwrap_or(0.0);
            let mut name = Span::styled(p.name.clone(), node_style(theme, a, top));
            if view.acting == Some(i) {
                name = name.patch_style(theme.active());
            }
            let mut cells = vec![Cell::from(name)];
            if full {
                cells.push(Cell::from(format!("{:?}", p.description.hidden)));
                cells.push(Cell::from(if tasks {
                    labels::short_task(&p.description.source_task).to_string()
                } else {
                    p.description.hidden.len().to_string()
                }));
            }
            cells.push(Cell::from(format_score(
                view.score,
                if relative { a - highest } else { a },
            )));
            cells.push(Cell::from(probability_bar(probability, bar_width)));
            // A count missing (a record from elsewhere, refused when read) shows as 0,
            // never a panic.
            let at = |counts: &[u64]| counts.get(i).copied().unwrap_or(0);
            cells.push(Cell::from(count(at(&view.selections))));
            if full {
                cells.push(Cell::from(format!(
                    "{}/{}",
                    count(at(&view.positive)),
                    count(at(&view.negative))
                )));
            }
            if history {
                cells.push(Cell::from(sparkline(
                    view.history.iter().skip(skipped).map(|scores| scores[i]),
                    history_top,
                )));
            }
            let row = Row::new(cells);
            if i == cursor {
                row.style(theme.cursor())
            } else {
                row
            }
        });
    let (mut header, mut widths) = if full {
        (
            vec![
                "policy",
                "hidden",
                if tasks { "task" } else { "cat" },
                &score_header,
                "P(π)",
                "acted",
                "+/−",
            ],
            vec![
                Constraint::Length(9),
                Constraint::Length(14),
                Constraint::Length(if tasks { 14 } else { 3 }),
                Constraint::Length(9),
                Constraint::Length(bar_width as u16 + 5),
                Constraint::Length(6),
                Constraint::Min(9),
            ],
        )
    } else {
        (
            vec!["policy", &score_header, "P(π)", "acted"],
            vec![
                Constraint::Length(9),
                Constraint::Length(9),
                Constraint::Length(bar_width as u16 + 5),
                Constraint::Min(6),
            ],
        )
    };
    if history {
        header.push("A per episode");
        widths.push(Constraint::Length(history_width as u16));
    }
    let mut marker = window.marker().unwrap_or_default();
    if let Some(acting) = view.acting.filter(|i| !window.rows().contains(i)) {
        marker.push_str(&format!("· {} acts ", view.policies[acting].name));
    }
    let block = block.title_bottom(Line::styled(marker, theme.title()).right_aligned());
    let table = Table::new(rows, widths)
        .header(Row::new(header).style(theme.title()))
        .block(block);
    frame.render_widget(table, area);
}
