//! Teach mode's graph: the lesson's net, the picked and the activated policy marked, the
//! walk so far lit and the next call's edge shown; the title gives T_ω, 𝒜 and τ.

use ratatui::layout::Rect;
use ratatui::text::Span;
use ratatui::widgets::Block;
use ratatui::Frame;

use crate::teach::Teach;
use crate::tui::graph_view::{self, Scene};
use crate::tui::theme::Theme;

/// Draws `teach`'s graph in `area`.
pub(super) fn draw(frame: &mut Frame, area: Rect, teach: &Teach, theme: Theme) {
    let walk = teach.walk();
    let next = walk.as_ref().and_then(|w| w.pending.last().copied());
    let lit: Vec<(usize, usize)> = walk
        .as_ref()
        .map(|w| w.path.windows(2).map(|e| (e[0], e[1])).collect())
        .unwrap_or_default();
    let scene = Scene {
        net: teach.net(),
        names: teach.names(),
        groups: teach.groups(),
        group_names: &[],
        cursor: Some(teach.cursor()),
        active: walk.as_ref().map(|w| w.policy),
        lit: &lit,
        walking: next.map(|c| (c.from, c.to)),
        excluded: teach.excluded(),
    };
    let params = teach.net().params();
    let title = format!(
        "SAP-Net · T_ω {} · 𝒜 {} · τ {}",
        params.threshold, params.coefficient, params.temperature
    );
    graph_view::draw_with_weights(
        frame,
        area,
        Block::bordered().title(Span::styled(format!(" {title} "), theme.title())),
        scene,
        theme,
        true,
    );
}
