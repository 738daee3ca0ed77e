//! The dashboard's bottom line: the mode, how fast training is let run and where the run
//! is, and the keys of the mode.

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Modifier;
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;
use ratatui::Frame;

use super::figures::thousands;
use crate::config::Budget;
use crate::results::folder_state::short_count;
use crate::tui::dashboard::{Dashboard, DashboardCommand, Mode, RunView, KEYS, SPEEDS};
use crate::tui::keys::{self, HELP_BAR, QUIT_BAR};
use crate::tui::theme::Theme;

/// Teach mode's keys in their short form (teach_view/status_bar.rs has the long one):
/// teach's own, not yet a table of teach's.
const TEACH_KEYS: &str = "a s r R u c 1–5± E x M n D C v w X";
const TEACH_BACK: &str = "Esc/t back";

/// The keys on the right of the line, as the Run view's table says them: the mode's own
/// (space, n, t), then `?` and `q` as every screen says them; teach mode's are its own.
fn hints(dashboard: &Dashboard, width: u16, failed: bool, finished: bool) -> String {
    use DashboardCommand as D;
    let said = |key: &str, words: &str| format!("{key} {words}");
    let own = |command: D| {
        let (key, words) = keys::binding(KEYS, command)
            .and_then(|b| b.bar)
            .expect("the bar's keys are in the table");
        said(key, dashboard.bar_words(command).unwrap_or(words))
    };
    let help = said(HELP_BAR.0, HELP_BAR.1);
    let quit = said(QUIT_BAR.0, QUIT_BAR.1);
    let teaching = dashboard.mode == Mode::Teach;
    let hints: Vec<String> = if failed {
        vec![quit]
    } else if let Some(notice) = dashboard.notice {
        vec![notice.to_string()]
    } else if width < 100 && teaching {
        // `q` here would quit the training too: the way back is what teach mode offers.
        vec![TEACH_BACK.into(), help]
    } else if width < 100 {
        vec![help, quit]
    } else if teaching {
        vec![TEACH_KEYS.into(), TEACH_BACK.into(), help]
    } else if finished {
        // Nothing left to pause or step; the graph can still be taught on.
        vec![own(D::Teach), help, quit]
    } else if dashboard.mode == Mode::Paused {
        vec![own(D::PauseResume), own(D::Step), own(D::Teach), help]
    } else {
        vec![own(D::PauseResume), own(D::Teach), help, quit]
    };
    hints.join(" · ")
}

/// Where `run` is: its episode (the one being played) of those planned, or under a step
/// budget its steps too.
fn episode(dashboard: &Dashboard, r: &RunView) -> String {
    // Run 0 goes without saying; another (`--follow-run`) is named, from 0 as in the
    // results' files.
    let which = match r.run {
        0 => String::new(),
        run => format!(" run {run}"),
    };
    // The episode being played, as the step line counts it: the next one once its
    // first step came (the run counts the episodes that ended).
    let playing = dashboard.last_step.as_ref().map_or(0, |s| s.episode);
    let episode = r.episode.max(playing);
    match r.budget {
        Budget::Episodes(n) => format!("{}{which} ep {episode}/{n}", r.method),
        Budget::Steps(n) => {
            let stepped = dashboard.last_step.as_ref().map_or(0, |s| s.step);
            let steps = short_count(r.steps.max(stepped));
            format!(
                "{}{which} ep {episode} · {steps}/{} steps",
                r.method,
                short_count(n)
            )
        }
    }
}

