//! The dashboard's graph panel: the followed run's library as SAP-Net sees it, the acting
//! policy marked, the edges of a policy that just spread activation lit.

use ratatui::layout::Rect;
use ratatui::widgets::Block;
use ratatui::Frame;

use crate::tui::dashboard::{Dashboard, LibraryView};
use crate::tui::graph_view::{self, Scene};
use crate::tui::theme::Theme;

/// "SAP-Net graph", or for another method the scores it keeps; the categories left out of
/// the candidates counted.
pub(super) fn title(view: &LibraryView) -> String {
    let mut title = if view.score == crate::reuse::sapnet::SCORE {
        "SAP-Net graph".to_string()
    } else {
        format!("library graph · {} ({})", view.method, view.score.name)
    };
    let out = view.excluded.iter().filter(|&&e| e).count();
    if out > 0 {
        title.push_str(&format!(" · × {out} excluded"));
    }
    title
}

/// Draws `view`'s graph in `area`, inside `block`.
pub(super) fn draw(
    frame: &mut Frame,
    area: Rect,
    block: Block,
    view: &LibraryView,
    dashboard: &Dashboard,
    theme: Theme,
) {
    let names: Vec<String> = view.policies.iter().map(|p| p.name.clone()).collect();
    let groups = view.categories();
    let group_names = view.task_groups();
    let lit: Vec<(usize, usize)> = view
        .spread
        .filter(|&(p, _)| view.glows(p, dashboard.step))
        .map(|(p, _)| {
            view.net
                .graph()
                .neighbours(p)
                .map(|(j, _)| (p, j))
                .collect()
        })
        .unwrap_or_default();
    let scene = Scene {
        net: &view.net,
        names: &names,
        groups: Some(&groups),
        group_names: &group_names,
        cursor: Some(dashboard.cursor),
        active: view.acting,
        lit: &lit,
        walking: None,
        excluded: &view.excluded,
    };
    graph_view::draw(frame, area, block, scene, theme);
}
