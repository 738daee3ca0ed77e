//! The Curves view: what it keeps and what its keys do — the statistic over runs (IQM or
//! mean), the methods shown, the picked one, the episodes in view, and the run shown
//! alone when its method's runs are read one by one. Each method's curve is the one
//! `sample_efficiency.csv` holds ([`sample_efficiency::curve`]: the same points, the same
//! bootstrap seeds), made again only when that method's runs have grown. `chart.rs` draws
//! it.

mod chart;

use std::cell::RefCell;
use std::collections::BTreeSet;

use crossterm::event::{KeyCode, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;
use ratatui::Frame;

use crate::config::Budget;
use crate::report::sample_efficiency::{self, EfficiencyPoint};
use crate::report::TrainingEpisodes;
use crate::results::folder_state::{FolderState, RunProgress, RunStatus};
use crate::stats::Estimate;
use crate::tui::keys::{ch, code, Binding};
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};
use crate::tui::workbench::folder::Folder;

pub use chart::MARKERS;

/// The fewest episodes the view zooms in to: a moving average's span or so.
const NARROWEST: f64 = 20.0;

/// Which aggregate over runs the curves show, as `sample_efficiency.csv`'s `statistic`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Statistic {
    Iqm,
    Mean,
}

impl Statistic {
    pub fn name(self) -> &'static str {
        match self {
            Statistic::Iqm => "IQM",
            Statistic::Mean => "mean",
        }
    }

    pub fn of(self, point: &EfficiencyPoint) -> Estimate {
        match self {
            Statistic::Iqm => point.iqm,
            Statistic::Mean => point.mean,
        }
    }
}

/// The Curves view's choices.
#[derive(Debug)]
pub struct CurvesView {
    pub statistic: Statistic,
    /// Methods (by their place in the protocol) switched off.
    pub hidden: BTreeSet<usize>,
    /// The picked method (the legend's cursor).
    pub cursor: usize,
    /// The episodes shown, first to last; `None`: all of them.
    pub zoom: Option<(f64, f64)>,
    /// When the picked method's runs are read one by one: which of its runs (by place
    /// among those with episodes).
    pub run: Option<usize>,
    /// Each method's curve, with the episode counts of the runs it was made of.
    cache: RefCell<Vec<Option<Cached>>>,
}

/// A method's curve and what its runs were when it was made (their episodes in points'
/// worths, whether each had ended): made again when that changes.
type Cached = (Vec<(u64, bool)>, Vec<EfficiencyPoint>);

impl Default for CurvesView {
    fn default() -> Self {
        Self {
            statistic: Statistic::Iqm,
            hidden: BTreeSet::new(),
            cursor: 0,
            zoom: None,
            run: None,
            cache: RefCell::new(Vec::new()),
        }
    }
}

/// The runs of method `index` that have episodes (finished, stopped or running): those
/// `episodes.csv` holds when the protocol ends.
pub fn runs_of(folder: &FolderState, index: usize) -> Vec<&RunProgress> {
    folder
        .runs
        .iter()
        .filter(|r| r.method.index == index && !r.training.is_empty())
        .collect()
}

/// The episodes (or, under a step budget, the steps) a run of the protocol is given: the x
/// axis's end when not zoomed.
pub fn planned(folder: &FolderState) -> f64 {
    match folder.config.protocol.budget {
        Budget::Episodes(n) => f64::from(n.max(1)),
        Budget::Steps(n) => n.max(1) as f64,
    }
}

impl CurvesView {
    /// The curve of method `index` over its runs so far: on a finished folder, that
    /// method's rows of `sample_efficiency.csv`.
    pub fn curve(&self, folder: &FolderState, index: usize) -> Vec<EfficiencyPoint> {
        let runs = runs_of(folder, index);
        // A curve is a bootstrap per point (a large protocol's, a good part of a second):
        // made again when a run has grown by a point's worth of episodes, or ended — not
        // at every refresh of a live folder.
        let quantum = (planned(folder) as u64 / sample_efficiency::POINTS as u64).max(1);
        let key: Vec<(u64, bool)> = runs
            .iter()
            .map(|r| (r.done() / quantum, r.status == RunStatus::Done))
            .collect();
        let mut cache = self.cache.borrow_mut();
        if cache.len() <= index {
            cache.resize(index + 1, None);
        }
        if let Some((cached, points)) = &cache[index] {
            if *cached == key {
                return points.clone();
            }
        }
        let Some(label) = folder.config.protocol.methods.get(index).map(|m| m.label()) else {
            return Vec::new();
        };
        let training: Vec<TrainingEpisodes> = runs
            .iter()
            .map(|r| TrainingEpisodes::clone(&r.training))
            .collect();
        let protocol = &folder.config.protocol;
        let points =
            sample_efficiency::curve(&label, &training, protocol.moving_average, protocol.budget);
        cache[index] = Some((key, points.clone()));
        points
    }