/// The bottom line: mode and figures on the left, the keys of the mode on the right
/// (the figures give way first on a narrow terminal).
pub(super) fn draw(frame: &mut Frame, area: Rect, dashboard: &Dashboard, theme: Theme) {
    let mode = match dashboard.mode {
        Mode::Running => "RUNNING",
        Mode::Paused => "PAUSED",
        Mode::Teach => "TEACH",
    };
    let run = dashboard.main_run();
    let finished = run.is_some_and(|r| r.ended.is_some());
    // Ended before its episodes: stopped by the user, or by another run's failure.
    let stopped = run.is_some_and(|r| r.ended.as_ref().is_some_and(|e| e.stopped));
    // The followed run failing is the one thing worth the whole line: its training went no
    // further. A baseline's failure is a note beside the figures; the rest goes on.
    let failure = run.and_then(|r| Some((&r.method, r.failed.as_ref()?)));
    let other_failures: Vec<&str> = dashboard
        .runs
        .iter()
        .skip(1)
        .filter(|r| r.failed.is_some())
        .map(|r| r.method.label())
        .collect();
    let hints = hints(dashboard, area.width, failure.is_some(), finished);
    let hints = hints.as_str();
    let episode = run.map_or("-".to_string(), |r| episode(dashboard, r));
    // Paused, training makes no steps: the last rate measured would be stale.
    let speed = match (dashboard.mode, dashboard.steps_per_second) {
        (Mode::Teach, _) => Some("paused".to_string()),
        _ if finished || dashboard.mode == Mode::Paused => None,
        (_, Some(s)) => Some(format!("{s:.0} steps/s")),
        (_, None) => Some("- steps/s".to_string()),
    };
    // A run that ended (or read from its files) is not paced: no speed to say.
    let throttle = match SPEEDS[dashboard.speed] {
        _ if finished || dashboard.from_files.is_some() => None,
        d if d.is_zero() => Some("full speed".to_string()),
        d => Some(format!("{} ms/step", d.as_millis())),
    };
    // ε where it is known: not before a run, nor from files that did not keep it.
    let epsilon = run
        .filter(|_| dashboard.from_files.is_none_or(|f| f.learner))
        .map(|r| format!("ε {:.2}", r.epsilon));
    let figures = match failure {
        Some((method, error)) => Line::from(vec![
            Span::styled(" FAILED ", theme.stopped().add_modifier(Modifier::REVERSED)),
            Span::raw(if error.contains(method.label()) {
                format!(" {error}")
            } else {
                format!(" {method}: {error}")
            }),
        ]),
        None => {
            let mut spans = vec![Span::styled(
                format!(
                    " {} ",
                    match (stopped, finished) {
                        (true, _) => "STOPPED",
                        (false, true) => "DONE",
                        _ => mode,
                    }
                ),
                theme.title().add_modifier(Modifier::REVERSED),
            )];
            // First, where a narrow terminal cannot cut it off; the error itself is
            // printed when the dashboard closes.
            for method in other_failures {
                spans.push(Span::styled(format!(" {method} FAILED ·"), theme.stopped()));
            }
            // The state first: how fast training is let run, where the run is. What does
            // not fit before the keys is dropped from the end, never cut mid-word; two
            // spaces at least keep the last figure from reading into the keys.
            let room = usize::from(area.width)
                .saturating_sub(hints.chars().count() + 2)
                .saturating_sub(spans.iter().map(|s| s.content.chars().count()).sum());
            let figures = [
                throttle,
                Some(episode),
                Some(format!("step {}", thousands(dashboard.step))),
                speed,
                epsilon,
                Some(dashboard.task.clone()),
            ];
            let mut text = String::new();
            for figure in figures.into_iter().flatten() {
                let next = if text.is_empty() {
                    format!(" {figure}")
                } else {
                    format!(" · {figure}")
                };
                if text.chars().count() + next.chars().count() > room {
                    break;
                }
                text.push_str(&next);
            }
            spans.push(Span::raw(text));
            Line::from(spans)
        }
    };
    let [left, right] = Layout::horizontal([
        Constraint::Min(0),
        Constraint::Length(hints.chars().count() as u16 + 1),
    ])
    .areas(area);
    frame.render_widget(Paragraph::new(figures), left);
    frame.render_widget(
        Paragraph::new(Span::styled(hints, theme.dim())).right_aligned(),
        right,
    );
}
