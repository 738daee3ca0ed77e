//! The dashboard's live step line: the step just taken as Algorithm 3 sees it. Who acted,
//! its update's loss, E before and after, T_a = E_{t+1} − E_t and the judgment it gave
//! (eq. 7), what a positive judgment deposited (eq. 8–11), and the episode's return so far.
//!
//! The line says the most telling things first, and a narrow terminal leaves out whole
//! parts, never half of one.
//! Slowed down (`-`) it reads step by step; at full speed each frame shows the latest step,
//! a sample.

use ratatui::text::{Line, Span};

use crate::trainer::StepRecord;
use crate::tui::dashboard::{Dashboard, FromFiles};
use crate::tui::theme::Theme;

/// What a dashboard made from a finished run's files says: that, and what its files lacked,
/// each part left out whole where `width` has no room for it.
fn from_files(files: FromFiles, reuses: bool, width: u16) -> String {
    let mut parts = vec![" from its files, no steps kept"];
    if reuses && !files.activations {
        parts.push(" · no activations.csv: scores shown as at the start");
    }
    if !files.learner {
        parts.push(" · no ε, losses on file: shown as 0");
    }
    let mut line = String::new();
    for part in parts {
        if line.chars().count() + part.chars().count() <= usize::from(width) {
            line.push_str(part);
        }
    }
    line
}

/// The step line of `dashboard`'s followed run in `width` columns (a waiting note before
/// its first step). Parts that do not fit are left out whole; the most telling come first.
pub(super) fn step_line(dashboard: &Dashboard, width: u16, theme: Theme) -> Line<'static> {
    let Some(step) = &dashboard.last_step else {
        // Steps stream only from the run followed: one followed after it ended sent none.
        let ended = dashboard.main_run().is_some_and(|r| r.ended.is_some());
        return Line::styled(
            match dashboard.from_files {
                Some(files) => from_files(files, dashboard.library.is_some(), width),
                None if ended => {
                    " no steps: this run ended before it was followed (its curve is below)".into()
                }
                None => " waiting for the first step…".into(),
            },
            theme.dim(),
        );
    };
    let name = |i: usize| {
        dashboard
            .library
            .as_ref()
            .and_then(|v| v.policies.get(i))
            .map_or_else(|| format!("source {i}"), |p| p.name.clone())
    };
    let actor = step.policy.map_or("the learner".to_string(), name);
    let (episode, so_far) = dashboard.episode_return;
    let mut parts = vec![
        vec![Span::styled(format!(" {actor}"), theme.active())],
        vec![Span::raw(format!(
            " · ep {episode} return {}",
            short(so_far)
        ))],
    ];
    if step.warm_up {
        parts.push(vec![Span::raw(
            " · warm-up: the sources act in turn, no learning yet",
        )]);
    } else {
        parts.extend(judged(step, theme));
    }
    let mut spans = Vec::new();
    let mut used = 0;
    for part in parts {
        let length: usize = part.iter().map(|s| s.content.chars().count()).sum();
        if used + length > usize::from(width) {
            continue;
        }
        used += length;
        spans.extend(part);
    }
    Line::from(spans)
}

/// `· T_a −4.000e-4 ≤ 0, positive (eq. 7)`, `· ΔA +1 own, +0.5263 others`,
/// `· E 0.0421 → 0.0417` (T_a = E_{t+1} − E_t), `· loss 0.05`: the parts of a step past
/// the warm-up.
fn judged(step: &StepRecord, theme: Theme) -> Vec<Vec<Span<'static>>> {
    let Some(update) = step.update else {
        return vec![vec![Span::raw(" · no update this step")]];
    };
    let mut judgment = vec![Span::raw(format!(" · T_a {}", signed(update.transition())))];
    match step.judgment {
        Some(true) => judgment.push(Span::styled(" ≤ 0, positive (eq. 7)", theme.active())),
        Some(false) => judgment.push(Span::styled(" > 0, negative (eq. 7)", theme.stopped())),
        None => {}
    }
    let mut parts = vec![judgment];
    if let Some(deposit) = step.deposit {
        parts.push(vec![Span::raw(format!(
            " · ΔA {} own, {} others",
            signed(deposit.own),
            signed(deposit.others)
        ))]);
    }
    parts.push(vec![Span::raw(format!(
        " · E {} → {}",
        decimal(update.previous_statistic_loss),
        decimal(update.statistic_loss),
    ))]);
    parts.push(vec![Span::raw(format!(" · loss {}", decimal(update.loss)))]);
    parts
}

/// Four decimals without trailing zeros, or an exponent for the tiny and the huge.
fn decimal(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e5) {
        format!("{x:.3e}")
    } else {
        let text = format!("{x:.4}");
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn signed(x: f64) -> String {
    let text = decimal(x.abs());
    if x < 0.0 {
        format!("−{text}")
    } else {
        format!("+{text}")
    }
}

/// A return as episodes count it: whole when it is whole.
fn short(x: f64) -> String {
    if x.fract() == 0.0 {
        format!("{x:.0}")
    } else {
        format!("{x:.2}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dqn::UpdateReport;
    use crate::trainer::Event;

    fn step(step: u64, episode: u32, warm_up: bool, e: (f64, f64)) -> Event {
        let update = (!warm_up).then_some(UpdateReport {
            loss: 0.5,
            previous_statistic_loss: e.0,
            statistic_loss: e.1,
            td: None,
        });
        Event::Step(StepRecord {
            method: 0,
            run: 0,
            step,
            episode,
            policy: Some(2),
            action: 0,
            reward: 1.0,
            update,
            judgment: update
                .map(|u| crate::sapnet::judge(u.previous_statistic_loss, u.statistic_loss)),
            deposit: None,
            warm_up,
        })
    }

    fn text(line: &Line) -> String {
        line.spans.iter().map(|s| s.content.as_ref()).collect()
    }

    #[test]
    fn the_line_follows_the_steps_and_sums_the_episode() {
        let theme = Theme::plain();
        let mut dashboard = Dashboard::new("CartPole-v1");
        assert_eq!(
            text(&step_line(&dashboard, 120, theme)),
            " waiting for the first step…"
        );
        dashboard.on_event(step(1, 1, true, (0.0, 0.0)));
        dashboard.on_event(step(2, 1, true, (0.0, 0.0)));
        assert_eq!(
            text(&step_line(&dashboard, 120, theme)),
            " source 2 · ep 1 return 2 · warm-up: the sources act in turn, no learning yet"
        );
        // A new episode starts its return afresh; E rose: T_a = 0.01 > 0, negative.
        dashboard.on_event(step(3, 2, false, (0.04, 0.05)));
        assert_eq!(
            text(&step_line(&dashboard, 120, theme)),
            " source 2 · ep 2 return 1 · T_a +0.01 > 0, negative (eq. 7) · E 0.04 → 0.05 · loss 0.5"
        );
        // Too narrow for the judgment: it is left out whole, the shorter E still fits.
        assert_eq!(
            text(&step_line(&dashboard, 50, theme)),
            " source 2 · ep 2 return 1 · E 0.04 → 0.05"
        );
    }

    #[test]
    fn numbers_read_at_a_glance() {
        assert_eq!(decimal(0.0421), "0.0421");
        assert_eq!(decimal(0.0), "0");
        assert_eq!(signed(-0.0004), "−4.000e-4");
        assert_eq!(signed(1.0), "+1");
        assert_eq!(decimal(0.52631), "0.5263");
        assert_eq!(decimal(236_000.0), "2.360e5");
        assert_eq!(short(37.0), "37");
        assert_eq!(short(-0.5), "-0.50");
    }
}
