//! The Curves view: what it keeps and what its keys do — the metric drawn (any number
//! per episode the folder's files hold, [`run_metrics::on_file`]), the x axis (episode,
//! environment step, wall time; the step by default where every run has steps), the
//! smoothing (a moving average's window, cycled), the statistic over runs (IQM or mean),
//! the methods shown, the picked one, the range in view, and the run shown alone when its
//! method's runs are read one by one. The return against the budget's own axis, smoothed
//! by the protocol's window, is the curve `sample_efficiency.csv` holds
//! ([`sample_efficiency::curve`]: the same points, the same bootstrap seeds); any other
//! choice is [`metric::curve`] of the runs' files. The curves are made on a thread of
//! their own ([`background`]), the view saying that it works meanwhile, and made again
//! only when the choice changes or a run has grown by a point's worth. `chart.rs` draws
//! them.

mod chart;

use std::cell::RefCell;
use std::collections::BTreeSet;
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Instant;

use crossterm::event::{KeyCode, MouseButton, MouseEvent, MouseEventKind};
use ratatui::layout::Rect;
use ratatui::Frame;

use crate::config::Budget;
use crate::report::metric::{self, CurvePoint, Metric, RunMetric, XAxis};
use crate::report::sample_efficiency;
use crate::report::TrainingEpisodes;
use crate::results::folder_state::{RunProgress, RunStatus};
use crate::results::run_metrics::{self, OnFile, RunFiles};
use crate::stats::Estimate;
use crate::tui::background;
use crate::tui::keys::{ch, code, Binding};
use crate::tui::theme::Theme;
use crate::tui::view::{Outcome, View};
use crate::tui::workbench::folder::Compared;

pub use chart::MARKERS;

/// The fewest units (episodes, steps, seconds) the view zooms in to: a moving average's
/// span or so.
const NARROWEST: f64 = 20.0;

/// The smoothing windows `s` cycles through after the protocol's own: none, then wider.
const WINDOWS: [usize; 5] = [1, 5, 25, 50, 100];

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

    pub fn of(self, point: &CurvePoint) -> Estimate {
        match self {
            Statistic::Iqm => point.iqm,
            Statistic::Mean => point.mean,
        }
    }
}

/// What the curves are made of: the choice and the runs as they stood.
#[derive(Debug, Clone, PartialEq)]
struct Request {
    metric: Metric,
    axis: XAxis,
    window: usize,
    /// Each run with episodes: its method, its episodes in points' worths, whether it
    /// had ended.
    runs: Vec<(usize, u64, bool)>,
}

impl Request {
    /// The same choice, whatever the runs.
    fn same_choice(&self, other: &Request) -> bool {
        (self.metric, self.axis, self.window) == (other.metric, other.axis, other.window)
    }
}

/// The curves made for a request.
#[derive(Debug, Clone, Default)]
pub struct Made {
    /// Each method's curve, in the protocol's order.
    pub methods: Vec<Vec<CurvePoint>>,
    /// Each method's runs' own lines (smoothed, at the curve's points), in the order of
    /// [`runs_of`].
    pub runs: Vec<Vec<Vec<(f64, f64)>>>,
    /// The axis's extent: what "all" shows.
    pub extent: (f64, f64),
    /// Why they could not be made (a file that could not be read).
    pub error: Option<String>,
}

/// The curves made and being made.
#[derive(Default)]
struct Curves {
    made: Option<(Request, Made)>,
    making: Option<(Request, Instant, mpsc::Receiver<Made>)>,
    /// What the folder's files hold, and the runs' count it was looked at with.
    on_file: Option<(PathBuf, usize, OnFile)>,
}

/// The Curves view's choices.
pub struct CurvesView {
    pub statistic: Statistic,
    /// The metric drawn.
    pub metric: Metric,
    /// The x axis; `None`: the default (the step where every run has steps).
    pub axis: Option<XAxis>,
    /// The moving average's window; `None`: the protocol's.
    pub window: Option<usize>,
    /// Methods (by their place in the protocol) switched off.
    pub hidden: BTreeSet<usize>,
    /// The picked method (the legend's cursor).
    pub cursor: usize,
    /// The range shown on the axis, first to last; `None`: all of it.
    pub zoom: Option<(f64, f64)>,
    /// When the picked method's runs are read one by one: which of its runs (by place
    /// among those with episodes).
    pub run: Option<usize>,
    curves: RefCell<Curves>,
}