    /// The episodes shown, first to last.
    pub fn range(&self, folder: &FolderState) -> (f64, f64) {
        let all = (1.0, planned(folder));
        self.zoom.map_or(all, |zoom| clamp(zoom, all))
    }

    /// Shows method `index` if hidden, hides it if shown.
    pub fn toggle(&mut self, index: usize) {
        if !self.hidden.remove(&index) {
            self.hidden.insert(index);
        }
    }
}

/// `range` in whole episodes, moved inside `all` (kept as wide as it fits) and no
/// narrower than [`NARROWEST`] episodes (nor than `all`).
fn clamp((from, to): (f64, f64), (first, last): (f64, f64)) -> (f64, f64) {
    let span = last - first;
    let width = (to - from).round().clamp(NARROWEST.min(span), span);
    let from = from.round().clamp(first, last - width);
    (from, from + width)
}

/// What the Curves view's keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurvesCommand {
    /// The legend's cursor by one method.
    Pick(isize),
    Toggle,
    Statistic,
    ZoomIn,
    ZoomOut,
    /// Along the episodes by this many quarters of the view.
    Pan(i8),
    All,
    /// The picked method's runs one by one, or back to every method.
    Runs,
    /// Back to every method from its runs.
    Back,
    /// The next or previous run of the picked method.
    Run(isize),
}

use CurvesCommand as C;

/// The Curves view's keys.
const KEYS: &[Binding<CurvesCommand>] = &[
    Binding {
        keys: &[
            (code(KeyCode::Up), C::Pick(-1)),
            (ch('k'), C::Pick(-1)),
            (code(KeyCode::Down), C::Pick(1)),
            (ch('j'), C::Pick(1)),
        ],
        help: ("↑ ↓ j k", "pick a method (its runs one by one: Enter)"),
        bar: Some(("↑↓", "method")),
    },
    Binding {
        keys: &[(ch(' '), C::Toggle)],
        help: ("space", "show or hide the picked method"),
        bar: Some(("␣", "on/off")),
    },
    Binding {
        keys: &[(ch('m'), C::Statistic)],
        help: ("m", "IQM or mean over runs"),
        bar: Some(("m", "IQM/mean")),
    },
    Binding {
        keys: &[
            (ch('+'), C::ZoomIn),
            (ch('='), C::ZoomIn),
            (ch('-'), C::ZoomOut),
            (code(KeyCode::Left), C::Pan(-1)),
            (ch('h'), C::Pan(-1)),
            (code(KeyCode::Right), C::Pan(1)),
            (ch('l'), C::Pan(1)),
            (ch('0'), C::All),
        ],
        help: (
            "+ -, ← → h l, 0",
            "zoom in and out, move along the episodes, all of them",
        ),
        bar: Some(("+-←→", "zoom")),
    },
    Binding {
        keys: &[(code(KeyCode::Enter), C::Runs)],
        help: (
            "Enter",
            "the picked method's runs one by one, each over its band; again, every method",
        ),
        bar: Some(("⏎", "runs")),
    },
    Binding {
        keys: &[
            (ch(']'), C::Run(1)),
            (code(KeyCode::Tab), C::Run(1)),
            (ch('['), C::Run(-1)),
            (code(KeyCode::BackTab), C::Run(-1)),
        ],
        help: ("] [, Tab Shift-Tab", "its runs: the next, the previous"),
        bar: Some(("[ ]", "run")),
    },
    Binding {
        keys: &[(code(KeyCode::Esc), C::Back)],
        help: ("Esc", "from its runs, back to every method"),
        bar: None,
    },
];

impl View for CurvesView {
    type Model = Folder;
    type Command = CurvesCommand;
    type Intent = super::Intent;

