//! A SAP-Net that could spread forever, or divide by zero, is refused and the culprit named.

use sapnet::sapnet::{
    BaseGraph, Graph, PolicyDescription, Prototype, SapNet, SapNetError, SapNetParams,
    WeightedPrototype,
};

#[test]
fn a_weight_that_is_not_positive_and_finite_names_its_pair() {
    for weight in [0.0, -0.4, f64::NAN, f64::INFINITY] {
        let err = Graph::from_edges(3, [(0, 1, 0.4), (2, 1, weight)]).unwrap_err();
        assert!(
            matches!(err, SapNetError::BadWeight { i: 2, j: 1, .. }),
            "{weight}: {err:?}"
        );
        let message = err.to_string();
        assert!(message.starts_with("edge (2, 1) weighs"), "{message}");
        assert!(message.contains("> 0"), "{message}");
    }
}

#[test]
fn eq5_pushing_a_weight_to_zero_is_refused_at_its_parameters() {
    let policies: Vec<_> = [1, 2, 1]
        .iter()
        .map(|&l| PolicyDescription::new(vec![100; l], "CartPole-v1"))
        .collect();
    // δ·ω_c = −10·0.1 = −1: the same-category pair (0, 2) would weigh 1 − 1 = 0. The
    // parameters alone say so, before any graph is built.
    let params = SapNetParams {
        delta: -10.0,
        ..SapNetParams::default()
    };
    let err = Graph::from_categories(&policies, &params).unwrap_err();
    assert!(
        matches!(&err, SapNetError::BadParameter { name, .. } if name == "delta"),
        "{err:?}"
    );
    assert!(err.to_string().contains("1 + δ·Σω_c > 0"), "{err}");
}

#[test]
fn a_complete_base_graph_keeps_unrelated_pairs_at_weight_1() {
    let policies: Vec<_> = [1, 2, 1]
        .iter()
        .map(|&l| PolicyDescription::new(vec![100; l], "CartPole-v1"))
        .collect();
    let params = SapNetParams {
        base_graph: BaseGraph::Complete,
        ..SapNetParams::default()
    };
    let g = Graph::from_categories(&policies, &params).unwrap();
    assert_eq!(
        g.edges().collect::<Vec<_>>(),
        [(0, 1, 1.0), (0, 2, 0.95), (1, 2, 1.0)]
    );
}

#[test]
fn two_shared_prototypes_add_up_in_eq5() {
    let policies = [
        PolicyDescription::new(vec![100], "CartPole-v1"),
        PolicyDescription::new(vec![110], "CartPole-v1"),
    ];
    let params = SapNetParams {
        prototypes: vec![
            WeightedPrototype {
                prototype: Prototype::HiddenLayers,
                omega: 0.1,
            },
            WeightedPrototype {
                prototype: Prototype::SourceTask,
                omega: 0.3,
            },
        ],
        ..SapNetParams::default()
    };
    let g = Graph::from_categories(&policies, &params).unwrap();
    // 1 − 0.5·(0.1 + 0.3) = 0.8
    assert!((g.weight(0, 1).unwrap() - 0.8).abs() < 1e-15);
}

#[test]
fn a_threshold_that_is_not_positive_and_finite_names_the_parameter() {
    for threshold in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let params = SapNetParams {
            threshold,
            ..SapNetParams::default()
        };
        let err = SapNet::new(Graph::from_edges(2, [(0, 1, 0.5)]).unwrap(), params).unwrap_err();
        assert!(
            matches!(&err, SapNetError::BadParameter { name, .. } if name == "threshold"),
            "{threshold}: {err:?}"
        );
        assert!(
            err.to_string().starts_with("parameter `threshold` is"),
            "{err}"
        );
    }
}

#[test]
fn other_parameters_are_named_too() {
    let graph = || Graph::from_edges(2, [(0, 1, 0.5)]).unwrap();
    let cases: [(SapNetParams, &str); 4] = [
        (
            SapNetParams {
                temperature: 0.0,
                ..SapNetParams::default()
            },
            "temperature",
        ),
        (
            SapNetParams {
                coefficient: f64::NAN,
                ..SapNetParams::default()
            },
            "coefficient",
        ),
        (
            SapNetParams {
                delta: f64::NEG_INFINITY,
                ..SapNetParams::default()
            },
            "delta",
        ),
        (
            SapNetParams {
                prototypes: vec![WeightedPrototype {
                    prototype: Prototype::UnitsBucket { width: 0 },
                    omega: 0.1,
                }],
                ..SapNetParams::default()
            },
            "prototypes[0].width",
        ),
    ];
    for (params, field) in cases {
        let err = SapNet::new(graph(), params).unwrap_err();
        assert!(
            matches!(&err, SapNetError::BadParameter { name, .. } if name == field),
            "{field}: {err:?}"
        );
    }
}