impl std::fmt::Debug for CurvesView {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CurvesView")
            .field("metric", &self.metric)
            .field("axis", &self.axis)
            .field("window", &self.window)
            .field("cursor", &self.cursor)
            .finish_non_exhaustive()
    }
}

impl Default for CurvesView {
    fn default() -> Self {
        Self {
            statistic: Statistic::Iqm,
            metric: Metric::Return,
            axis: None,
            window: None,
            hidden: BTreeSet::new(),
            cursor: 0,
            zoom: None,
            run: None,
            curves: RefCell::new(Curves::default()),
        }
    }
}

/// The runs of method `index` that have episodes (finished, stopped or running): those
/// `episodes.csv` holds when the protocol ends.
pub fn runs_of(folder: &dyn Compared, index: usize) -> Vec<&RunProgress> {
    folder
        .runs()
        .iter()
        .filter(|r| r.method.index == index && !r.training.is_empty())
        .collect()
}

/// The episodes (or, under a step budget, the steps) a run of the protocol is given.
pub fn planned(folder: &dyn Compared) -> f64 {
    match folder.budget() {
        Budget::Episodes(n) => f64::from(n.max(1)),
        Budget::Steps(n) => n.max(1) as f64,
    }
}

/// The axis of the protocol's budget: what `sample_efficiency.csv` is drawn against.
fn budget_axis(budget: Budget) -> XAxis {
    match budget {
        Budget::Episodes(_) => XAxis::Episode,
        Budget::Steps(_) => XAxis::Step,
    }
}

/// The curves of `request` for `runs` (on any thread).
fn make(
    request: &Request,
    runs: &[RunFiles],
    labels: &[String],
    sources: &[String],
    (budget, protocol_window): (Budget, usize),
) -> Made {
    let methods = labels.len();
    // The return on the budget's axis by the protocol's window: sample_efficiency.csv's.
    if request.metric == Metric::Return
        && request.axis == budget_axis(budget)
        && request.window == protocol_window
    {
        let mut made = Made {
            extent: (
                1.0,
                match budget {
                    Budget::Episodes(n) => f64::from(n.max(1)),
                    Budget::Steps(n) => n.max(1) as f64,
                },
            ),
            ..Made::default()
        };
        for (index, label) in labels.iter().enumerate() {
            let training: Vec<TrainingEpisodes> = runs
                .iter()
                .filter(|r| r.method == index)
                .map(|r| TrainingEpisodes::clone(&r.training))
                .collect();
            let points = sample_efficiency::curve(label, &training, protocol_window, budget);
            made.runs.push(
                training
                    .iter()
                    .map(|t| {
                        let run = RunMetric {
                            values: t.returns.iter().map(|&r| Some(r)).collect(),
                            lengths: t.lengths.clone(),
                            wall_s: None,
                        };
                        run_line(
                            &run,
                            request,
                            &points.iter().map(|p| p.at as f64).collect::<Vec<_>>(),
                        )
                    })
                    .collect(),
            );
            made.methods
                .push(points.into_iter().map(CurvePoint::from).collect());
        }
        return made;
    }
    let mut made = Made::default();
    let mut read: Vec<(usize, RunMetric)> = Vec::new();
    for run in runs {
        match run_metrics::read(run, request.metric, request.axis == XAxis::Wall, sources) {
            Ok(values) => read.push((run.method, values)),
            Err(error) => {
                made.error = Some(format!("{error:#}"));
                return made;
            }
        }
    }
    let Some(extent) = metric::extent(read.iter().map(|(_, r)| r), request.axis) else {
        made.methods = vec![Vec::new(); methods];
        made.runs = vec![Vec::new(); methods];
        return made;
    };
    made.extent = extent;
    let points = metric::grid(extent.0, extent.1, sample_efficiency::POINTS);
    let name = request.metric.name(sources);
    for (index, label) in labels.iter().enumerate() {
        let mine: Vec<RunMetric> = read
            .iter()
            .filter(|(m, _)| *m == index)
            .map(|(_, r)| r.clone())
            .collect();
        made.methods.push(metric::curve(
            &format!("{label} {name}"),
            &mine,
            request.axis,
            request.window,
            &points,
        ));
        made.runs
            .push(mine.iter().map(|r| run_line(r, request, &points)).collect());
    }
    made
}

