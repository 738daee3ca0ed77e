//! Selection by eq. 6: hand values, large activations, temperature.

use sapnet::sapnet::selection::{probabilities, select};

fn assert_close(got: &[f64], want: &[f64]) {
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1e-12, "got {got:?}, want {want:?}");
    }
}

#[test]
fn hand_values() {
    // exp(0) : exp(ln 2) : exp(ln 3) = 1 : 2 : 3.
    let p = probabilities(&[0.0, 2f64.ln(), 3f64.ln()], 1.0);
    assert_close(&p, &[1.0 / 6.0, 2.0 / 6.0, 3.0 / 6.0]);
    // Equal activations: uniform.
    assert_close(&probabilities(&[0.7; 4], 1.0), &[0.25; 4]);
}

#[test]
fn large_activations_neither_overflow_nor_lose_the_ratios() {
    // exp(1000) overflows f64; after subtracting the max the terms are 1 and 2.
    let p = probabilities(&[1000.0, 1000.0 + 2f64.ln()], 1.0);
    assert_close(&p, &[1.0 / 3.0, 2.0 / 3.0]);
    let p = probabilities(&[1e6, 0.0, -1e6], 1.0);
    assert_eq!(p, [1.0, 0.0, 0.0]);
}

#[test]
fn temperature_divides_the_activations() {
    // τ = 2: exp(0/2) : exp(2/2) = 1 : e.
    let e = 1f64.exp();
    assert_close(
        &probabilities(&[0.0, 2.0], 2.0),
        &[1.0 / (1.0 + e), e / (1.0 + e)],
    );
    // A high temperature flattens towards uniform, a low one sharpens towards the max.
    let hot = probabilities(&[0.0, 1.0], 1e6);
    assert!((hot[0] - 0.5).abs() < 1e-6);
    let cold = probabilities(&[0.0, 1.0], 1e-3);
    assert!(cold[1] > 1.0 - 1e-12);
}

#[test]
fn sampling_a_certain_policy_always_draws_it() {
    use rand::SeedableRng;
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    assert!((0..100).all(|_| select(&[-1e6, 5.0, -1e6], 1.0, &mut rng) == 1));
}
