//! Teach mode's state: one activation's spreading recursion, stepped a `spread` call at a
//! time (Algorithms 1 and 2), with undo.
//!
//! The walk keeps the recursion's state ([`SpreadState`]: the pending calls and the path)
//! and its own activations, so a step costs O(1) whatever the walk's length. Undo rebuilds
//! the walk from its start, one call fewer. `r` runs the rest in slices of
//! [`Teach::advance`], so a walk of millions of calls leaves the screen and the keys
//! responsive.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use serde::Serialize;

use super::edit::GraphEdit;
use super::knobs::{refusal, walk_end, EditReport, Knob};
use super::labels;
use super::lesson::TeachConfig;
use super::lesson::WalkPosition;
use super::questions::Question;
use crate::sapnet::{Call, SapNet, SpreadState, Spreader, TraceStep};

/// Calls `r` makes between two frames: a few milliseconds' worth.
pub const CALLS_PER_FRAME: usize = 50_000;

/// Where teach mode stands: which policy is picked, and the activation in progress.
#[derive(Debug, Clone)]
pub struct Teach {
    names: Vec<String>,
    /// The names the lesson gave, where they could not tell the policies apart on the
    /// graph (`1×100`, `2×100` both read `100`): the policies are then called π0…, and the
    /// activations table gives these beside.
    descriptions: Option<Vec<String>>,
    /// The names as the paper numbers policies, π1…πN, where the given ones are π0…πN−1.
    paper_names: Option<Vec<String>>,
    /// Show `paper_names` (`p`).
    paper_numbering: bool,
    net: SapNet,
    /// The activations before the first activation of this lesson (`c` goes back to them).
    initial: Vec<f64>,
    /// The policy the arrows point at.
    cursor: usize,
    walk: Option<Walk>,
    /// `r` was pressed: the front end calls [`Teach::advance`] between frames.
    running: bool,
    /// Category of each policy, to draw related policies together.
    groups: Option<Vec<usize>>,
    /// Per policy, whether the live run had its category out of the candidates when teach
    /// mode opened on its net (empty: none, or a lesson).
    excluded: Vec<bool>,
    /// What `+` and `−` change (`1`…`5`).
    knob: Knob,
    /// Which of the picked policy's edges a weight edit changes (`e` moves it).
    edge: usize,
    /// The last edit and what it changed.
    last_edit: Option<EditReport>,
    /// Something the last key did that the screen must say: an edit refused, pending
    /// calls made before a new activation.
    notice: Option<String>,
    /// A line being typed (an edge to add, the file to save to), if any.
    prompt: Option<Prompt>,
    /// Exercise mode (`X`): before each call the student types its ΔA; the score so far.
    exercise: Option<Score>,
    /// The lesson file this session was opened from, for what the net does not hold: the
    /// policies' descriptions where categories build M, and what `w` writes back.
    source: TeachConfig,
    /// `M`: clicks edit edges — a first click picks a policy, a second joins it to the
    /// one clicked or cuts their edge.
    linking: bool,
    /// In `M` mode, the policy the first click picked.
    link_from: Option<usize>,
    /// D: the share of every activation lost between two activations (0: the paper).
    decay: f64,
    /// A and P at the end of each walk finished since the lesson (or `c`) started.
    history: Vec<TimeRow>,
    /// The lesson's questions, asked one after another when a walk ends.
    questions: Vec<Question>,
    /// The next question to ask.
    next_question: usize,
    /// The questions' score.
    quiz: Score,
    /// `r`: calls made one at a time at [`Teach::speed`], the next when this is due.
    animation: Option<Instant>,
    /// Index into [`SPEEDS`].
    speed: usize,
    /// What the panel under the edits shows (`v` cycles).
    panel: WalkPanel,
}

/// Calls a second `r` makes along the edges (`<` and `>` choose).
pub const SPEEDS: [f64; 6] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0];
/// `r`'s speed at the start: two calls a second, slow enough to follow on the graph.
const DEFAULT_SPEED: usize = 2;

/// What the panel under the edits shows; `v` goes to the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WalkPanel {
    /// The calls made, one row each.
    #[default]
    Trace,
    /// The calls as the recursion makes them: each under the call that made it.
    Tree,
    /// A and P of every policy over the calls made so far.
    Chart,
    /// A and P of every policy after each activation's walk.
    ThroughTime,
}

impl WalkPanel {
    /// The panel `v` shows after this one.
    pub fn following(self) -> Self {
        match self {
            Self::Trace => Self::Tree,
            Self::Tree => Self::Chart,
            Self::Chart => Self::ThroughTime,
            Self::ThroughTime => Self::Trace,
        }
    }

    /// Its name, in the panel's title and the status bar.
    pub fn name(self) -> &'static str {
        match self {
            Self::Trace => "trace",
            Self::Tree => "tree",
            Self::Chart => "chart",
            Self::ThroughTime => "through time",
        }
    }
}

/// A and P of every policy at the end of one activation's walk (`through_time` in
/// `--json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TimeRow {
    /// The policy activated.
    pub activated: usize,
    pub activations: Vec<f64>,
    pub probabilities: Vec<f64>,
}

/// The weight of an edge added by the mouse (`M`): Fig. 2's; `5` and `+`/`−` change it.
pub const MOUSE_EDGE_WEIGHT: f64 = 0.4;

/// An exercise's score: answers right of answers given.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Score {
    pub right: usize,
    pub asked: usize,
}

/// How far a typed ΔA may be from the call's and count as right: the screen gives ΔA to
/// six decimals, a student working by hand to three or four.
pub const ANSWER_TOLERANCE: f64 = 1e-3;

/// A line the user types in teach mode, and what Enter does with it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Prompt {
    pub kind: PromptKind,
    pub text: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PromptKind {
    /// `E`: `I J W`, an edge of weight W between policies I and J (0-based, as
    /// `--add-edge` takes them), added or reweighted.
    AddEdge,
    /// `w`: the path the lesson is written to.
    Save,
    /// Exercise mode: the ΔA the next call deposits, or `stop` where eq. 10 stops it.
    Predict,
    /// `n` in a lesson of categories: the new policy's category.
    AddPolicy,
    /// `C`: the picked policy's new category.
    SetCategory,
    /// The lesson's `k`-th question, at a walk's end.
    Question(usize),
}

impl PromptKind {
    /// What the prompt asks, on screen.
    pub fn question(self) -> &'static str {
        match self {
            PromptKind::AddEdge => "add edge I J W (0-based, as --add-edge):",
            PromptKind::Save => "save the lesson to:",
            PromptKind::Predict => "ΔA of the next call (a number, or stop)?",
            PromptKind::AddPolicy => "category of the new policy (as --add-policy):",
            PromptKind::SetCategory => "new category of the picked policy (as --set-category):",
            PromptKind::Question(_) => "the lesson asks:",
        }
    }
}

/// The file `w` offers.
pub const LESSON_FILE: &str = "lesson.ron";

