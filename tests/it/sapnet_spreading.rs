//! Activation and spreading on the paper's graphs, against values computed by hand.

use sapnet::sapnet::spreading::{self, activate_recursive};
use sapnet::sapnet::{
    Graph, Paths, PolicyDescription, SapNet, SapNetParams, Spreader, Spreading, TraceStep,
};

/// The paper's Fig. 2 (eq. 4) with every weight 0.4: edges 0–1, 0–2, 1–2, 1–3, so the
/// degrees are k = [2, 3, 2, 1].
fn fig2() -> Graph {
    Graph::from_edges(4, [(0, 1, 0.4), (0, 2, 0.4), (1, 2, 0.4), (1, 3, 0.4)]).unwrap()
}

fn spread_fig2(paths: Paths) -> (Vec<f64>, Vec<TraceStep>) {
    let spreading = Spreading {
        threshold: 1.0,
        paths,
    };
    let mut a = vec![0.0; 4];
    let mut trace = Vec::new();
    spreading::activate(&fig2(), spreading, 1, 1.0, &mut a, &mut trace);
    (a, trace)
}

fn assert_close(got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1e-12, "got {got:?}, want {want:?}");
    }
}

/// Activating π1 with 𝒜 = 1, T_ω = 1, paths that may step back:
///
/// ```text
/// A1 += 1; k1 = 3, so η = 1/3 to each of π0, π2, π3.
/// π0: h=1 Ω=0.4: ΔA0 = (1/3)/(1·0.4) = 5/6;  k0 = 2, η = 1/6 onwards
///   π1: h=2 Ω=0.8: ΔA1 = (1/6)/(2·0.8) = 5/48;  onwards Ω = 1.2 ≥ 1: 3 stopped calls
///   π2: h=2 Ω=0.8: ΔA2 = 5/48;                  onwards Ω = 1.2: 2 stopped calls
/// π2: h=1 Ω=0.4: ΔA2 = 5/6;  k2 = 2, η = 1/6
///   π0: h=2 Ω=0.8: ΔA0 = 5/48;                  2 stopped calls
///   π1: h=2 Ω=0.8: ΔA1 = 5/48;                  3 stopped calls
/// π3: h=1 Ω=0.4: ΔA3 = 5/6;  k3 = 1, η = 1/3
///   π1: h=2 Ω=0.8: ΔA1 = (1/3)/(2·0.8) = 5/24;  3 stopped calls
///
/// A0 = 5/6 + 5/48         = 45/48 = 0.9375
/// A1 = 1 + 5/48 + 5/48 + 5/24 = 1 + 20/48 = 1.41666…
/// A2 = 5/6 + 5/48         = 0.9375
/// A3 = 5/6                = 0.83333…
/// ```
/// 8 deposits and 13 stopped calls: 21 calls.
#[test]
fn fig2_literal_paths_match_the_hand_computation() {
    let (a, trace) = spread_fig2(Paths::Literal);
    assert_close(&a, &[0.9375, 1.0 + 20.0 / 48.0, 0.9375, 5.0 / 6.0]);
    assert_eq!(trace.len(), 21);
    assert_eq!(trace.iter().filter(|s| s.stopped).count(), 13);

    let calls: Vec<_> = trace
        .iter()
        .map(|s| (s.from, s.to, s.h, s.stopped))
        .collect();
    #[rustfmt::skip]
    let expected = [
        (1, 0, 1, false),
            (0, 1, 2, false), (1, 0, 3, true), (1, 2, 3, true), (1, 3, 3, true),
            (0, 2, 2, false), (2, 0, 3, true), (2, 1, 3, true),
        (1, 2, 1, false),
            (2, 0, 2, false), (0, 1, 3, true), (0, 2, 3, true),
            (2, 1, 2, false), (1, 0, 3, true), (1, 2, 3, true), (1, 3, 3, true),
        (1, 3, 1, false),
            (3, 1, 2, false), (1, 0, 3, true), (1, 2, 3, true), (1, 3, 3, true),
    ];
    assert_eq!(calls, expected);

    // The last deposit: π3 passes on all of its η = 1/3 (k3 = 1) over Ω = 0.4 + 0.4.
    let s = trace[17];
    assert!((s.eta - 1.0 / 3.0).abs() < 1e-15 && (s.omega - 0.8).abs() < 1e-15);
    assert!((s.delta - 5.0 / 24.0).abs() < 1e-15);
    assert!(trace
        .iter()
        .filter(|s| s.stopped)
        .all(|s| s.delta == 0.0 && s.omega >= 1.0));
}

