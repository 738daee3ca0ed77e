//! Stand-alone teach mode's bottom line: the policies' numbering, if `p` changes it, and
//! the keys (on the dashboard, the dashboard's status bar stands in its place).

use ratatui::layout::Rect;
use ratatui::style::Modifier;
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;
use ratatui::Frame;

use crate::teach::Teach;
use crate::tui::teach_keys;
use crate::tui::theme::Theme;

/// Draws the status line of `teach` in `area`, a row as wide as the screen.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let mut spans = vec![
        Span::styled(" teach ", theme.title().add_modifier(Modifier::REVERSED)),
        Span::raw(" "),
    ];
    let wide = area.width >= 100;
    let modes_on = teach.is_linking()
        || teach.is_animating()
        || teach.score().is_some()
        || teach.quiz().is_some();
    // On a narrow screen a mode that is on says more than the numbering.
    if let (Some(numbering), true) = (teach.numbering(), wide || !modes_on) {
        spans.push(Span::raw(format!("{numbering} (p) · ")));
    }
    // What is on that changes what keys and clicks do, said before the keys.
    if teach.is_linking() {
        let said = if wide {
            "M: click two policies · "
        } else {
            "M clicks · "
        };
        spans.push(Span::styled(said, theme.active()));
    }
    if teach.is_animating() {
        spans.push(Span::styled(
            format!("r {}/s · ", teach.speed()),
            theme.active(),
        ));
    }
    if let Some(score) = teach.score() {
        spans.push(Span::styled(
            if wide {
                format!("exercise {}/{} · ", score.right, score.asked)
            } else {
                format!("ex {}/{} · ", score.right, score.asked)
            },
            theme.active(),
        ));
    }
    if let Some(quiz) = teach.quiz() {
        spans.push(Span::raw(format!(
            "questions {}/{} · ",
            quiz.right, quiz.asked
        )));
    }
    // Narrow terminals drop the keys' words, not the keys.
    // The keys' words where they fit beside the modes said, else the keys alone.
    let used: usize = spans.iter().map(|s| s.content.chars().count()).sum();
    let room = usize::from(area.width).saturating_sub(used);
    let with_words = format!("{} · ? q", teach_keys::bar(true));
    let hints = if wide && with_words.chars().count() <= room {
        with_words
    } else {
        format!("{} · ? q", teach_keys::bar(false))
    };
    spans.push(Span::styled(hints, theme.dim()));
    let line = Line::from(spans);
    frame.render_widget(Paragraph::new(line), area);
}
