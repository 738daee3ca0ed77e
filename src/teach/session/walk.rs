//! One activation's spreading recursion, stepped a `spread` call at a time (Algorithms 1
//! and 2), with undo; and A and P after each walk, through time.
//!
//! The walk keeps the recursion's state ([`SpreadState`]: the pending calls and the path)
//! and its own activations, so a step costs O(1) whatever the walk's length. Undo rebuilds
//! the walk from its start, one call fewer.

use serde::Serialize;

use super::Teach;
use crate::sapnet::{Call, Graph, SapNet, SpreadState, Spreader, TraceStep};
use crate::teach::lesson::WalkPosition;

/// One activation being stepped.
#[derive(Debug, Clone)]
pub(super) struct Walk {
    policy: usize,
    /// The activations just before `A[policy] += 𝒜`.
    before: Vec<f64>,
    /// The calls made so far, in order.
    trace: Vec<TraceStep>,
    /// The recursion after those calls.
    state: SpreadState,
    /// The activations after those calls (the net's, once settled).
    activations: Vec<f64>,
    /// `activations − before`, kept with them: eq. 11's sum of ΔA, eq. 8's 𝒜 included.
    deposited: Vec<f64>,
}

impl Walk {
    /// A walk activating `policy` of `net` from the activations `before` (eq. 8, the first
    /// calls queued).
    pub(super) fn start(net: &SapNet, policy: usize, before: Vec<f64>) -> Self {
        let mut activations = before.clone();
        let state = Spreader::activate(
            net.graph(),
            net.spreading(),
            policy,
            net.params().coefficient,
            &mut activations,
        )
        .suspend();
        Self {
            policy,
            before,
            trace: Vec::new(),
            state,
            activations,
            deposited: Vec::new(),
        }
    }

    /// The next call, on the walk's own activations; O(1).
    pub(super) fn call(&mut self, graph: &Graph) -> Option<TraceStep> {
        let state = std::mem::take(&mut self.state);
        let mut spreader = Spreader::resume(graph, state);
        let call = spreader.step(&mut self.activations);
        self.state = spreader.suspend();
        self.trace.extend(call);
        call
    }

    /// The walk one call shorter, made again from its start on `net`; or, before any
    /// call, the activations it started from.
    pub(super) fn without_last_call(self, net: &SapNet) -> Result<Self, Vec<f64>> {
        let mut trace = self.trace;
        if trace.pop().is_none() {
            return Err(self.before);
        }
        let mut rebuilt = Self::start(net, self.policy, self.before);
        for _ in 0..trace.len() {
            let mut spreader = Spreader::resume(net.graph(), rebuilt.state);
            spreader.step(&mut rebuilt.activations);
            rebuilt.state = spreader.suspend();
        }
        rebuilt.trace = trace;
        Ok(rebuilt)
    }

    /// Brings what it has deposited up to date, and gives the activations to show.
    pub(super) fn settle(&mut self) -> &[f64] {
        self.deposited = self
            .activations
            .iter()
            .zip(&self.before)
            .map(|(a, b)| a - b)
            .collect();
        &self.activations
    }

    pub(super) fn policy(&self) -> usize {
        self.policy
    }

    pub(super) fn before(&self) -> &[f64] {
        &self.before
    }

    pub(super) fn calls_made(&self) -> usize {
        self.trace.len()
    }

    /// The call the next step makes, if the walk is not done.
    pub(super) fn next_call(&self) -> Option<Call> {
        self.state.pending().last().copied()
    }

    pub(super) fn is_done(&self) -> bool {
        self.state.is_done()
    }

    fn view(&self) -> WalkView<'_> {
        WalkView {
            policy: self.policy,
            trace: &self.trace,
            pending: self.state.pending(),
            path: self.state.path(),
            done: self.state.is_done(),
            deposited: &self.deposited,
        }
    }
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

/// A and P of every policy at the end of one activation's walk (`through_time` in
/// `--json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TimeRow {
    /// The policy activated.
    pub activated: usize,
    pub activations: Vec<f64>,
    pub probabilities: Vec<f64>,
}

impl TimeRow {
    /// The row of `activated`'s walk ending with `net` as it stands.
    pub(super) fn of(activated: usize, net: &SapNet) -> Self {
        Self {
            activated,
            activations: net.activations().to_vec(),
            probabilities: net.probabilities(),
        }
    }
}