/// With simple paths no walk revisits a policy, π1 included:
///
/// ```text
/// π0: ΔA0 = 5/6; onwards only to π2 (π1 is on the path): h=2 Ω=0.8 η=1/6, ΔA2 = 5/48
/// π2: ΔA2 = 5/6; onwards only to π0:                      ΔA0 = 5/48
/// π3: ΔA3 = 5/6; its only neighbour π1 is on the path.
/// A = [5/6 + 5/48, 1, 5/6 + 5/48, 5/6] = [0.9375, 1, 0.9375, 0.83333…]
/// ```
#[test]
fn fig2_simple_paths_match_the_hand_computation() {
    let (a, trace) = spread_fig2(Paths::Simple);
    assert_close(&a, &[0.9375, 1.0, 0.9375, 5.0 / 6.0]);
    let calls: Vec<_> = trace.iter().map(|s| (s.from, s.to, s.h)).collect();
    assert_eq!(
        calls,
        [(1, 0, 1), (0, 2, 2), (1, 2, 1), (2, 0, 2), (1, 3, 1)]
    );
}

#[test]
fn stepping_fig2_makes_the_recursions_calls_one_at_a_time() {
    let g = fig2();
    let spreading = Spreading {
        threshold: 1.0,
        paths: Paths::Literal,
    };
    let mut reference = vec![0.0; 4];
    let mut expected = Vec::new();
    activate_recursive(&g, spreading, 1, 1.0, &mut reference, &mut expected);

    let mut a = vec![0.0; 4];
    let mut spreader = Spreader::activate(&g, spreading, 1, 1.0, &mut a);
    assert_eq!(
        a,
        [0.0, 1.0, 0.0, 0.0],
        "activation (eq. 8) happens before any spread call"
    );
    assert_eq!(spreader.pending().len(), 3);
    let first = *spreader.next_call().unwrap();
    assert_eq!((first.from, first.to, first.h, first.omega), (1, 0, 1, 0.4));

    let mut steps = Vec::new();
    // Undo by snapshot: step twice, go back one, step again: the same step comes out.
    let before_second = {
        steps.push(spreader.step(&mut a).unwrap());
        (spreader.clone(), a.clone())
    };
    let second = spreader.step(&mut a).unwrap();
    let (mut spreader, mut a) = before_second;
    assert_eq!(spreader.step(&mut a), Some(second));
    steps.push(second);
    while let Some(step) = spreader.step(&mut a) {
        steps.push(step);
    }
    assert!(spreader.is_done());
    assert_eq!(steps, expected);
    assert_eq!(a, reference);
}

/// Ten policies in three categories of the number of hidden layers (3, 4 and 3 policies),
/// Table II's parameters.
fn table2() -> SapNet {
    let layers = [1, 1, 1, 2, 2, 2, 2, 3, 3, 3];
    let policies: Vec<_> = layers
        .iter()
        .map(|&l| PolicyDescription::new(vec![100; l], "CartPole-v1"))
        .collect();
    SapNet::from_policies(&policies, SapNetParams::default()).unwrap()
}

#[test]
fn table2_same_category_edges_weigh_0_95_by_eq5() {
    let net = table2();
    let m = net.graph().matrix();
    for i in 0..10 {
        for j in 0..10 {
            let same = i != j && net_category(i) == net_category(j);
            // 1 (eq. 3) + δ·ω_c = 1 − 0.5·0.1 (eq. 5); no edge across categories.
            assert_eq!(m[i * 10 + j], if same { 0.95 } else { 0.0 }, "M[{i}][{j}]");
        }
    }
}

fn net_category(i: usize) -> usize {
    [1, 1, 1, 2, 2, 2, 2, 3, 3, 3][i]
}

/// Ω = 0.95 < T_ω deposits (𝒜/k)/(1·0.95) in each same-category neighbour; one edge
/// further Ω = 1.90 ≥ T_ω stops. Nobody else moves.
#[test]
fn table2_activation_reaches_exactly_the_same_category_neighbours() {
    for i in 0..10 {
        let mut net = table2();
        let mut trace = Vec::new();
        net.activate_traced(i, true, &mut trace);
        let k = net.graph().degree(i) as f64;
        for (j, &a) in net.activations().iter().enumerate() {
            let want = if j == i {
                1.0
            } else if net_category(j) == net_category(i) {
                (1.0 / k) / 0.95
            } else {
                0.0
            };
            assert_eq!(a, want, "activating {i}: A[{j}]");
        }
        assert!(trace.iter().all(|s| (s.h == 1) != s.stopped), "{trace:?}");
    }
}

#[test]
fn a_negative_transition_changes_nothing() {
    let mut net = table2();
    net.activate(4, false);
    assert_eq!(net.activations(), [0.0; 10]);
    let mut trace = Vec::new();
    net.activate_traced(4, false, &mut trace);
    assert_eq!(net.activations(), [0.0; 10]);
    assert!(!trace.is_empty() && trace.iter().all(|s| s.delta == 0.0));
}

#[test]
fn the_chosen_policy_is_the_most_activated() {
    let mut net = table2();
    net.activate(5, true);
    net.activate(8, true);
    net.activate(5, true);
    assert_eq!(net.chosen(), 5);
    assert!(SapNet::judge(0.3, 0.2) && !SapNet::judge(0.2, 0.3));
}