/// One activation being stepped.
#[derive(Debug, Clone)]
struct Walk {
    policy: usize,
    /// The activations just before `A[policy] += 𝒜`.
    before: Vec<f64>,
    /// The calls made so far, in order.
    trace: Vec<TraceStep>,
    /// The recursion after those calls.
    state: SpreadState,
    /// The activations after those calls (the net's, once synced).
    activations: Vec<f64>,
    /// `activations − before`, kept with them.
    deposited: Vec<f64>,
}

/// What a front end draws of the walk in progress.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkView<'a> {
    pub policy: usize,
    /// The calls made so far.
    pub trace: &'a [TraceStep],
    /// The pending calls, the next one last (the recursion's stack).
    pub pending: &'a [Call],
    /// The walk from the activated policy to the last call's target.
    pub path: &'a [usize],
    pub done: bool,
    /// What the walk has added to each activation so far, eq. 8's 𝒜 included: eq. 11's
    /// sum of ΔA.
    pub deposited: &'a [f64],
}

impl Teach {
    pub fn new(names: Vec<String>, net: SapNet) -> Self {
        let initial = net.activations().to_vec();
        let (names, descriptions) = match labels::distinct_labels(&names) {
            Some(_) => (names, None),
            None => (
                (0..names.len()).map(|i| format!("π{i}")).collect(),
                Some(names),
            ),
        };
        let zero_based = names
            .iter()
            .enumerate()
            .all(|(i, name)| *name == format!("π{i}"));
        let paper_names = zero_based.then(|| (1..=names.len()).map(|i| format!("π{i}")).collect());
        Self {
            paper_names,
            paper_numbering: false,
            names,
            descriptions,
            net,
            initial,
            cursor: 0,
            walk: None,
            running: false,
            groups: None,
            excluded: Vec::new(),
            knob: Knob::default(),
            edge: 0,
            last_edit: None,
            notice: None,
            prompt: None,
            exercise: None,
            source: TeachConfig::default(),
            linking: false,
            link_from: None,
            decay: 0.0,
            history: Vec::new(),
            questions: Vec::new(),
            next_question: 0,
            quiz: Score::default(),
            animation: None,
            speed: DEFAULT_SPEED,
            panel: WalkPanel::default(),
        }
    }

    /// The lesson file the session was opened from: its policies' descriptions, where
    /// categories build M, are kept for the category edits and for `w`.
    pub fn with_source(mut self, source: TeachConfig) -> Self {
        self.decay = source.decay;
        self.questions = source.questions.clone();
        self.source = source;
        self
    }

    /// D between activations (`--decay`; 0 is the paper).
    pub fn with_decay(mut self, decay: f64) -> Self {
        self.decay = decay;
        self
    }

    pub fn decay(&self) -> f64 {
        self.decay
    }

    /// A and P after each walk so far, and the walk on screen's as it stands last (`true`
    /// while it is still in progress).
    pub fn through_time(&self) -> (Vec<TimeRow>, bool) {
        let mut rows = self.history.clone();
        let mut in_progress = false;
        if let Some(walk) = &self.walk {
            rows.push(TimeRow {
                activated: walk.policy,
                activations: self.net.activations().to_vec(),
                probabilities: self.net.probabilities(),
            });
            in_progress = !walk.state.is_done();
        }
        (rows, in_progress)
    }

    /// Reopens a saved walk (`walk` of a lesson file): activates its policy and makes its
    /// calls.
    pub fn resume_walk(&mut self, position: WalkPosition) {
        if position.activate >= self.net.len() {
            return;
        }
        self.cursor = position.activate;
        self.activate();
        for _ in 0..position.calls {
            self.call();
        }
        self.sync();
    }

    /// What the panel under the edits shows.
    pub fn panel(&self) -> WalkPanel {
        self.panel
    }

    /// `v`: the trace, the tree, the chart, A and P through time, in turn.
    pub fn next_panel(&mut self) {
        self.panel = self.panel.following();
    }

    /// `r`'s speed, in calls a second.
    pub fn speed(&self) -> f64 {
        SPEEDS[self.speed]
    }

    /// `<` / `>`: `r` slower or faster.
    pub fn change_speed(&mut self, faster: bool) {
        self.speed = if faster {
            (self.speed + 1).min(SPEEDS.len() - 1)
        } else {
            self.speed.saturating_sub(1)
        };
        self.notice = Some(format!("r walks {} calls a second", self.speed()));
    }

    /// `r`: the walk's calls made one at a time at [`speed`](Self::speed), lit on the
    /// graph as they go; `r` again pauses.
    pub fn animate(&mut self) {
        self.running = false;
        let going = self.walk.as_ref().is_some_and(|w| !w.state.is_done());
        self.animation = match self.animation {
            Some(_) => None,
            None if going => Some(Instant::now()),
            None => None,
        };
    }

    /// Whether `r` is walking.
    pub fn is_animating(&self) -> bool {
        self.animation.is_some()
    }

    /// The questions' score, once one is answered.
    pub fn quiz(&self) -> Option<Score> {
        (self.quiz.asked > 0).then_some(self.quiz)
    }

    /// How many questions the lesson holds, and how many are asked.
    pub fn questions(&self) -> (usize, usize) {
        (self.questions.len(), self.next_question)
    }

    /// What the prompt asks, on screen: a question's own text.
    pub fn prompt_question(&self) -> Option<String> {
        let prompt = self.prompt.as_ref()?;
        Some(match prompt.kind {
            PromptKind::Question(k) => self.questions.get(k).map(Question::prompt)?,
            kind => kind.question().to_string(),
        })
    }

    /// At a walk's end, the next of the lesson's questions is asked.
    fn ask_at_walk_end(&mut self) {
        let done = self.walk.as_ref().is_some_and(|w| w.state.is_done());
        if done && self.prompt.is_none() && self.next_question < self.questions.len() {
            self.running = false;
            self.animation = None;
            self.prompt = Some(Prompt {
                kind: PromptKind::Question(self.next_question),
                text: String::new(),
            });
        }
    }

    /// Checks the answer to question `k`, says right or the answer, and asks the next.
    fn check_question(&mut self, k: usize, typed: &str) {
        let Some(question) = self.questions.get(k) else {
            return;
        };
        let verdict = question.check(typed, self.names());
        self.next_question = k + 1;
        self.quiz.asked += 1;
        if verdict.right {
            self.quiz.right += 1;
        }
        let said = if verdict.right {
            format!("right: {}", verdict.answer)
        } else if typed.trim().is_empty() {
            format!("no answer: it is {}", verdict.answer)
        } else {
            format!("not {}: it is {}", typed.trim(), verdict.answer)
        };
        self.notice = Some(format!(
            "{said} · questions {}/{}",
            self.quiz.right, self.quiz.asked
        ));
        self.ask_at_walk_end();
    }

    /// Whether the lesson's graph is built from categories (eq. 3–5), so that the policies
    /// have a category to change.
    pub fn has_categories(&self) -> bool {
        !self.source.descriptions.is_empty()
    }