/// The walks finished since the lesson (or `c`) started, and the decay between two.
#[derive(Debug, Clone, Default)]
pub(super) struct Timeline {
    /// D: the share of every activation lost between two activations (0: the paper).
    pub(super) decay: f64,
    /// A and P at the end of each walk finished.
    pub(super) rows: Vec<TimeRow>,
}

impl Teach {
    /// The walk in progress, if any.
    pub fn walk(&self) -> Option<WalkView<'_>> {
        self.walk.as_ref().map(Walk::view)
    }

    /// `a`: activates the policy under the cursor as after a positive transition (eq. 8),
    /// queueing the first `spread` calls. A walk still in progress is finished first, so
    /// its deposits are not lost, and the screen says so.
    pub fn activate(&mut self) {
        self.notice = None;
        let pending = self
            .walk
            .as_ref()
            .filter(|w| !w.is_done())
            .map(Walk::policy);
        let made_before = self.walk.as_ref().map_or(0, Walk::calls_made);
        self.run_to_end();
        if let Some(policy) = pending {
            let made = self.walk.as_ref().map_or(0, Walk::calls_made) - made_before;
            self.notice = Some(format!(
                "{}'s walk was not done: its {made} remaining calls were made first",
                self.names()[policy]
            ));
        }
        if let Some(walk) = &self.walk {
            // The walk before this one ends here: a row of the table through time, then
            // the decay between the two activations.
            let row = TimeRow::of(walk.policy(), &self.net);
            self.timeline.rows.push(row);
            if self.timeline.decay > 0.0 {
                let kept = 1.0 - self.timeline.decay;
                let decayed = self.net.activations().iter().map(|a| a * kept).collect();
                self.set_activations(decayed);
            }
        }
        let before = self.net.activations().to_vec();
        self.restart_walk(self.cursor, before);
    }

    /// `s`: makes the next `spread` call. Returns it, or `None` when there is nothing to
    /// step.
    pub fn step(&mut self) -> Option<TraceStep> {
        self.playback.stop();
        self.notice = None;
        let call = self.call();
        self.sync();
        self.ask_at_walk_end();
        call
    }

    /// Makes every remaining call of the walk in progress.
    pub fn run_to_end(&mut self) {
        self.playback.stop();
        while self.call().is_some() {}
        self.sync();
    }

    /// `u`: takes back the last call (or, before any, the activation itself).
    pub fn undo(&mut self) {
        self.playback.stop();
        self.notice = None;
        let Some(walk) = self.walk.take() else {
            return;
        };
        match walk.without_last_call(&self.net) {
            Ok(shorter) => {
                self.walk = Some(shorter);
                self.sync();
            }
            Err(before) => self.set_activations(before),
        }
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

    /// D between activations (`--decay`; 0 is the paper).
    pub fn decay(&self) -> f64 {
        self.timeline.decay
    }

    /// A and P after each walk so far, and the walk on screen's as it stands last (`true`
    /// while it is still in progress).
    pub fn through_time(&self) -> (Vec<TimeRow>, bool) {
        let mut rows = self.timeline.rows.clone();
        let mut in_progress = false;
        if let Some(walk) = &self.walk {
            rows.push(TimeRow::of(walk.policy(), &self.net));
            in_progress = !walk.is_done();
        }
        (rows, in_progress)
    }

    /// A new walk on screen: `policy` activated from `before` (eq. 8).
    pub(super) fn restart_walk(&mut self, policy: usize, before: Vec<f64>) {
        self.walk = Some(Walk::start(&self.net, policy, before));
        self.sync();
    }

    /// The next call of the walk in progress, if any.
    pub(super) fn call(&mut self) -> Option<TraceStep> {
        self.walk.as_mut()?.call(self.net.graph())
    }

    /// Shows the walk's activations on the net.
    pub(super) fn sync(&mut self) {
        if let Some(walk) = &mut self.walk {
            let activations = walk.settle().to_vec();
            self.set_activations(activations);
        }
    }

    pub(super) fn set_activations(&mut self, activations: Vec<f64>) {
        // The net's bounds keep every activation finite (see `SapNet::with_activations`)
        // and the count is the graph's: `set_activations` cannot refuse these.
        self.net
            .set_activations(activations)
            .expect("activations from the same graph");
    }
}
