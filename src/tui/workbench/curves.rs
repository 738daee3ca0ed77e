//! What the Curves view keeps and what its keys do: the statistic over runs (IQM or
//! mean), the methods shown, the picked one, the episodes in view, and the run shown
//! alone when its method's runs are read one by one. Each method's curve is the one
//! `sample_efficiency.csv` holds ([`sample_efficiency::curve`]: the same points, the same
//! bootstrap seeds), made again only when that method's runs have grown.

use std::cell::RefCell;
use std::collections::BTreeSet;

use crossterm::event::{KeyCode, KeyEvent};

use crate::config::Budget;
use crate::report::sample_efficiency::{self, EfficiencyPoint};
use crate::report::TrainingEpisodes;
use crate::results::folder_state::{FolderState, RunProgress, RunStatus};
use crate::stats::Estimate;

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
pub struct Curves {
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

impl Default for Curves {
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

impl Curves {
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

    /// Acts on a key of the Curves view; `false` for a key it does not take (the
    /// workbench's own: views, help, quit).
    pub fn on_key(&mut self, key: KeyEvent, folder: &FolderState) -> bool {
        let methods = folder.config.protocol.methods.len();
        let all = (1.0, planned(folder));
        let (from, to) = self.range(folder);
        let width = to - from;
        match key.code {
            KeyCode::Up | KeyCode::Char('k') if self.run.is_none() => {
                self.cursor = self.cursor.saturating_sub(1);
            }
            KeyCode::Down | KeyCode::Char('j') if self.run.is_none() => {
                self.cursor = (self.cursor + 1).min(methods.saturating_sub(1));
            }
            KeyCode::Char(' ') => self.toggle(self.cursor),
            KeyCode::Char('m') => {
                self.statistic = match self.statistic {
                    Statistic::Iqm => Statistic::Mean,
                    Statistic::Mean => Statistic::Iqm,
                };
            }
            KeyCode::Char('+' | '=') => {
                let centre = (from + to) / 2.0;
                let half = (width / 4.0).max(NARROWEST / 2.0);
                self.zoom = Some(clamp((centre - half, centre + half), all));
            }
            KeyCode::Char('-') => {
                let centre = (from + to) / 2.0;
                self.zoom = Some(clamp((centre - width, centre + width), all));
            }
            KeyCode::Left | KeyCode::Char('h') => {
                self.zoom = Some(clamp((from - width / 4.0, to - width / 4.0), all));
            }
            KeyCode::Right | KeyCode::Char('l') => {
                self.zoom = Some(clamp((from + width / 4.0, to + width / 4.0), all));
            }
            KeyCode::Char('0') => self.zoom = None,
            KeyCode::Enter => {
                self.run = match self.run {
                    Some(_) => None,
                    None => Some(0),
                };
            }
            KeyCode::Esc if self.run.is_some() => self.run = None,
            KeyCode::Char(']') | KeyCode::Tab if self.run.is_some() => {
                let runs = runs_of(folder, self.cursor).len();
                self.run = self.run.map(|r| (r + 1).min(runs.saturating_sub(1)));
            }
            KeyCode::Char('[') | KeyCode::BackTab if self.run.is_some() => {
                self.run = self.run.map(|r| r.saturating_sub(1));
            }
            _ => return false,
        }
        true
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

/// Every key of the Curves view, for `?`.
pub const KEYS: [(&str, &str); 6] = [
    ("v", "Curves: MA10 over runs with its 95% band"),
    ("↑ ↓, space", "Curves: pick a method; show or hide it"),
    ("m", "Curves: IQM or mean over runs"),
    ("+ -, ← →, 0", "Curves: zoom, move along the episodes, all"),
    ("Enter, [ ]", "Curves: the picked method's runs one by one"),
    ("click", "a view's name, a run, a method, a legend entry"),
];

/// The Curves view's keys in the status bar.
pub const COMMANDS: [(&str, &str); 5] = [
    ("↑↓", "method"),
    ("␣", "on/off"),
    ("m", "IQM/mean"),
    ("+-←→", "zoom"),
    ("⏎", "runs"),
];

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