    /// The picked policy's category (the first prototype's key), where there are categories.
    pub fn category_of(&self, i: usize) -> Option<String> {
        let prototype = self.source.first_prototype().ok()?;
        let policy = self.source.descriptions.get(i)?;
        Some(super::category::key(&prototype, policy))
    }

    /// The names as the lesson gives them, and how the screen calls the policies from them.
    fn set_names(&mut self, given: Vec<String>) {
        let fresh = Teach::new(given, self.net.clone());
        self.names = fresh.names;
        self.descriptions = fresh.descriptions;
        self.paper_names = fresh.paper_names;
        if self.paper_names.is_none() {
            self.paper_numbering = false;
        }
    }

    /// Draws policies of the same category together (the graph's categories).
    pub fn with_groups(mut self, groups: Vec<usize>) -> Self {
        self.groups = (groups.len() == self.net.len()).then_some(groups);
        self
    }

    pub fn groups(&self) -> Option<&[usize]> {
        self.groups.as_deref()
    }

    /// The live run's excluded policies, shown on the graph (spreading by hand ignores them:
    /// exclusion acts on eq. 6's draw, not on eq. 8–11).
    pub fn with_excluded(mut self, excluded: Vec<bool>) -> Self {
        self.excluded = excluded;
        self
    }

    pub fn excluded(&self) -> &[bool] {
        &self.excluded
    }

    /// The policies' names as shown: π0… as the lesson gives them, or π1… (`p`).
    pub fn names(&self) -> &[String] {
        match (&self.paper_names, self.paper_numbering) {
            (Some(paper), true) => paper,
            _ => &self.names,
        }
    }

    /// What the lesson called each policy, where the screen calls them π0… instead (see
    /// [`new`](Self::new)).
    pub fn descriptions(&self) -> Option<&[String]> {
        self.descriptions.as_deref()
    }

    /// `p`: the paper's numbering π1…πN, or back to π0…; `false` when the lesson names
    /// its policies itself.
    pub fn toggle_numbering(&mut self) -> bool {
        if self.paper_names.is_some() {
            self.paper_numbering = !self.paper_numbering;
        }
        self.paper_names.is_some()
    }

