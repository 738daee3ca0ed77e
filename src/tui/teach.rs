//! Teach mode's state: one activation's spreading recursion, stepped a `spread` call at a
//! time (Algorithms 1 and 2), with undo.
//!
//! A [`Spreader`] borrows the graph, so the state keeps what is needed to rebuild it
//! instead: the activations before the activation started and how many calls were made.
//! Stepping, undoing and redrawing replay the calls from there; a teaching graph makes a
//! few dozen, so a replay costs microseconds.

use crate::sapnet::{Call, SapNet, Spreader, TraceStep};

/// Where teach mode stands: which policy is picked, and the activation in progress.
#[derive(Debug, Clone)]
pub struct Teach {
    names: Vec<String>,
    net: SapNet,
    /// The activations before the first activation of this lesson (`c` goes back to them).
    initial: Vec<f64>,
    /// The policy the arrows point at.
    cursor: usize,
    walk: Option<Walk>,
    /// Category of each policy, to draw related policies together.
    groups: Option<Vec<usize>>,
}

/// One activation being stepped.
#[derive(Debug, Clone)]
struct Walk {
    policy: usize,
    /// The activations just before `A[policy] += 𝒜`.
    before: Vec<f64>,
    /// The calls made so far, in order.
    trace: Vec<TraceStep>,
}

/// What a front end draws of the walk in progress.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkView {
    pub policy: usize,
    /// The calls made so far.
    pub trace: Vec<TraceStep>,
    /// The pending calls, the next one last (the recursion's stack).
    pub pending: Vec<Call>,
    /// The walk from the activated policy to the last call's target.
    pub path: Vec<usize>,
    pub done: bool,
}

impl Teach {
    pub fn new(names: Vec<String>, net: SapNet) -> Self {
        let initial = net.activations().to_vec();
        Self {
            names,
            net,
            initial,
            cursor: 0,
            walk: None,
            groups: None,
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

    pub fn names(&self) -> &[String] {
        &self.names
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
        }
    }

    /// `a`: activates the policy under the cursor as after a positive transition (eq. 8),
    /// queueing the first `spread` calls. A walk still in progress is finished first, so
    /// its deposits are not lost.
    pub fn activate(&mut self) {
        self.run_to_end();
        self.walk = Some(Walk {
            policy: self.cursor,
            before: self.net.activations().to_vec(),
            trace: Vec::new(),
        });
        self.replay();
    }

    /// `s`: makes the next `spread` call. Returns it, or `None` when there is nothing to
    /// step.
    pub fn step(&mut self) -> Option<TraceStep> {
        let (mut spreader, mut activations) = self.replayed(self.walk.as_ref()?);
        let call = spreader.step(&mut activations)?;
        self.walk.as_mut()?.trace.push(call);
        self.set_activations(activations);
        Some(call)
    }

    /// `r`: makes every remaining call of the walk in progress.
    pub fn run_to_end(&mut self) {
        while self.step().is_some() {}
    }

    /// `u`: takes back the last call (or, before any, the activation itself).
    pub fn undo(&mut self) {
        let Some(walk) = self.walk.as_mut() else {
            return;
        };
        if walk.trace.pop().is_none() {
            let before = walk.before.clone();
            self.walk = None;
            self.set_activations(before);
            return;
        }
        self.replay();
    }

    /// `c`: back to the activations the lesson started with.
    pub fn reset(&mut self) {
        self.walk = None;
        self.set_activations(self.initial.clone());
    }

    /// The walk in progress, if any.
    pub fn walk(&self) -> Option<WalkView> {
        let walk = self.walk.as_ref()?;
        let (spreader, _) = self.replayed(walk);
        Some(WalkView {
            policy: walk.policy,
            trace: walk.trace.clone(),
            pending: spreader.pending().to_vec(),
            path: spreader.path().to_vec(),
            done: spreader.is_done(),
        })
    }

    /// The walk's spreader and activations after its calls so far, rebuilt from its start.
    fn replayed(&self, walk: &Walk) -> (Spreader<'_>, Vec<f64>) {
        let mut activations = walk.before.clone();
        let mut spreader = Spreader::activate(
            self.net.graph(),
            self.net.spreading(),
            walk.policy,
            self.net.params().coefficient,
            &mut activations,
        );
        for _ in 0..walk.trace.len() {
            spreader.step(&mut activations);
        }
        (spreader, activations)
    }

    /// Sets the activations to what the walk's calls so far leave.
    fn replay(&mut self) {
        if let Some(walk) = &self.walk {
            let (_, activations) = self.replayed(walk);
            self.set_activations(activations);
        }
    }

    fn set_activations(&mut self, activations: Vec<f64>) {
        // Spreading only adds finite deposits to finite activations, and the count is the
        // graph's: `set_activations` cannot refuse these.
        self.net
            .set_activations(activations)
            .expect("activations from the same graph");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teach::config::TeachConfig;

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
}