#[test]
fn initial_activations_must_fit_the_graph() {
    let graph = || Graph::from_edges(2, [(0, 1, 0.5)]).unwrap();
    let p = SapNetParams::default;
    assert_eq!(
        SapNet::with_activations(graph(), p(), vec![0.0]).unwrap_err(),
        SapNetError::ActivationCount { n: 2, got: 1 }
    );
    assert!(matches!(
        SapNet::with_activations(graph(), p(), vec![0.0, f64::NAN]).unwrap_err(),
        SapNetError::BadActivation { i: 1, .. }
    ));
}

#[test]
fn a_graph_whose_walks_would_explode_is_refused() {
    // Six policies, degree up to 5, weight 0.05, T_ω = 1: walks deposit up to ⌊1/0.05⌋ = 20
    // hops deep, up to Σ 5^h ≈ 1.2·10^14 deposits for one activation.
    let mut edges: Vec<(usize, usize, f64)> = (1..6).map(|j| (0, j, 0.05)).collect();
    edges.extend([
        (1, 2, 0.05),
        (2, 3, 0.05),
        (3, 4, 0.05),
        (4, 5, 0.05),
        (5, 1, 0.05),
    ]);
    let graph = Graph::from_edges(6, edges).unwrap();
    let err = SapNet::new(graph, SapNetParams::default()).unwrap_err();
    assert!(
        matches!(err, SapNetError::UnboundedSpreading { degree: 5, .. }),
        "{err:?}"
    );
    assert!(err.to_string().contains("lightest edge 0.05"), "{err}");

    // Two policies ping-ponging: degree 1 but 10^9 hops.
    let graph = Graph::from_edges(2, [(0, 1, 1e-9)]).unwrap();
    assert!(matches!(
        SapNet::new(graph, SapNetParams::default()),
        Err(SapNetError::UnboundedSpreading { degree: 1, .. })
    ));

    // The paper's Fig. 2 at weight 0.4 is fine: deposits 2 hops deep, at most 3 + 9.
    let fig2 = Graph::from_edges(4, [(0, 1, 0.4), (0, 2, 0.4), (1, 2, 0.4), (1, 3, 0.4)]).unwrap();
    assert!(SapNet::new(fig2, SapNetParams::default()).is_ok());
    // So is a hub with 5000 neighbours at Table II's 0.95: one hop, 5000 deposits (walks
    // the threshold stops, 5000² of them, are not made, so they do not count).
    let n = 5001;
    let hub = Graph::from_edges(n, (1..n).map(|j| (0, j, 0.95))).unwrap();
    assert!(SapNet::new(hub, SapNetParams::default()).is_ok());
}

/// Fig. 2's graph: the lightest edge 0.4, the largest degree 3, T_ω = 1, so one activation
/// makes at most 3 + 9 = 12 deposits of at most 𝒜/0.4 each: it adds at most 31·𝒜 to an
/// activation, and 10¹² activations stay below f64::MAX for 𝒜 ≤ f64::MAX / (31·10¹²).
#[test]
fn an_activated_coefficient_that_could_overflow_the_activations_is_refused() {
    let fig2 = || Graph::from_edges(4, [(0, 1, 0.4), (0, 2, 0.4), (1, 2, 0.4), (1, 3, 0.4)]);
    let most = f64::MAX / (31.0 * 1e12);
    let with = |coefficient: f64| {
        SapNet::new(
            fig2().unwrap(),
            SapNetParams {
                coefficient,
                ..SapNetParams::default()
            },
        )
    };
    assert!(with(most).is_ok());
    // 𝒜 ≤ 0 would never credit a good step (Algorithm 3), whatever its size.
    for coefficient in [-most, -0.5, 0.0, -0.0] {
        assert!(
            matches!(with(coefficient), Err(SapNetError::BadParameter { ref name, .. }) if name == "coefficient"),
            "{coefficient}"
        );
    }
    let err = with(most * 1.001).unwrap_err();
    assert!(
        matches!(err, SapNetError::ActivationOverflow { most: m, .. } if m == most),
        "{err:?}"
    );
    let err = with(1e308).unwrap_err().to_string();
    assert!(err.contains("𝒜 = 1e308 is too large"), "{err}");
    assert!(err.contains("expected |𝒜| ≤ 5.799e294"), "{err}");
    // Activations that start high leave less room.
    let high = SapNet::with_activations(
        fig2().unwrap(),
        SapNetParams::default(),
        vec![f64::MAX, 0.0, 0.0, 0.0],
    );
    assert!(matches!(high, Err(SapNetError::ActivationOverflow { .. })));
}