    fn keys(&self) -> &'static [Binding<CurvesCommand>] {
        KEYS
    }

    fn apply(&mut self, folder: &Folder, command: CurvesCommand) -> Outcome<super::Intent> {
        let folder = &folder.state;
        let methods = folder.config.protocol.methods.len();
        let all = (1.0, planned(folder));
        let (from, to) = self.range(folder);
        let width = to - from;
        match command {
            // Reading one method's runs, the method stays put; with every method shown,
            // there is no run to move to or come back from (Esc is then the screen's).
            C::Pick(_) if self.run.is_some() => return Outcome::Ignored,
            C::Back | C::Run(_) if self.run.is_none() => return Outcome::Ignored,
            C::Pick(by) => {
                let last = methods.saturating_sub(1) as isize;
                self.cursor = (self.cursor as isize + by).clamp(0, last) as usize;
            }
            C::Toggle => self.toggle(self.cursor),
            C::Statistic => {
                self.statistic = match self.statistic {
                    Statistic::Iqm => Statistic::Mean,
                    Statistic::Mean => Statistic::Iqm,
                };
            }
            C::ZoomIn => {
                let centre = (from + to) / 2.0;
                let half = (width / 4.0).max(NARROWEST / 2.0);
                self.zoom = Some(clamp((centre - half, centre + half), all));
            }
            C::ZoomOut => {
                let centre = (from + to) / 2.0;
                self.zoom = Some(clamp((centre - width, centre + width), all));
            }
            C::Pan(by) => {
                let shift = width / 4.0 * f64::from(by);
                self.zoom = Some(clamp((from + shift, to + shift), all));
            }
            C::All => self.zoom = None,
            C::Runs => {
                self.run = match self.run {
                    Some(_) => None,
                    None => Some(0),
                };
            }
            C::Back => self.run = None,
            C::Run(by) => {
                let runs = runs_of(folder, self.cursor).len();
                let last = runs.saturating_sub(1) as isize;
                self.run = self.run.map(|r| (r as isize + by).clamp(0, last) as usize);
            }
        }
        Outcome::Done
    }

    fn draw(&self, folder: &Folder, frame: &mut Frame, area: Rect, theme: Theme) {
        chart::draw(frame, area, self, &folder.state, theme);
    }

    /// Reading one method's runs, the arrows pick nothing and `[ ]` move; else the
    /// reverse.
    fn offers(&self, _: &Folder, command: CurvesCommand) -> bool {
        match command {
            C::Pick(_) => self.run.is_none(),
            C::Run(_) => self.run.is_some(),
            _ => true,
        }
    }

    fn words(&self, _: &Folder, command: CurvesCommand) -> Option<&'static str> {
        (command == C::Runs && self.run.is_some()).then_some("methods")
    }

    fn legend(&self, _: &Folder) -> Vec<(&'static str, &'static str)> {
        vec![(
            "click",
            "a method in the legend picks it and shows or hides it; a view's name below \
             shows it",
        )]
    }

    fn on_mouse(
        &mut self,
        folder: &Folder,
        mouse: MouseEvent,
        area: Rect,
    ) -> Outcome<super::Intent> {
        if mouse.kind != MouseEventKind::Down(MouseButton::Left) {
            return Outcome::Ignored;
        }
        match chart::legend_method_at(area, self, &folder.state, mouse.column, mouse.row) {
            Some(method) => {
                self.cursor = method;
                self.toggle(method);
                Outcome::Done
            }
            None => Outcome::Ignored,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_zoomed_range_stays_inside_the_episodes_and_no_narrower_than_twenty() {
        let all = (1.0, 501.0);
        assert_eq!(clamp((101.0, 201.0), all), (101.0, 201.0));
        // Whole episodes.
        assert_eq!(clamp((5.5, 25.5), all), (6.0, 26.0));
        // Moved back in, as wide as asked.
        assert_eq!(clamp((450.0, 550.0), all), (401.0, 501.0));
        assert_eq!(clamp((-49.0, 51.0), all), (1.0, 101.0));
        // Too narrow: twenty episodes from where it starts.
        assert_eq!(clamp((100.0, 105.0), all), (100.0, 120.0));
        // Wider than all: all.
        assert_eq!(clamp((-500.0, 1500.0), all), all);
        // A protocol of fewer episodes than twenty: all of them.
        assert_eq!(clamp((3.0, 4.0), (1.0, 11.0)), (1.0, 11.0));
    }
}
