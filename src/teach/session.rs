//! Teach mode's state: a lesson being taught, the policy picked, the activation in
//! progress. Each of its jobs has a room of its own under `session/`, and `Teach` owns
//! their state:
//!
//! - `walk`: one activation stepped a `spread` call at a time, with undo, and A and P
//!   through time;
//! - `playback`: `r` and `R`, calls made between frames;
//! - `names`: what the screen calls the policies (`p`);
//! - `graph_edits`: knobs turned, edges and policies edited by key and by mouse (`M`);
//! - `prompt`: the line typed, and what Enter does with it;
//! - `quiz`: the exercise's predictions and the lesson's questions;
//! - `lesson_file`: the lesson written back (`w`).
//!
//! This file holds what they share: the net, the cursor, the notice, the panel shown. The
//! rooms are its children, so that they read its fields and it reads theirs without the
//! files importing each other in a circle.

mod graph_edits;
mod lesson_file;
mod names;
mod playback;
mod prompt;
mod quiz;
mod walk;

use super::lesson::TeachConfig;
use crate::sapnet::SapNet;
use graph_edits::Editing;
use names::Names;
use playback::Playback;
use quiz::Questions;
use walk::{Timeline, Walk};

pub use graph_edits::MOUSE_EDGE_WEIGHT;
pub use playback::{CALLS_PER_FRAME, SPEEDS};
pub use prompt::{Prompt, PromptKind, LESSON_FILE};
pub use quiz::{Score, ANSWER_TOLERANCE};
pub use walk::{TimeRow, WalkView};

/// Where teach mode stands: which policy is picked, and the activation in progress.
#[derive(Debug, Clone)]
pub struct Teach {
    /// The lesson's net, with the activations as they stand after the calls made so far.
    net: SapNet,
    names: Names,
    /// The activations before the first activation of this lesson (`c` goes back to them).
    initial: Vec<f64>,
    /// The policy the arrows point at.
    cursor: usize,
    walk: Option<Walk>,
    playback: Playback,
    /// The walks finished so far, and the decay between two.
    timeline: Timeline,
    /// Category of each policy, to draw related policies together.
    groups: Option<Vec<usize>>,
    /// Per policy, whether the live run had its category out of the candidates when teach
    /// mode opened on its net (empty: none, or a lesson).
    excluded: Vec<bool>,
    /// The knob and edge the next edit acts on, the last edit, the mouse's `M` mode.
    editing: Editing,
    /// Something the last key did that the screen must say: an edit refused, pending
    /// calls made before a new activation.
    notice: Option<String>,
    /// A line being typed (an edge to add, the file to save to), if any.
    prompt: Option<Prompt>,
    /// Exercise mode (`X`): before each call the student types its ΔA; the score so far.
    exercise: Option<Score>,
    /// The lesson's questions, asked one after another when a walk ends.
    questions: Questions,
    /// The lesson file this session was opened from, for what the net does not hold: the
    /// policies' descriptions where categories build M, and what `w` writes back.
    source: TeachConfig,
    /// What the panel under the edits shows (`v` cycles).
    panel: WalkPanel,
}

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

impl Teach {
    pub fn new(names: Vec<String>, net: SapNet) -> Self {
        Self {
            names: Names::new(names),
            initial: net.activations().to_vec(),
            net,
            cursor: 0,
            walk: None,
            playback: Playback::default(),
            timeline: Timeline::default(),
            groups: None,
            excluded: Vec::new(),
            editing: Editing::default(),
            notice: None,
            prompt: None,
            exercise: None,
            questions: Questions::default(),
            source: TeachConfig::default(),
            panel: WalkPanel::default(),
        }
    }

    /// The lesson file the session was opened from: its policies' descriptions, where
    /// categories build M, are kept for the category edits and for `w`.
    pub fn with_source(mut self, source: TeachConfig) -> Self {
        self.timeline.decay = source.decay;
        self.questions = Questions::new(source.questions.clone());
        self.source = source;
        self
    }

    /// D between activations (`--decay`; 0 is the paper).
    pub fn with_decay(mut self, decay: f64) -> Self {
        self.timeline.decay = decay;
        self
    }

    /// Draws policies of the same category together (the graph's categories).
    pub fn with_groups(mut self, groups: Vec<usize>) -> Self {
        self.groups = (groups.len() == self.net.len()).then_some(groups);
        self
    }

    /// The live run's excluded policies, shown on the graph (spreading by hand ignores them:
    /// exclusion acts on eq. 6's draw, not on eq. 8–11).
    pub fn with_excluded(mut self, excluded: Vec<bool>) -> Self {
        self.excluded = excluded;
        self
    }

    /// The net with the activations as they stand after the calls made so far.
    pub fn net(&self) -> &SapNet {
        &self.net
    }

    pub fn groups(&self) -> Option<&[usize]> {
        self.groups.as_deref()
    }

    pub fn excluded(&self) -> &[bool] {
        &self.excluded
    }

    /// The policies' names as shown: π0… as the lesson gives them, or π1… (`p`).
    pub fn names(&self) -> &[String] {
        self.names.shown()
    }

    /// What the lesson called each policy, where the screen calls them π0… instead (the
    /// lesson's names would label two nodes alike).
    pub fn descriptions(&self) -> Option<&[String]> {
        self.names.descriptions()
    }

    /// `p`: the paper's numbering π1…πN, or back to π0…; `false` when the lesson names
    /// its policies itself.
    pub fn toggle_numbering(&mut self) -> bool {
        self.names.toggle_numbering()
    }

    /// Which numbering is on screen, for the status bar: `π0…` or `π1…` (none for names
    /// the lesson gives).
    pub fn numbering(&self) -> Option<&'static str> {
        self.names.numbering()
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

    pub fn cursor(&self) -> usize {
        self.cursor
    }

    /// Moves the cursor by `delta` policies, wrapping around.
    pub fn move_cursor(&mut self, delta: isize) {
        let n = self.net.len() as isize;
        if n > 0 {
            self.cursor = (self.cursor as isize + delta).rem_euclid(n) as usize;
            self.editing.edge = 0;
        }
    }

    /// What the last key did that needs saying, if anything.
    pub fn notice(&self) -> Option<&str> {
        self.notice.as_deref()
    }

    /// What the panel under the edits shows.
    pub fn panel(&self) -> WalkPanel {
        self.panel
    }

    /// `v`: the trace, the tree, the chart, A and P through time, in turn.
    pub fn next_panel(&mut self) {
        self.panel = self.panel.following();
    }

    /// `c`: back to the activations the lesson started with.
    pub fn reset(&mut self) {
        self.playback.stop();
        self.notice = None;
        self.walk = None;
        self.timeline.rows.clear();
        self.set_activations(self.initial.clone());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teach::knobs::Knob;
    use crate::teach::lesson::{TeachConfig, WalkPosition};
    use std::time::{Duration, Instant};

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
