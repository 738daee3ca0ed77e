//! Activation and spreading (paper II-F and II-G, eq. 8–11, Algorithms 1 and 2), as
//! `DESIGN.md` writes them with the paper's typos corrected:
//!
//! ```text
//! activate(i, 𝒜):
//!     A[i] += 𝒜                                      # eq. 8
//!     k = degree(i)
//!     for each neighbour j of i:
//!         spread(j, h = 1, Ω = M[i][j], η = 𝒜 / k, came_from = i)     # eq. 9
//!
//! spread(j, h, Ω, η, came_from):
//!     if Ω >= T_ω: return                            # eq. 10, first case
//!     A[j] += η / (h · Ω)                            # eq. 10, second case; eq. 11 sums them
//!     k = degree(j)
//!     for each neighbour l of j:
//!         spread(l, h + 1, Ω + M[j][l], η / k, j)
//! ```
//!
//! [`activate_recursive`] is that recursion word for word. [`Spreader`] makes the same
//! calls in the same order from an explicit stack, one call per [`Spreader::step`], so a
//! front end can walk through it; [`activate`] runs a `Spreader` to the end and is what
//! training uses. Both report every call as a [`TraceStep`] to a [`TraceSink`].

use serde::Serialize;

use super::graph::Graph;
use super::params::Paths;

/// How far activation may spread (eq. 10 and the walks of Algorithm 2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spreading {
    /// T_ω: a walk whose summed weight Ω reaches it deposits nothing and ends.
    pub threshold: f64,
    pub paths: Paths,
}

/// One call `spread(to, h, Ω, η, came_from = from)` and what it did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TraceStep {
    pub from: usize,
    pub to: usize,
    /// Edges walked from the activated policy.
    pub h: usize,
    /// Ω, the summed weight of those edges.
    pub omega: f64,
    /// η, the activation output that arrived.
    pub eta: f64,
    /// ΔA_to = η / (h·Ω), or 0 when stopped.
    pub delta: f64,
    /// Ω ≥ T_ω: the first case of eq. 10.
    pub stopped: bool,
}

/// Where trace steps go. [`NoTrace`] discards them at compile time.
pub trait TraceSink {
    /// Whether this sink wants to hear about calls the threshold stops. If not, such calls
    /// are never made: they change nothing, and on a dense graph they are nearly all the
    /// calls (a complete graph of 1000 at Table II weights makes 999 deposits and 998,001
    /// stopped calls).
    const WANTS_STOPPED: bool = true;

    fn record(&mut self, step: TraceStep);
}

/// Nobody is listening.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoTrace;

impl TraceSink for NoTrace {
    const WANTS_STOPPED: bool = false;

    #[inline(always)]
    fn record(&mut self, _: TraceStep) {}
}

/// Counts the calls, stopped ones too (as a teach-mode trace lists them).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CallCount(pub usize);

impl TraceSink for CallCount {
    #[inline(always)]
    fn record(&mut self, _: TraceStep) {
        self.0 += 1;
    }
}

impl TraceSink for Vec<TraceStep> {
    fn record(&mut self, step: TraceStep) {
        self.push(step);
    }
}

impl<S: TraceSink + ?Sized> TraceSink for &mut S {
    const WANTS_STOPPED: bool = S::WANTS_STOPPED;

    #[inline(always)]
    fn record(&mut self, step: TraceStep) {
        (**self).record(step);
    }
}

/// A call of `spread` waiting its turn: `spread(to, h, omega, eta, came_from = from)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Call {
    pub from: usize,
    pub to: usize,
    pub h: usize,
    pub omega: f64,
    pub eta: f64,
}

/// Activates policy `i` with coefficient 𝒜 = `coefficient` and spreads it to completion.
///
/// Training calls this with 𝒜 on a positive transition and 0 on a negative one (Algorithm
/// 3), when every deposit is 0.
///
/// # Panics
/// If `i` is not a policy of `graph` or `activations` does not have one entry per policy.
pub fn activate<S: TraceSink>(
    graph: &Graph,
    spreading: Spreading,
    i: usize,
    coefficient: f64,
    activations: &mut [f64],
    sink: &mut S,
) {
    if !S::WANTS_STOPPED && deposits_stop_at_neighbours(graph, spreading, i) {
        activate_neighbours(graph, spreading, i, coefficient, activations, sink);
        return;
    }
    let mut spreader = Spreader::start(
        graph,
        spreading,
        i,
        coefficient,
        activations,
        !S::WANTS_STOPPED,
    );
    while let Some(step) = spreader.step(activations) {
        sink.record(step);
    }
}

/// Whether every walk of two edges from `i` reaches T_ω, so that the only deposits are
/// eq. 10's on `i`'s neighbours (Table II's graphs: same-category weight 0.95, T_ω = 1).
fn deposits_stop_at_neighbours(graph: &Graph, spreading: Spreading, i: usize) -> bool {
    graph.neighbours(i).all(|(j, w)| {
        // Ω as the walk sums it; a walk that stops at j, or leaves it only over edges that
        // reach T_ω, deposits nothing past j.
        let omega = 0.0 + w;
        omega >= spreading.threshold || omega + graph.lightest(j) >= spreading.threshold
    })
}

