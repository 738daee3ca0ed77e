//! Properties of activation, spreading and selection on random positive graphs.

use proptest::prelude::*;

use sapnet::sapnet::selection::probabilities;
use sapnet::sapnet::spreading::{self, activate_recursive};
use sapnet::sapnet::{Graph, Paths, Spreader, Spreading, TraceSink, TraceStep};

/// A sink that, like `NoTrace`, lets the spreader leave out the calls the threshold stops,
/// but keeps the deposits it makes.
#[derive(Default)]
struct Deposits(Vec<TraceStep>);

impl TraceSink for Deposits {
    const WANTS_STOPPED: bool = false;

    fn record(&mut self, step: TraceStep) {
        self.0.push(step);
    }
}

#[derive(Debug, Clone)]
struct Case {
    n: usize,
    edges: Vec<(usize, usize, f64)>,
    threshold: f64,
    coefficient: f64,
    paths: Paths,
    root: usize,
    initial: Vec<f64>,
}

impl Case {
    fn graph(&self) -> Graph {
        Graph::from_edges(self.n, self.edges.iter().copied()).unwrap()
    }

    fn spreading(&self) -> Spreading {
        Spreading {
            threshold: self.threshold,
            paths: self.paths,
        }
    }

    /// Runs the fast path with a full trace.
    fn trace(&self, paths: Paths, coefficient: f64) -> (Vec<f64>, Vec<TraceStep>) {
        let spreading = Spreading {
            paths,
            ..self.spreading()
        };
        let mut a = self.initial.clone();
        let mut trace = Vec::new();
        spreading::activate(
            &self.graph(),
            spreading,
            self.root,
            coefficient,
            &mut a,
            &mut trace,
        );
        (a, trace)
    }
}

/// Up to 7 policies, weights ≥ 0.3 and T_ω ≤ 1.2: walks are at most 4 edges deep, so a
/// literal walk makes at most 6 + 6² + 6³ + 6⁴ calls.
fn case() -> impl Strategy<Value = Case> {
    (1usize..=7).prop_flat_map(|n| {
        let pairs: Vec<(usize, usize)> = (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .collect();
        let m = pairs.len();
        (
            proptest::collection::vec(proptest::option::weighted(0.6, 0.3f64..2.0), m),
            0.05f64..1.2,
            0.0f64..3.0,
            prop_oneof![Just(Paths::Literal), Just(Paths::Simple)],
            0..n,
            proptest::collection::vec(-5.0f64..5.0, n),
        )
            .prop_map(
                move |(weights, threshold, coefficient, paths, root, initial)| Case {
                    n,
                    edges: pairs
                        .iter()
                        .zip(weights)
                        .filter_map(|(&(i, j), w)| w.map(|w| (i, j, w)))
                        .collect(),
                    threshold,
                    coefficient,
                    paths,
                    root,
                    initial,
                },
            )
    })
}

proptest! {
    #[test]
    fn spreading_terminates_within_the_depth_bound(c in case()) {
        let (_, trace) = c.trace(c.paths, c.coefficient);
        // Ω grows by ≥ 0.3 per edge, so a call at depth h ≥ 5 has Ω ≥ 1.5 > T_ω and none
        // deeper than that depth is ever made; each call fans out to at most n − 1.
        let d = c.n.saturating_sub(1);
        let bound: usize = (1..=4).map(|h| d.pow(h)).sum();
        prop_assert!(trace.len() <= bound, "{} calls > {bound}", trace.len());
        prop_assert!(trace.iter().all(|s| s.h <= 4));
    }

    #[test]
    fn every_deposit_is_non_negative_and_activations_only_grow(c in case()) {
        let (a, trace) = c.trace(c.paths, c.coefficient);
        prop_assert!(trace.iter().all(|s| s.delta >= 0.0 && s.delta.is_finite()));
        prop_assert!(trace.iter().all(|s| s.stopped == (s.omega >= c.threshold)));
        prop_assert!(a.iter().zip(&c.initial).all(|(after, before)| after >= before));
    }

    #[test]
    fn probabilities_sum_to_one(c in case(), scale in prop_oneof![Just(1.0), Just(1e3), Just(1e6)], tau in 0.01f64..100.0) {
        let (a, _) = c.trace(c.paths, c.coefficient);
        let a: Vec<f64> = a.iter().map(|x| x * scale).collect();
        let p = probabilities(&a, tau);
        prop_assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-9, "{p:?}");
        prop_assert!(p.iter().all(|&x| (0.0..=1.0).contains(&x)));
    }

    #[test]
    fn coefficient_zero_changes_nothing(c in case()) {
        let (a, trace) = c.trace(c.paths, 0.0);
        prop_assert_eq!(a, c.initial.clone());
        prop_assert!(trace.iter().all(|s| s.delta == 0.0));
    }

    #[test]
    fn simple_paths_never_deposit_more_than_literal_ones(c in case()) {
        // Each simple walk is also a literal walk with the same h, Ω and η, so simple
        // deposits are a subset of literal ones.
        let total = |paths| c.trace(paths, c.coefficient).1.iter().map(|s| s.delta).sum::<f64>();
        let (simple, literal) = (total(Paths::Simple), total(Paths::Literal));
        prop_assert!(simple <= literal * (1.0 + 1e-12), "{simple} > {literal}");
    }

    #[test]
    fn recursion_stepper_and_fast_path_agree_bit_for_bit(c in case()) {
        let graph = c.graph();
        let mut reference = c.initial.clone();
        let mut expected = Vec::new();
        activate_recursive(&graph, c.spreading(), c.root, c.coefficient, &mut reference, &mut expected);

        let mut a = c.initial.clone();
        let mut spreader = Spreader::activate(&graph, c.spreading(), c.root, c.coefficient, &mut a);
        let mut stepped = Vec::new();
        while let Some(step) = spreader.step(&mut a) {
            stepped.push(step);
        }
        prop_assert_eq!(&stepped, &expected);
        prop_assert_eq!(&a, &reference);

        let (fast, traced) = c.trace(c.paths, c.coefficient);
        prop_assert_eq!(&traced, &expected);
        prop_assert_eq!(&fast, &reference);

        // Leaving out the stopped calls leaves the deposits, and their order, unchanged.
        let mut quiet = c.initial.clone();
        let mut deposits = Deposits::default();
        spreading::activate(&graph, c.spreading(), c.root, c.coefficient, &mut quiet, &mut deposits);
        let unstopped: Vec<_> = expected.iter().copied().filter(|s| !s.stopped).collect();
        prop_assert_eq!(deposits.0, unstopped);
        prop_assert_eq!(quiet, reference);
    }
}