/// One run's smoothed line at `points`, where it has a value.
fn run_line(run: &RunMetric, request: &Request, points: &[f64]) -> Vec<(f64, f64)> {
    points
        .iter()
        .zip(run.curve(request.axis, request.window, points))
        .filter_map(|(&x, y)| Some((x, y?)))
        .collect()
}

impl CurvesView {
    /// What the folder's files hold (looked at again when runs gain episodes or files).
    pub fn on_file(&self, folder: &dyn Compared) -> OnFile {
        let runs = folder
            .runs()
            .iter()
            .filter(|r| !r.training.is_empty())
            .count();
        let mut curves = self.curves.borrow_mut();
        if let Some((dir, count, on_file)) = &curves.on_file {
            if dir == folder.dir() && *count == runs {
                return on_file.clone();
            }
        }
        let on_file = run_metrics::on_file(&folder.run_files(), folder.sources().len());
        curves.on_file = Some((folder.dir().to_path_buf(), runs, on_file.clone()));
        on_file
    }

    /// Whether every run with episodes has their steps (a run from elsewhere may not).
    fn stepped(folder: &dyn Compared) -> bool {
        folder
            .runs()
            .iter()
            .filter(|r| !r.training.is_empty())
            .all(|r| r.training.lengths.iter().any(|&l| l > 0))
    }

    /// The x axis drawn: the one picked, else the environment step where every run with
    /// episodes has steps, else the episode.
    pub fn axis(&self, folder: &dyn Compared) -> XAxis {
        self.axis.unwrap_or_else(|| {
            if Self::stepped(folder) {
                XAxis::Step
            } else {
                XAxis::Episode
            }
        })
    }

    /// The moving average's window: the one picked, else the folder's.
    pub fn window(&self, folder: &dyn Compared) -> usize {
        self.window.unwrap_or(folder.window()).max(1)
    }

    fn request(&self, folder: &dyn Compared) -> Request {
        let quantum = (planned(folder) as u64 / sample_efficiency::POINTS as u64).max(1);
        Request {
            metric: self.metric,
            axis: self.axis(folder),
            window: self.window(folder),
            runs: folder
                .runs()
                .iter()
                .filter(|r| !r.training.is_empty())
                .map(|r| {
                    (
                        r.method.index,
                        r.done() / quantum,
                        r.status == RunStatus::Done,
                    )
                })
                .collect(),
        }
    }

    /// The curves of the view's choice: made, or being made (then the last ones of the
    /// same choice if any, and since when). Starts making them when needed.
    pub fn curves(&self, folder: &dyn Compared) -> (Option<Made>, Option<Instant>) {
        let request = self.request(folder);
        let mut curves = self.curves.borrow_mut();
        if let Some((_, _, rx)) = &curves.making {
            if let Ok(made) = rx.try_recv() {
                let (done, _, _) = curves.making.take().expect("being made");
                curves.made = Some((done, made));
            }
        }
        let current = curves.made.as_ref().filter(|(r, _)| *r == request);
        if let Some((_, made)) = current {
            return (Some(made.clone()), None);
        }
        let started = match &curves.making {
            Some((r, since, _)) if *r == request => *since,
            _ => {
                let runs = folder.run_files();
                let labels: Vec<String> = folder
                    .methods()
                    .iter()
                    .map(|m| m.label().to_string())
                    .collect();
                let sources = folder.sources();
                let protocol = (folder.budget(), folder.window());
                let job = request.clone();
                let rx = background::spawn("workbench: making the curves", move || {
                    make(&job, &runs, &labels, &sources, protocol)
                });
                let since = Instant::now();
                curves.making = Some((request.clone(), since, rx));
                since
            }
        };
        // While a live folder's curves are made again, the last ones of the same choice.
        let last = curves
            .made
            .as_ref()
            .filter(|(r, _)| r.same_choice(&request))
            .map(|(_, made)| made.clone());
        (last, Some(started))
    }