/// Eq. 8: the activated policy gains 𝒜, before any spreading; every entry point begins so.
///
/// # Panics
/// If `activations` does not hold one value per policy of `graph`.
fn activate_own(graph: &Graph, i: usize, coefficient: f64, activations: &mut [f64]) {
    assert_eq!(activations.len(), graph.len(), "one activation per policy");
    activations[i] += coefficient;
}

/// `activate` when [`deposits_stop_at_neighbours`]: eq. 8, then eq. 10's deposit on each
/// neighbour the threshold lets through, in the walk's order and with its arithmetic
/// (`h = 1`, so `η / (h·Ω)` is `η / Ω` exactly), without the walk's stack: training
/// activates after every positive step, and the stack's allocations and bookkeeping cost
/// more than the deposits.
fn activate_neighbours<S: TraceSink>(
    graph: &Graph,
    spreading: Spreading,
    i: usize,
    coefficient: f64,
    activations: &mut [f64],
    sink: &mut S,
) {
    activate_own(graph, i, coefficient, activations);
    let eta = coefficient / graph.degree(i) as f64;
    for (j, w) in graph.neighbours(i) {
        let omega = 0.0 + w;
        let walked_back = spreading.paths == Paths::Simple && j == i;
        if omega >= spreading.threshold || walked_back {
            continue;
        }
        let delta = eta / omega;
        activations[j] += delta;
        sink.record(TraceStep {
            from: i,
            to: j,
            h: 1,
            omega,
            eta,
            delta,
            stopped: false,
        });
    }
}

/// Algorithms 1 and 2 as plain recursion, the reference [`Spreader`] is tested against.
/// Reports every call, stopped ones included.
///
/// # Panics
/// As [`activate`].
pub fn activate_recursive<S: TraceSink>(
    graph: &Graph,
    spreading: Spreading,
    i: usize,
    coefficient: f64,
    activations: &mut [f64],
    sink: &mut S,
) {
    activate_own(graph, i, coefficient, activations);
    let k = graph.degree(i) as f64;
    let mut path = vec![i];
    for (j, w) in graph.neighbours(i) {
        if spreading.paths == Paths::Literal || !path.contains(&j) {
            let call = Call {
                from: i,
                to: j,
                h: 1,
                omega: w,
                eta: coefficient / k,
            };
            spread_recursive(graph, spreading, call, activations, &mut path, sink);
        }
    }
}

fn spread_recursive<S: TraceSink>(
    graph: &Graph,
    spreading: Spreading,
    Call {
        from,
        to: j,
        h,
        omega,
        eta,
    }: Call,
    activations: &mut [f64],
    path: &mut Vec<usize>,
    sink: &mut S,
) {
    let mut step = TraceStep {
        from,
        to: j,
        h,
        omega,
        eta,
        delta: 0.0,
        stopped: omega >= spreading.threshold,
    };
    if step.stopped {
        sink.record(step);
        return;
    }
    step.delta = eta / (h as f64 * omega);
    activations[j] += step.delta;
    sink.record(step);
    let k = graph.degree(j) as f64;
    path.push(j);
    for (l, w) in graph.neighbours(j) {
        if spreading.paths == Paths::Literal || !path.contains(&l) {
            let call = Call {
                from: j,
                to: l,
                h: h + 1,
                omega: omega + w,
                eta: eta / k,
            };
            spread_recursive(graph, spreading, call, activations, path, sink);
        }
    }
    path.pop();
}

/// The spreading recursion of one activation, one `spread` call at a time.
///
/// The pending calls live on an explicit stack whose top is the next call the recursion
/// would make, so [`step`](Self::step) makes exactly the calls of [`activate_recursive`],
/// in the same order, with bit-identical numbers. It is `Clone` and small, so a front end
/// undoes a step by keeping the clone from before it (with the activations of then).
#[derive(Debug, Clone)]
pub struct Spreader<'g> {
    graph: &'g Graph,
    spreading: Spreading,
    /// Leave out calls the threshold is sure to stop (see [`TraceSink::WANTS_STOPPED`]).
    skip_stopped: bool,
    /// Pending calls; the last is the next.
    pending: Vec<Call>,
    /// The walk that led to the last call, the activated policy first. Depth-first order
    /// means a call at depth h finds its ancestors in `path[..h]`.
    path: Vec<usize>,
}

/// A suspended [`Spreader`]: the pending calls and the path, without the graph.
#[derive(Debug, Clone, PartialEq)]
pub struct SpreadState {
    spreading: Spreading,
    skip_stopped: bool,
    pending: Vec<Call>,
    path: Vec<usize>,
}