    /// Which numbering is on screen, for the status bar: `π0…` or `π1…` (none for names
    /// the lesson gives).
    pub fn numbering(&self) -> Option<&'static str> {
        self.paper_names.as_ref().map(|_| {
            if self.paper_numbering {
                "π1…"
            } else {
                "π0…"
            }
        })
    }

    /// The net with the activations as they stand after the calls made so far.
    pub fn net(&self) -> &SapNet {
        &self.net
    }

    pub fn cursor(&self) -> usize {
        self.cursor
    }

    /// Moves the cursor by `delta` policies, wrapping around.
    pub fn move_cursor(&mut self, delta: isize) {
        let n = self.net.len() as isize;
        if n > 0 {
            self.cursor = (self.cursor as isize + delta).rem_euclid(n) as usize;
            self.edge = 0;
        }
    }

    /// Picks policy `i` (a click on its node or row); out of range changes nothing. In
    /// `M` mode a second click on another policy joins the two (weight
    /// [`MOUSE_EDGE_WEIGHT`]) or cuts their edge, and a second click on the same one lets
    /// it go.
    pub fn pick(&mut self, i: usize) {
        if i >= self.net.len() {
            return;
        }
        match self.link_from.take() {
            Some(from) if self.linking && from != i => {
                let edit = if self.net.graph().weight(from, i).is_some() {
                    GraphEdit::Cut { i: from, j: i }
                } else {
                    GraphEdit::Add {
                        i: from,
                        j: i,
                        w: MOUSE_EDGE_WEIGHT,
                    }
                };
                self.edit_graph(edit);
                self.select_edge_to(i);
                return;
            }
            Some(_) => {
                self.notice = Some(format!("{} let go", self.names()[i]));
            }
            None if self.linking => {
                self.link_from = Some(i);
                self.notice = Some(format!(
                    "{} picked: click another policy to join them or cut their edge",
                    self.names()[i]
                ));
            }
            None => {}
        }
        self.cursor = i;
        self.edge = 0;
    }

    /// `M`: clicks edit edges, or pick as before.
    pub fn toggle_linking(&mut self) {
        self.linking = !self.linking;
        self.link_from = None;
        self.notice = Some(if self.linking {
            "M: click a policy, then another: joined at 0.4 (5 and +/− reweigh) or their \
             edge cut; M again ends it"
                .to_string()
        } else {
            "M ended: a click picks a policy".to_string()
        });
    }

    /// Whether clicks edit edges (`M`).
    pub fn is_linking(&self) -> bool {
        self.linking
    }

    /// Selects the picked policy's edge to `j`, if there is one, for `5` and `x`.
    fn select_edge_to(&mut self, j: usize) {
        if let Some(at) = self
            .net
            .graph()
            .neighbours(self.cursor)
            .position(|(k, _)| k == j)
        {
            self.edge = at;
            self.knob = Knob::EdgeWeight;
        }
    }

    /// `n`: adds a policy — at once where the lesson gives its edges (joined to nothing),
    /// or asking its category where categories build M.
    pub fn add_policy(&mut self) {
        if self.has_categories() {
            self.open_prompt(PromptKind::AddPolicy);
        } else {
            self.edit_graph(GraphEdit::AddPolicy {
                category: super::edit::NO_CATEGORY.to_string(),
            });
        }
    }

    /// `D`: removes the picked policy and its edges.
    pub fn remove_policy(&mut self) {
        self.edit_graph(GraphEdit::RemovePolicy { i: self.cursor });
    }

    /// `C`: asks the picked policy's new category (refused where there are none).
    pub fn change_category(&mut self) {
        if self.has_categories() {
            self.open_prompt(PromptKind::SetCategory);
        } else {
            self.edit_graph(GraphEdit::SetCategory {
                i: self.cursor,
                category: super::edit::NO_CATEGORY.to_string(),
            });
        }
    }

    /// What `+` and `−` change.
    pub fn knob(&self) -> Knob {
        self.knob
    }

    /// `1`…`5`: chooses what `+` and `−` change.
    pub fn choose_knob(&mut self, knob: Knob) {
        self.knob = knob;
    }

    /// The edge a weight edit changes: the picked policy's `e`-th, as `(picked, other)`.
    pub fn selected_edge(&self) -> Option<(usize, usize)> {
        let degree = self.net.graph().degree(self.cursor);
        (degree > 0).then(|| {
            let (j, _) = self
                .net
                .graph()
                .neighbours(self.cursor)
                .nth(self.edge % degree)
                .expect("within the degree");
            (self.cursor, j)
        })
    }

    /// `e`: selects the picked policy's next edge (and chooses the weight knob).
    pub fn next_edge(&mut self) {
        let degree = self.net.graph().degree(self.cursor);
        if degree > 0 {
            self.edge = (self.edge + 1) % degree;
        }
        self.knob = Knob::EdgeWeight;
    }

    /// The last edit and what it changed, until the next one.
    pub fn last_edit(&self) -> Option<&EditReport> {
        self.last_edit.as_ref()
    }

    /// What the last key did that needs saying, if anything.
    pub fn notice(&self) -> Option<&str> {
        self.notice.as_deref()
    }

    /// `+` / `−`: turns the chosen knob one step. The walk on screen restarts from the
    /// activations it started from, and [`last_edit`](Self::last_edit) compares its end
    /// before and after. A value the net refuses changes nothing and is said.
    pub fn edit(&mut self, up: bool) {
        self.running = false;
        self.animation = None;
        self.notice = None;
        let (policy, before) = match &self.walk {
            Some(w) => (Some(w.policy), w.before.clone()),
            None => (None, self.net.activations().to_vec()),
        };
        let mut start = self.net.clone();
        start
            .set_activations(before.clone())
            .expect("activations of the same graph");
        let from = self.knob.value(&start, self.selected_edge());
        let turned = match self.knob.turn(&start, self.selected_edge(), up) {
            Ok(net) => net,
            Err(refused) => {
                // In the screen's names: the net's message numbers the policies from 0.
                let names = self.names();
                let (what, why) = match (self.knob, self.selected_edge()) {
                    (Knob::EdgeWeight, Some((i, j))) => (
                        format!("M({},{})", names[i], names[j]),
                        refusal(&refused, names),
                    ),
                    (Knob::EdgeWeight, None) => (
                        "M".to_string(),
                        format!("{} has no edge to change", names[self.cursor]),
                    ),
                    (knob, _) => (knob.symbol().to_string(), refusal(&refused, names)),
                };
                self.notice = Some(format!("{what} stays {from}: {why}"));
                return;
            }
        };
        let (old_a, old_p, old_calls) = walk_end(&start, policy, &before);
        let (new_a, new_p, new_calls) = walk_end(&turned, policy, &before);
        self.last_edit = Some(EditReport {
            knob: self.knob,
            edge: self
                .selected_edge()
                .filter(|_| self.knob == Knob::EdgeWeight),
            to: self.knob.value(&turned, self.selected_edge()),
            from,
            policy,
            calls: (old_calls, new_calls),
            activations: (old_a, new_a),
            probabilities: (old_p, new_p),
        });
        self.net = turned;
        if self.knob == Knob::EdgeWeight && self.has_categories() {
            // M is now set by hand, not by the categories: the lesson gives its edges.
            self.source.descriptions.clear();
            self.notice = Some(
                "M set by hand: the lesson now gives its graph by its edges, not by categories"
                    .to_string(),
            );
        }
        if let Some(policy) = policy {
            self.walk = Some(self.start(policy, before));
            self.sync();
        }
    }

    /// `a`: activates the policy under the cursor as after a positive transition (eq. 8),
    /// queueing the first `spread` calls. A walk still in progress is finished first, so
    /// its deposits are not lost, and the screen says so.
    pub fn activate(&mut self) {
        self.notice = None;
        let pending = self
            .walk
            .as_ref()
            .filter(|w| !w.state.is_done())
            .map(|w| w.policy);
        let made_before = self.walk.as_ref().map_or(0, |w| w.trace.len());
        self.run_to_end();
        if let Some(policy) = pending {
            let made = self.walk.as_ref().map_or(0, |w| w.trace.len()) - made_before;
            self.notice = Some(format!(
                "{}'s walk was not done: its {made} remaining calls were made first",
                self.names()[policy]
            ));
        }
        if let Some(walk) = &self.walk {
            // The walk before this one ends here: a row of the table through time, then
            // the decay between the two activations.
            self.history.push(TimeRow {
                activated: walk.policy,
                activations: self.net.activations().to_vec(),
                probabilities: self.net.probabilities(),
            });
            if self.decay > 0.0 {
                let kept = 1.0 - self.decay;
                let decayed = self.net.activations().iter().map(|a| a * kept).collect();
                self.set_activations(decayed);
            }
        }
        let before = self.net.activations().to_vec();
        let walk = self.start(self.cursor, before);
        self.walk = Some(walk);
        self.sync();
    }

    /// `s`: makes the next `spread` call. Returns it, or `None` when there is nothing to
    /// step.
    pub fn step(&mut self) -> Option<TraceStep> {
        self.running = false;
        self.animation = None;
        self.notice = None;
        let call = self.call();
        self.sync();
        self.ask_at_walk_end();
        call
    }

    /// Makes every remaining call of the walk in progress.
    pub fn run_to_end(&mut self) {
        self.running = false;
        self.animation = None;
        while self.call().is_some() {}
        self.sync();
    }

    /// `R` in a front end: the remaining calls are made by [`advance`](Self::advance), as
    /// fast as it goes.
    pub fn run(&mut self) {
        self.animation = None;
        self.running = self.walk.as_ref().is_some_and(|w| !w.state.is_done());
        self.ask_at_walk_end();
    }

    /// Whether `r` is still making calls.
    pub fn is_running(&self) -> bool {
        self.running
    }

    /// Makes up to `calls` of the remaining calls while running; returns how many.
    pub fn advance(&mut self, calls: usize) -> usize {
        self.advance_at(calls, Instant::now())
    }

    /// [`advance`](Self::advance) at the time `now`: `r`'s walk makes the calls due by
    /// then at its speed (at most one a frame, so each is seen on the graph).
    pub fn advance_at(&mut self, calls: usize, now: Instant) -> usize {
        if let Some(due) = self.animation {
            if now < due {
                return 0;
            }
            let made = usize::from(self.call().is_some());
            self.sync();
            let going = self.walk.as_ref().is_some_and(|w| !w.state.is_done());
            self.animation = going.then(|| now + Duration::from_secs_f64(1.0 / SPEEDS[self.speed]));
            self.ask_at_walk_end();
            return made;
        }
        if !self.running {
            return 0;
        }
        let mut made = 0;
        while made < calls && self.call().is_some() {
            made += 1;
        }
        if made < calls {
            self.running = false;
        }
        self.sync();
        self.ask_at_walk_end();
        made
    }

    /// `u`: takes back the last call (or, before any, the activation itself).
    pub fn undo(&mut self) {
        self.running = false;
        self.animation = None;
        self.notice = None;
        let Some(walk) = self.walk.take() else {
            return;
        };
        let mut trace = walk.trace;
        if trace.pop().is_none() {
            self.set_activations(walk.before);
            return;
        }
        let mut rebuilt = self.start(walk.policy, walk.before);
        for _ in 0..trace.len() {
            let mut spreader = Spreader::resume(self.net.graph(), rebuilt.state);
            spreader.step(&mut rebuilt.activations);
            rebuilt.state = spreader.suspend();
        }
        rebuilt.trace = trace;
        self.walk = Some(rebuilt);
        self.sync();
    }

    /// `c`: back to the activations the lesson started with.
    pub fn reset(&mut self) {
        self.running = false;
        self.animation = None;
        self.notice = None;
        self.walk = None;
        self.history.clear();
        self.set_activations(self.initial.clone());
    }

    /// The walk in progress, if any.
    pub fn walk(&self) -> Option<WalkView<'_>> {
        let walk = self.walk.as_ref()?;
        Some(WalkView {
            policy: walk.policy,
            trace: &walk.trace,
            pending: walk.state.pending(),
            path: walk.state.path(),
            done: walk.state.is_done(),
            deposited: &walk.deposited,
        })
    }

    /// The line being typed, if any: while there is one every key goes to it.
    pub fn prompt(&self) -> Option<&Prompt> {
        self.prompt.as_ref()
    }

    /// `E` or `w`: starts typing an edge to add, or the file to save to (`lesson.ron`
    /// offered).
    pub fn open_prompt(&mut self, kind: PromptKind) {
        self.running = false;
        self.notice = None;
        let text = match kind {
            PromptKind::AddEdge | PromptKind::Predict | PromptKind::Question(_) => String::new(),
            PromptKind::Save => LESSON_FILE.to_string(),
            PromptKind::AddPolicy | PromptKind::SetCategory => {
                self.category_of(self.cursor).unwrap_or_default()
            }
        };
        self.prompt = Some(Prompt { kind, text });
    }

    /// A character typed into the prompt.
    pub fn prompt_type(&mut self, c: char) {
        if let Some(prompt) = &mut self.prompt {
            prompt.text.push(c);
        }
    }

    /// Backspace in the prompt.
    pub fn prompt_backspace(&mut self) {
        if let Some(prompt) = &mut self.prompt {
            prompt.text.pop();
        }
    }

    /// Esc in the prompt: nothing is done.
    pub fn prompt_cancel(&mut self) {
        if let Some(PromptKind::Question(k)) = self.prompt.take().map(|p| p.kind) {
            // Skipped: its answer stays hidden, the next is asked.
            self.next_question = k + 1;
            self.notice = Some("question skipped".to_string());
            self.ask_at_walk_end();
        }
    }

    /// Enter in the prompt: adds the edge or writes the lesson; what went wrong (a value
    /// not read, an edit the lesson or the net refuses, a file not written) is said and
    /// changes nothing.
    pub fn prompt_submit(&mut self) {
        let Some(prompt) = self.prompt.take() else {
            return;
        };
        match prompt.kind {
            PromptKind::AddEdge => {
                let values: Vec<String> =
                    prompt.text.split_whitespace().map(str::to_string).collect();
                match GraphEdit::parse("--add-edge", &values) {
                    Ok(edit) => self.edit_graph(edit),
                    Err(why) => {
                        self.notice = Some(format!("no edge added: {why}"));
                    }
                }
            }
            PromptKind::Predict => self.check_answer(&prompt.text),
            PromptKind::Question(k) => self.check_question(k, &prompt.text),
            PromptKind::AddPolicy => self.edit_graph(GraphEdit::AddPolicy {
                category: prompt.text.trim().to_string(),
            }),
            PromptKind::SetCategory => self.edit_graph(GraphEdit::SetCategory {
                i: self.cursor,
                category: prompt.text.trim().to_string(),
            }),
            PromptKind::Save => {
                let path = PathBuf::from(prompt.text.trim());
                self.notice = Some(match self.lesson_file().save(&path) {
                    Ok(()) => format!(
                        "wrote {}: `sapnet teach --config {}` opens it{}",
                        path.display(),
                        path.display(),
                        self.walk
                            .as_ref()
                            .map(|w| format!(
                                " at call {} of {}'s walk",
                                w.trace.len(),
                                self.names()[w.policy]
                            ))
                            .unwrap_or_default()
                    ),
                    Err(error) => format!("not saved: {error:#}"),
                });
            }
        }
    }

    /// `X`: exercise mode on (the score from 0) or off.
    pub fn toggle_exercise(&mut self) {
        self.exercise = match self.exercise {
            Some(_) => None,
            None => Some(Score::default()),
        };
        self.notice = Some(match self.exercise {
            Some(_) => format!(
                "exercise: s asks the next call's ΔA first (right within {ANSWER_TOLERANCE}); \
                 X ends it"
            ),
            None => "exercise ended".to_string(),
        });
    }

    /// The exercise's score, in exercise mode.
    pub fn score(&self) -> Option<Score> {
        self.exercise
    }

    /// `s`: in exercise mode, asks the next call's ΔA before making it; else makes it.
    pub fn step_or_ask(&mut self) {
        let next = self.walk.as_ref().and_then(|w| w.state.pending().last());
        if self.exercise.is_some() && next.is_some() {
            self.open_prompt(PromptKind::Predict);
        } else {
            self.step();
        }
    }

    /// Checks `answer` against the next call (eq. 10: ΔA = η/(h×Ω) where Ω < T_ω, else
    /// the call stops), says right or the working, counts it, then makes the call.
    fn check_answer(&mut self, answer: &str) {
        let Some(call) = self
            .walk
            .as_ref()
            .and_then(|w| w.state.pending().last().copied())
        else {
            return;
        };
        let threshold = self.net.params().threshold;
        let stops = call.omega >= threshold;
        let delta = call.eta / (call.h as f64 * call.omega);
        let answer = answer.trim();
        let said_stop = ["stop", "stops", "stopped"].contains(&answer.to_lowercase().as_str());
        let right = match (stops, said_stop, answer.parse::<f64>()) {
            (true, true, _) => true,
            (false, false, Ok(x)) => (x - delta).abs() <= ANSWER_TOLERANCE,
            _ => false,
        };
        let names = self.names();
        let working = if stops {
            format!(
                "eq. 10: Ω < T_ω is {:.4} < {threshold}, false: the call stops, ΔA = 0",
                call.omega
            )
        } else {
            format!(
                "eq. 10: Ω < T_ω is {:.4} < {threshold}, true: ΔA[{}] = η/(h×Ω) = \
                 {:.6}/({}×{:.4}) = {delta:.6}",
                call.omega, names[call.to], call.eta, call.h, call.omega
            )
        };
        let score = self.exercise.get_or_insert_with(Score::default);
        score.asked += 1;
        if right {
            score.right += 1;
        }
        let score = *score;
        let verdict = if right {
            format!("right ({working})")
        } else if answer.is_empty() {
            format!("no answer: {working}")
        } else {
            format!("not {answer}: {working}")
        };
        self.step();
        self.notice = Some(format!("{verdict} · score {}/{}", score.right, score.asked));
    }

    /// `x`: cuts the picked policy's selected edge (`e` selects it).
    pub fn cut_selected_edge(&mut self) {
        self.running = false;
        match self.selected_edge() {
            Some((i, j)) => self.edit_graph(GraphEdit::Cut { i, j }),
            None => self.notice = Some(format!("{} has no edge to cut", self.names()[self.cursor])),
        }
    }

    /// Edits the graph or its policies as `sapnet teach --add-edge`, `--cut-edge`,
    /// `--add-policy`, `--remove-policy` and `--set-category` do (the same checks, the
    /// same refusals), then builds the net the lesson file would: a refusal changes
    /// nothing and is said. The walk on screen restarts from the activations it started
    /// from (a new policy's 0, a removed one's dropped), as a knob's turn restarts it.
    pub fn edit_graph(&mut self, edit: GraphEdit) {
        self.running = false;
        self.animation = None;
        self.notice = None;
        let (policy, before) = match &self.walk {
            Some(w) => (Some(w.policy), w.before.clone()),
            None => (None, self.net.activations().to_vec()),
        };
        let mut lesson = self.lesson_file();
        // The walk restarts on the edited graph: no position to check against it.
        lesson.walk = None;
        let built = lesson.apply(&edit).and_then(|()| lesson.lesson());
        let built = match built {
            Ok(built) => built,
            Err(why) => {
                self.notice = Some(format!("{}: {why}", edit.flag()));
                return;
            }
        };
        let old_calls = walk_end(&self.net, policy, &before).2;
        let moved = policy.and_then(|p| edit.renumbered(p));
        // The built net holds the lesson's `initial`: the walk's starting activations,
        // renumbered.
        let before = built.net.activations().to_vec();
        let new_calls = walk_end(&built.net, moved, &before).2;
        let count_changed = built.net.len() != self.net.len();
        self.net = built.net;
        self.source = lesson;
        self.set_names(built.names);
        self.groups = match built.groups {
            Some(groups) => Some(groups),
            None if count_changed => None,
            None => self.groups.take(),
        };
        self.initial = edit.renumber(&self.initial, 0.0);
        if !self.excluded.is_empty() {
            self.excluded = edit.renumber(&self.excluded, false);
        }
        self.cursor = edit
            .renumbered(self.cursor)
            .unwrap_or(self.cursor)
            .min(self.net.len() - 1);
        if matches!(edit, GraphEdit::AddPolicy { .. }) {
            self.cursor = self.net.len() - 1;
        }
        self.edge = 0;
        self.notice = Some(match (policy, moved) {
            (Some(_), Some(p)) => format!(
                "{} done: {}'s walk {old_calls} → {new_calls} calls, restarted",
                edit.flag(),
                self.names()[p]
            ),
            (Some(_), None) => format!(
                "{} done: the walk's own policy is gone, so is its walk",
                edit.flag()
            ),
            (None, _) => format!("{} done", edit.flag()),
        });
        match moved {
            Some(policy) => {
                self.walk = Some(self.start(policy, before));
                self.sync();
            }
            None => {
                self.walk = None;
                self.set_activations(before);
            }
        }
    }

    /// The lesson as it stands, in the format `sapnet teach --config` reads: the graph
    /// (its edges, or the policies' descriptions where categories build it), T_ω, 𝒜, τ
    /// and the paths as edited, the policies' names as the lesson gave them, and as
    /// `initial` the activations the walk on screen started from (so `--activate` of its
    /// policy replays it), or those on screen without a walk.
    pub fn lesson_file(&self) -> TeachConfig {
        let params = self.net.params();
        let activations = match &self.walk {
            Some(w) => w.before.clone(),
            None => self.net.activations().to_vec(),
        };
        let names = self
            .descriptions
            .clone()
            .unwrap_or_else(|| self.names.clone());
        let default_names = names
            .iter()
            .enumerate()
            .all(|(i, name)| *name == format!("π{i}"));
        let defaults = TeachConfig::default();
        let by_categories = self.has_categories();
        TeachConfig {
            policies: self.net.len(),
            names: if default_names { Vec::new() } else { names },
            edges: if by_categories {
                Vec::new()
            } else {
                self.net.graph().edges().collect()
            },
            descriptions: self.source.descriptions.clone(),
            prototypes: if by_categories {
                params.prototypes.clone()
            } else {
                defaults.prototypes
            },
            delta: if by_categories {
                params.delta
            } else {
                defaults.delta
            },
            base_graph: if by_categories {
                params.base_graph
            } else {
                defaults.base_graph
            },
            threshold: params.threshold,
            coefficient: params.coefficient,
            temperature: params.temperature,
            paths: params.paths,
            initial: activations.iter().any(|&a| a != 0.0).then_some(activations),
            walk: self.walk.as_ref().map(|w| WalkPosition {
                activate: w.policy,
                calls: w.trace.len(),
            }),
            decay: self.decay,
            questions: self.questions.clone(),
        }
    }

    /// A walk activating `policy` from the activations `before` (eq. 8, the first calls
    /// queued).
    fn start(&self, policy: usize, before: Vec<f64>) -> Walk {
        let mut activations = before.clone();
        let state = Spreader::activate(
            self.net.graph(),
            self.net.spreading(),
            policy,
            self.net.params().coefficient,
            &mut activations,
        )
        .suspend();
        Walk {
            policy,
            before,
            trace: Vec::new(),
            state,
            activations,
            deposited: Vec::new(),
        }
    }

    /// The next call of the walk, on the walk's own activations; O(1).
    fn call(&mut self) -> Option<TraceStep> {
        let walk = self.walk.as_mut()?;
        let state = std::mem::take(&mut walk.state);
        let mut spreader = Spreader::resume(self.net.graph(), state);
        let call = spreader.step(&mut walk.activations);
        walk.state = spreader.suspend();
        walk.trace.extend(call);
        call
    }

    /// Shows the walk's activations on the net.
    fn sync(&mut self) {
        if let Some(walk) = &mut self.walk {
            walk.deposited = walk
                .activations
                .iter()
                .zip(&walk.before)
                .map(|(a, b)| a - b)
                .collect();
            let activations = walk.activations.clone();
            self.set_activations(activations);
        }
    }

    fn set_activations(&mut self, activations: Vec<f64>) {
        // The net's bounds keep every activation finite (see `SapNet::with_activations`)
        // and the count is the graph's: `set_activations` cannot refuse these.
        self.net
            .set_activations(activations)
            .expect("activations from the same graph");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teach::lesson::TeachConfig;

    fn fig2() -> Teach {
        let lesson = TeachConfig::load(None).expect("embedded Fig. 2");
        Teach::new(lesson.names, lesson.net)
    }

    #[test]
    fn stepping_to_the_end_gives_the_activation_in_one_go() {
        let mut teach = fig2();
        teach.move_cursor(1);
        teach.activate();
        assert_eq!(teach.net().activations()[1], 1.0, "eq. 8 before any call");
        let mut calls = 0;
        while teach.step().is_some() {
            calls += 1;
        }
        assert_eq!(calls, 21, "the Fig. 2 walk from π1 makes 21 calls");
        let mut whole = TeachConfig::load(None).unwrap().net;
        whole.activate(1, true);
        assert_eq!(teach.net().activations(), whole.activations());
        assert!(teach.walk().unwrap().done);
    }

    #[test]
    fn undo_takes_back_one_call_then_the_activation() {
        let mut teach = fig2();
        teach.activate();
        let after_activation = teach.net().activations().to_vec();
        let first = teach.step().unwrap();
        assert_eq!((first.from, first.to, first.h), (0, 1, 1));
        teach.step();
        teach.undo();
        assert_eq!(teach.walk().unwrap().trace, vec![first]);
        teach.undo();
        assert_eq!(teach.net().activations(), after_activation.as_slice());
        teach.undo();
        assert!(teach.walk().is_none());
        assert_eq!(teach.net().activations(), &[0.0; 4]);
    }

    #[test]
    fn a_second_activation_finishes_the_first_and_reset_clears_both() {
        let mut teach = fig2();
        teach.activate();
        teach.step();
        teach.move_cursor(-1);
        assert_eq!(teach.cursor(), 3, "the cursor wraps around");
        teach.activate();
        let mut both = TeachConfig::load(None).unwrap().net;
        both.activate(0, true);
        both.activate(3, true);
        teach.run_to_end();
        assert_eq!(teach.net().activations(), both.activations());
        teach.reset();
        assert_eq!(teach.net().activations(), &[0.0; 4]);
        assert!(teach.walk().is_none());
    }

    #[test]
    fn activating_mid_walk_says_it_finished_the_walk_first() {
        let mut teach = fig2();
        teach.activate();
        teach.step();
        assert_eq!(teach.notice(), None);
        teach.move_cursor(1);
        teach.activate();
        let notice = teach.notice().expect("a notice");
        assert!(
            notice.starts_with("π0's walk was not done: its "),
            "{notice}"
        );
        teach.step();
        assert_eq!(teach.notice(), None, "the next key clears it");
    }

    #[test]
    fn an_edit_without_a_walk_compares_the_probabilities() {
        let mut teach = fig2();
        teach.activate();
        teach.run_to_end();
        teach.reset();
        teach.move_cursor(1);
        teach.activate();
        teach.run_to_end();
        let before = teach.net().activations().to_vec();
        teach.walk = None;
        teach.choose_knob(Knob::Temperature);
        teach.edit(true);
        let report = teach.last_edit().expect("a report");
        assert_eq!((report.from.as_str(), report.to.as_str()), ("1", "2"));
        assert_eq!(report.calls, (0, 0));
        assert_eq!(report.activation_change(), vec![0.0; 4]);
        // π1 holds the most activation: a hotter softmax gives it less of P.
        assert!(report.probability_change()[1] < 0.0);
        assert_eq!(teach.net().activations(), before.as_slice());
    }

    #[test]
    fn an_edge_edit_names_its_edge_and_e_moves_to_the_next() {
        let mut teach = fig2();
        teach.move_cursor(1);
        assert_eq!(teach.selected_edge(), Some((1, 0)));
        teach.next_edge();
        assert_eq!(teach.selected_edge(), Some((1, 2)));
        assert_eq!(teach.knob(), Knob::EdgeWeight, "e chooses the weight");
        teach.edit(true);
        let report = teach.last_edit().expect("a report");
        assert_eq!(report.edge, Some((1, 2)));
        assert_eq!(teach.net().graph().weight(2, 1), Some(0.5));
    }

    #[test]
    fn a_refused_edit_changes_nothing_and_says_why() {
        let mut teach = fig2();
        teach.activate();
        teach.choose_knob(Knob::Threshold);
        for _ in 0..10 {
            teach.edit(false);
        }
        assert_eq!(teach.net().params().threshold, 0.1);
        let notice = teach.notice().expect("refused");
        assert!(
            notice.starts_with("T_ω stays 0.1: parameter `threshold`"),
            "{notice}"
        );
    }

    /// With `p` the screen calls Fig. 2's policies π1…π4: a refused weight names its edge
    /// so, not by the net's indices from 0.
    #[test]
    fn a_refused_weight_names_its_edge_as_the_screen_does() {
        let mut teach = fig2();
        assert!(teach.toggle_numbering());
        let (i, j) = teach.selected_edge().expect("π1 has edges");
        teach.choose_knob(Knob::EdgeWeight);
        for _ in 0..20 {
            teach.edit(false);
        }
        let notice = teach.notice().expect("refused");
        let edge = format!("M({},{})", teach.names()[i], teach.names()[j]);
        assert!(notice.contains(&edge), "{edge}: {notice}");
        assert!(!notice.contains(&format!("({i}, {j})")), "{notice}");
    }

    /// The graph of issue 13: 300 policies, every pair joined with weight 0.6. One
    /// activation makes ~89,000 calls; replaying the walk at every step (as teach mode
    /// once did) froze the screen for seconds in a release build.
    fn complete(n: usize) -> SapNet {
        let edges = (0..n).flat_map(|i| (i + 1..n).map(move |j| (i, j, 0.6)));
        let graph = crate::sapnet::Graph::from_edges(n, edges).unwrap();
        SapNet::new(graph, crate::sapnet::SapNetParams::default()).unwrap()
    }

    #[test]
    fn a_long_walk_runs_in_slices_to_the_activation_in_one_go() {
        let net = complete(300);
        let names = (0..300).map(|i| format!("p{i}")).collect();
        let mut teach = Teach::new(names, net.clone());
        teach.activate();
        teach.run();
        let mut slices = 0;
        while teach.is_running() {
            assert!(teach.advance(CALLS_PER_FRAME) <= CALLS_PER_FRAME);
            slices += 1;
        }
        let calls = teach.walk().unwrap().trace.len();
        assert!(calls > 80_000, "{calls}");
        assert!((calls.div_ceil(CALLS_PER_FRAME)..=calls / CALLS_PER_FRAME + 1).contains(&slices));
        let mut whole = net;
        whole.activate(0, true);
        assert_eq!(teach.net().activations(), whole.activations());

        // A key between slices stops the run where it is.
        teach.undo();
        assert_eq!(teach.walk().unwrap().trace.len(), calls - 1);
        teach.run();
        teach.step();
        assert!(!teach.is_running());
        assert_eq!(teach.net().activations(), whole.activations());
    }

    /// Fig. 2 from π1 by hand: the first call reaches π0 at h = 1, Ω = 0.4 with
    /// η = 𝒜/k = 1/3, so ΔA = (1/3)/(1×0.4) = 0.833333; the second goes back to π1 at
    /// h = 2, Ω = 0.8 with η = (1/3)/2 = 1/6, ΔA = (1/6)/(2×0.8) = 0.104167; the third
    /// returns to π0 at Ω = 1.2 ≥ T_ω = 1 and stops.
    #[test]
    fn an_exercise_checks_each_typed_delta_and_keeps_the_score() {
        let mut teach = fig2();
        teach.move_cursor(1);
        teach.activate();
        teach.toggle_exercise();
        let answer = |teach: &mut Teach, text: &str| {
            teach.step_or_ask();
            assert_eq!(teach.prompt().map(|p| p.kind), Some(PromptKind::Predict));
            text.chars().for_each(|c| teach.prompt_type(c));
            teach.prompt_submit();
            teach.notice().unwrap().to_string()
        };
        let said = answer(&mut teach, "0.8333");
        assert!(said.starts_with("right"), "{said}");
        assert!(said.ends_with("score 1/1"), "{said}");
        assert_eq!(teach.walk().unwrap().trace.len(), 1, "the call is made");

        let said = answer(&mut teach, "0.2");
        assert!(said.starts_with("not 0.2: "), "{said}");
        assert!(
            said.contains("ΔA[π1] = η/(h×Ω) = 0.166667/(2×0.8000) = 0.104167"),
            "{said}"
        );
        assert!(said.ends_with("score 1/2"), "{said}");

        let said = answer(&mut teach, "stop");
        assert!(said.starts_with("right"), "{said}");
        assert!(said.contains("1.2000 < 1, false: the call stops"), "{said}");
        assert_eq!(teach.score(), Some(Score { right: 2, asked: 3 }));

        // A number where the call stops is wrong.
        let said = answer(&mut teach, "0");
        assert!(said.starts_with("not 0: "), "{said}");
        teach.toggle_exercise();
        assert_eq!(teach.score(), None);
        teach.step_or_ask();
        assert!(teach.prompt().is_none(), "out of exercise mode s steps");
    }

    fn two_policies(extra: &str) -> Teach {
        let text = format!("(policies: 2, edges: [(0, 1, 0.4)]{extra})");
        let source: TeachConfig = crate::ron_file::parse_ron(&text, "two").unwrap();
        let lesson = source.lesson().unwrap();
        Teach::new(lesson.names, lesson.net).with_source(source)
    }

    fn close(got: &[f64], want: &[f64]) -> bool {
        got.len() == want.len() && got.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12)
    }

    /// Two policies joined at 0.4, D = 0.5. Activating π0: A[π0] = 1, then π1 gets
    /// η/(h×Ω) = 1/(1×0.4) = 2.5, π0 back 1/(2×0.8) = 0.625, and the third call stops
    /// (Ω = 1.2): A = (1.625, 2.5). The decay halves it to (0.8125, 1.25) before π1's
    /// activation, which adds 1 to π1, 2.5 to π0 and 0.625 to π1: (3.3125, 2.875).
    #[test]
    fn one_decay_step_between_two_activations_by_hand() {
        let mut teach = two_policies(", decay: 0.5");
        assert_eq!(teach.decay(), 0.5);
        teach.activate();
        teach.run_to_end();
        assert!(close(teach.net().activations(), &[1.625, 2.5]));
        teach.move_cursor(1);
        teach.activate();
        assert!(
            close(teach.net().activations(), &[0.8125, 2.25]),
            "decayed, then eq. 8"
        );
        teach.run_to_end();
        assert!(close(teach.net().activations(), &[3.3125, 2.875]));
        let (rows, in_progress) = teach.through_time();
        assert!(!in_progress);
        assert_eq!(rows.iter().map(|r| r.activated).collect::<Vec<_>>(), [0, 1]);
        assert!(close(&rows[0].activations, &[1.625, 2.5]));
        assert!(close(&rows[1].activations, &[3.3125, 2.875]));
        // P by eq. 6 at τ = 1: e^1.625 / (e^1.625 + e^2.5) = 1 / (1 + e^0.875).
        let p0 = 1.0 / (1.0 + 0.875f64.exp());
        assert!(close(&rows[0].probabilities, &[p0, 1.0 - p0]));
        teach.reset();
        assert!(teach.through_time().0.is_empty());
    }

    #[test]
    fn the_lessons_questions_are_asked_at_the_walks_end_and_scored() {
        let mut teach = two_policies(
            ", questions: [(ask: \"Which policy has the highest P?\", answer: Policy(1)), \
             (ask: \"A of π0?\", answer: Number(value: 1.625, tolerance: 0.001))]",
        );
        teach.activate();
        teach.step();
        teach.step();
        assert!(teach.prompt().is_none(), "not before the walk's end");
        teach.step();
        assert_eq!(
            teach.prompt().map(|p| p.kind),
            Some(PromptKind::Question(0))
        );
        let asked = teach.prompt_question().unwrap();
        assert_eq!(
            asked,
            "Which policy has the highest P? (a policy's name or index):"
        );
        "π0".chars().for_each(|c| teach.prompt_type(c));
        teach.prompt_submit();
        assert_eq!(teach.notice(), Some("not π0: it is π1 · questions 0/1"));
        assert_eq!(
            teach.prompt().map(|p| p.kind),
            Some(PromptKind::Question(1))
        );
        "1.625".chars().for_each(|c| teach.prompt_type(c));
        teach.prompt_submit();
        assert_eq!(teach.notice(), Some("right: 1.625 ± 0.001 · questions 1/2"));
        assert!(teach.prompt().is_none());
        assert_eq!(teach.quiz(), Some(Score { right: 1, asked: 2 }));
        // Asked once: the next walk's end asks nothing more.
        teach.activate();
        teach.run_to_end();
        teach.step();
        assert!(teach.prompt().is_none());
    }

    #[test]
    fn r_walks_a_call_at_a_time_at_its_speed() {
        let mut teach = fig2();
        teach.activate();
        teach.animate();
        assert!(teach.is_animating() && !teach.is_running());
        let start = Instant::now();
        assert_eq!(
            teach.advance_at(CALLS_PER_FRAME, start),
            1,
            "one call at once"
        );
        assert_eq!(
            teach.advance_at(CALLS_PER_FRAME, start),
            0,
            "the next not yet due"
        );
        // Two calls a second: the next is due half a second on.
        let later = start + Duration::from_millis(500);
        assert_eq!(teach.advance_at(CALLS_PER_FRAME, later), 1);
        assert_eq!(teach.walk().unwrap().trace.len(), 2);
        teach.change_speed(true);
        assert_eq!(teach.speed(), 4.0);
        teach.animate();
        assert!(!teach.is_animating(), "r again pauses");
        teach.run();
        teach.advance(CALLS_PER_FRAME);
        assert!(teach.walk().unwrap().done, "R runs to the end");
    }

    /// `w` keeps the walk's position, and a lesson reopened there shows the same calls.
    #[test]
    fn a_saved_walk_reopens_at_its_call() {
        let mut teach = fig2();
        teach.move_cursor(1);
        teach.activate();
        for _ in 0..5 {
            teach.step();
        }
        let saved = teach.lesson_file();
        assert_eq!(
            saved.walk,
            Some(WalkPosition {
                activate: 1,
                calls: 5
            })
        );
        let lesson = saved.lesson().unwrap();
        let mut reopened = Teach::new(lesson.names, lesson.net).with_source(saved);
        reopened.resume_walk(lesson.walk.unwrap());
        assert_eq!(reopened.walk(), teach.walk());
        assert_eq!(reopened.net().activations(), teach.net().activations());
    }
}