    /// Waits for the curves being made (tests, which draw once and look).
    pub fn settle(&self) {
        let mut curves = self.curves.borrow_mut();
        if let Some((request, _, rx)) = curves.making.take() {
            if let Ok(made) = rx.recv() {
                curves.made = Some((request, made));
            }
        }
    }

    /// The curves of the view's choice, made here and now.
    pub fn made_now(&self, folder: &dyn Compared) -> Made {
        let _ = self.curves(folder);
        self.settle();
        self.curves(folder).0.unwrap_or_default()
    }

    /// Method `index`'s curve of the view's choice, made here and now.
    pub fn curve(&self, folder: &dyn Compared, index: usize) -> Vec<CurvePoint> {
        self.made_now(folder)
            .methods
            .get(index)
            .cloned()
            .unwrap_or_default()
    }

    /// The axis's extent: the budget's on its own axis, else the curves' last made.
    pub fn extent(&self, folder: &dyn Compared) -> (f64, f64) {
        let axis = self.axis(folder);
        if axis == budget_axis(folder.budget()) {
            return (1.0, planned(folder));
        }
        let runs = folder.runs().iter().filter(|r| !r.training.is_empty());
        match axis {
            XAxis::Episode => (1.0, runs.map(|r| r.episodes()).max().unwrap_or(1) as f64),
            XAxis::Step => runs
                .map(|r| {
                    let first = r.training.lengths.first().copied().unwrap_or(0);
                    (
                        f64::from(first),
                        r.training.lengths.iter().map(|&l| l as f64).sum(),
                    )
                })
                .reduce(|(a, b), (c, d)| (f64::min(a, c), f64::max(b, d)))
                .unwrap_or((0.0, 1.0)),
            // On file only: the curves' once made.
            XAxis::Wall => {
                let request = self.request(folder);
                self.curves
                    .borrow()
                    .made
                    .as_ref()
                    .filter(|(r, _)| r.same_choice(&request))
                    .map_or((0.0, 1.0), |(_, made)| made.extent)
            }
        }
    }

    /// The range shown on the axis, first to last.
    pub fn range(&self, folder: &dyn Compared) -> (f64, f64) {
        let all = self.extent(folder);
        self.zoom.map_or(all, |zoom| clamp(zoom, all))
    }

    /// Shows method `index` if hidden, hides it if shown.
    pub fn toggle(&mut self, index: usize) {
        if !self.hidden.remove(&index) {
            self.hidden.insert(index);
        }
    }

    /// The next metric on file (`by` 1) or the previous (-1).
    fn next_metric(&mut self, folder: &dyn Compared, by: isize) {
        let metrics = self.on_file(folder).metrics;
        let at = metrics.iter().position(|&m| m == self.metric).unwrap_or(0) as isize;
        let n = metrics.len().max(1) as isize;
        self.metric = metrics
            .get((at + by).rem_euclid(n) as usize)
            .copied()
            .unwrap_or(Metric::Return);
    }

    /// The next x axis on file: episode, step, wall time; or, where not every run has
    /// steps and no wall time is on file, why the episode is the only one.
    fn next_axis(&mut self, folder: &dyn Compared) -> Outcome<super::Intent> {
        let wall = self.on_file(folder).wall;
        if !wall && !Self::stepped(folder) {
            return Outcome::Said(
                "the episode is the only x axis here: not every run's file gives its \
                 episodes' steps"
                    .into(),
            );
        }
        self.axis = Some(match self.axis(folder) {
            XAxis::Episode => XAxis::Step,
            XAxis::Step if wall => XAxis::Wall,
            XAxis::Step | XAxis::Wall => XAxis::Episode,
        });
        self.zoom = None;
        Outcome::Done
    }

    /// The next smoothing window: the folder's, none, then wider.
    fn next_window(&mut self, folder: &dyn Compared) {
        let own = folder.window().max(1);
        let mut windows = vec![own];
        windows.extend(WINDOWS.iter().copied().filter(|&w| w != own));
        let at = windows
            .iter()
            .position(|&w| w == self.window(folder))
            .unwrap_or(0);
        self.window = Some(windows[(at + 1) % windows.len()]);
    }
}