/// A finished walk: nothing pending (a placeholder while the real state is resumed).
impl Default for SpreadState {
    fn default() -> Self {
        SpreadState {
            spreading: Spreading {
                threshold: 0.0,
                paths: Paths::Literal,
            },
            skip_stopped: false,
            pending: Vec::new(),
            path: Vec::new(),
        }
    }
}

impl SpreadState {
    /// The pending calls, the next one last.
    pub fn pending(&self) -> &[Call] {
        &self.pending
    }

    pub fn is_done(&self) -> bool {
        self.pending.is_empty()
    }

    /// See [`Spreader::path`].
    pub fn path(&self) -> &[usize] {
        &self.path
    }
}

impl<'g> Spreader<'g> {
    /// Algorithm 1 up to its loop: `A[i] += 𝒜` (eq. 8), then one pending call
    /// `spread(j, 1, M_ij, 𝒜/k, i)` per neighbour j (eq. 9). Every later call, stopped ones
    /// included, is one [`step`](Self::step).
    ///
    /// # Panics
    /// If `i` is not a policy of `graph` or `activations` does not have one entry per policy.
    pub fn activate(
        graph: &'g Graph,
        spreading: Spreading,
        i: usize,
        coefficient: f64,
        activations: &mut [f64],
    ) -> Self {
        Self::start(graph, spreading, i, coefficient, activations, false)
    }

    fn start(
        graph: &'g Graph,
        spreading: Spreading,
        i: usize,
        coefficient: f64,
        activations: &mut [f64],
        skip_stopped: bool,
    ) -> Self {
        activate_own(graph, i, coefficient, activations);
        let mut spreader = Spreader {
            graph,
            spreading,
            skip_stopped,
            pending: Vec::with_capacity(graph.degree(i)),
            path: vec![i],
        };
        if graph.degree(i) > 0 {
            spreader.queue_neighbours(i, 1, 0.0, coefficient / graph.degree(i) as f64);
        }
        spreader
    }

    /// Makes the next `spread` call, updating `activations`; `None` once the recursion has
    /// returned to `activate`.
    ///
    /// Pass the activations the spreader was started with, as they were left by the
    /// previous step.
    ///
    /// # Panics
    /// If `activations` has fewer entries than the graph has policies.
    pub fn step(&mut self, activations: &mut [f64]) -> Option<TraceStep> {
        let Call {
            from,
            to,
            h,
            omega,
            eta,
        } = self.pending.pop()?;
        self.path.truncate(h);
        let mut step = TraceStep {
            from,
            to,
            h,
            omega,
            eta,
            delta: 0.0,
            stopped: omega >= self.spreading.threshold,
        };
        if !step.stopped {
            step.delta = eta / (h as f64 * omega);
            activations[to] += step.delta;
            self.path.push(to);
            // `to` was reached over an edge, so its degree is at least 1.
            self.queue_neighbours(to, h + 1, omega, eta / self.graph.degree(to) as f64);
        }
        Some(step)
    }

    /// Lets go of the graph, keeping where the walk stands: a front end that makes one
    /// call per key keeps the state and [`resume`](Self::resume)s it, in O(1).
    pub fn suspend(self) -> SpreadState {
        SpreadState {
            spreading: self.spreading,
            skip_stopped: self.skip_stopped,
            pending: self.pending,
            path: self.path,
        }
    }

    /// The walk `state` describes, over the graph it was started on.
    pub fn resume(graph: &'g Graph, state: SpreadState) -> Self {
        Spreader {
            graph,
            spreading: state.spreading,
            skip_stopped: state.skip_stopped,
            pending: state.pending,
            path: state.path,
        }
    }

    /// The pending calls, the next one last.
    pub fn pending(&self) -> &[Call] {
        &self.pending
    }

    /// The call the next [`step`](Self::step) makes.
    pub fn next_call(&self) -> Option<&Call> {
        self.pending.last()
    }

    pub fn is_done(&self) -> bool {
        self.pending.is_empty()
    }

    /// The walk from the activated policy to the last call's target (included when that
    /// call deposited), e.g. to highlight it.
    pub fn path(&self) -> &[usize] {
        &self.path
    }

    /// Queues `spread(l, h, Ω + M_jl, η, j)` for each neighbour l of j, the first
    /// neighbour on top so that calls are made in index order, as the loop makes them.
    fn queue_neighbours(&mut self, j: usize, h: usize, omega: f64, eta: f64) {
        let threshold = self.spreading.threshold;
        if self.skip_stopped && omega + self.graph.lightest(j) >= threshold {
            return;
        }
        let simple = self.spreading.paths == Paths::Simple;
        for (l, w) in self.graph.neighbours(j).rev() {
            // Ω + M_jl, summed exactly as the recursion sums it.
            let omega = omega + w;
            if self.skip_stopped && omega >= threshold {
                continue;
            }
            if simple && self.path.contains(&l) {
                continue;
            }
            self.pending.push(Call {
                from: j,
                to: l,
                h,
                omega,
                eta,
            });
        }
    }
}