/// `range` in whole units, moved inside `all` (kept as wide as it fits) and no narrower
/// than [`NARROWEST`] units (nor than `all`).
fn clamp((from, to): (f64, f64), (first, last): (f64, f64)) -> (f64, f64) {
    let span = last - first;
    let width = (to - from).round().clamp(NARROWEST.min(span), span);
    let from = from.round().clamp(first, last - width);
    (from, from + width)
}

/// What the Curves view's keys do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurvesCommand {
    /// The next (1) or previous (-1) metric on file.
    Metric(isize),
    /// The next x axis.
    Axis,
    /// The next smoothing window.
    Smoothing,
    /// The legend's cursor by one method.
    Pick(isize),
    Toggle,
    Statistic,
    ZoomIn,
    ZoomOut,
    /// Along the axis by this many quarters of the view.
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

/// The Curves view's keys (the status bar drops the last first on a narrow terminal).
const KEYS: &[Binding<CurvesCommand>] = &[
    Binding {
        keys: &[(ch('y'), C::Metric(1)), (ch('Y'), C::Metric(-1))],
        help: (
            "y Y",
            "the next metric on file, the previous: return, length, loss, ε, steps/s, each \
             source's activation A and probability P (what the folder's files hold)",
        ),
        bar: Some(("y", "metric")),
    },
    Binding {
        keys: &[(ch('x'), C::Axis)],
        help: (
            "x",
            "the x axis: environment step, wall time (where on file), episode",
        ),
        bar: Some(("x", "axis")),
    },
    Binding {
        keys: &[(ch('s'), C::Smoothing)],
        help: (
            "s",
            "the smoothing: the folder's moving average, none, 5, 25, 50, 100 episodes",
        ),
        bar: Some(("s", "smooth")),
    },
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
            "zoom in and out, move along the axis, all of it",
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
    type Model = dyn Compared;
    type Command = CurvesCommand;
    type Intent = super::Intent;

    fn keys(&self) -> &'static [Binding<CurvesCommand>] {
        KEYS
    }

    fn apply(&mut self, folder: &dyn Compared, command: CurvesCommand) -> Outcome<super::Intent> {
        let methods = folder.methods().len();
        let all = self.extent(folder);
        let (from, to) = self.range(folder);
        let width = to - from;
        match command {
            // Reading one method's runs, the method stays put; with every method shown,
            // there is no run to move to or come back from (Esc is then the screen's).
            C::Pick(_) if self.run.is_some() => return Outcome::Ignored,
            C::Back | C::Run(_) if self.run.is_none() => return Outcome::Ignored,
            C::Metric(by) => self.next_metric(folder, by),
            C::Axis => return self.next_axis(folder),
            C::Smoothing => self.next_window(folder),
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

    fn draw(&self, folder: &dyn Compared, frame: &mut Frame, area: Rect, theme: Theme) {
        chart::draw(frame, area, self, folder, theme);
    }

    /// Reading one method's runs, the arrows pick nothing and `[ ]` move; else the
    /// reverse.
    fn offers(&self, _: &dyn Compared, command: CurvesCommand) -> bool {
        match command {
            C::Pick(_) => self.run.is_none(),
            C::Run(_) => self.run.is_some(),
            _ => true,
        }
    }

    fn words(&self, _: &dyn Compared, command: CurvesCommand) -> Option<&'static str> {
        (command == C::Runs && self.run.is_some()).then_some("methods")
    }

    fn legend(&self, _: &dyn Compared) -> Vec<(&'static str, &'static str)> {
        vec![(
            "click",
            "a method in the legend picks it and shows or hides it; a view's name below \
             shows it",
        )]
    }

    fn on_mouse(
        &mut self,
        folder: &dyn Compared,
        mouse: MouseEvent,
        area: Rect,
    ) -> Outcome<super::Intent> {
        if mouse.kind != MouseEventKind::Down(MouseButton::Left) {
            return Outcome::Ignored;
        }
        match chart::legend_method_at(area, self, folder, mouse.column, mouse.row) {
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
