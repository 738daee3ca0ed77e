//! Selecting the policy that acts (paper II-E, eq. 6).
//!
//! `P(π_i) = exp(A_i/τ) / Σ_j exp(A_j/τ)`. Activations only grow during a run, so they
//! soon overflow `exp`; subtracting max_j A_j first leaves every ratio unchanged and keeps
//! the largest term at exp(0) = 1.

use rand::Rng;

/// The selection probabilities of eq. 6 at temperature `tau`, written into `out`.
///
/// # Panics
/// If `out` and `activations` differ in length.
pub fn probabilities_into(activations: &[f64], tau: f64, out: &mut [f64]) {
    assert_eq!(activations.len(), out.len(), "one probability per policy");
    let max = max(activations);
    let mut total = 0.0;
    for (p, &a) in out.iter_mut().zip(activations) {
        *p = ((a - max) / tau).exp();
        total += *p;
    }
    out.iter_mut().for_each(|p| *p /= total);
}

/// The selection probabilities of eq. 6 at temperature `tau`.
pub fn probabilities(activations: &[f64], tau: f64) -> Vec<f64> {
    let mut out = vec![0.0; activations.len()];
    probabilities_into(activations, tau, &mut out);
    out
}

/// Draws a policy index with the probabilities of eq. 6, without allocating: one uniform
/// number is compared with the running sum of the unnormalised terms.
///
/// # Panics
/// If there are no policies.
pub fn select(activations: &[f64], tau: f64, rng: &mut impl Rng) -> usize {
    assert!(!activations.is_empty(), "selecting from no policies");
    let max = max(activations);
    let term = |a: f64| ((a - max) / tau).exp();
    let total: f64 = activations.iter().map(|&a| term(a)).sum();
    let target = rng.random::<f64>() * total;
    let mut running = 0.0;
    let mut last_possible = 0;
    for (i, &a) in activations.iter().enumerate() {
        let t = term(a);
        running += t;
        if target < running {
            return i;
        }
        if t > 0.0 {
            last_possible = i;
        }
    }
    // Rounding left the running sum a hair below `target`: the draw belongs to the last
    // policy that can be drawn at all.
    last_possible
}

fn max(values: &[f64]) -> f64 {
    values.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

#[cfg(test)]
mod tests {
    use rand::rngs::StdRng;
    use rand::SeedableRng;

    use super::*;

    #[test]
    fn sampling_follows_the_probabilities() {
        let a = [0.0, 1.0, 2.0];
        let p = probabilities(&a, 1.0);
        let mut rng = StdRng::seed_from_u64(7);
        let mut counts = [0usize; 3];
        let draws = 200_000;
        for _ in 0..draws {
            counts[select(&a, 1.0, &mut rng)] += 1;
        }
        for (c, p) in counts.iter().zip(&p) {
            // Binomial standard deviation is below 0.0012 here; allow five of them.
            assert!(
                (*c as f64 / draws as f64 - p).abs() < 0.006,
                "{counts:?} vs {p:?}"
            );
        }
    }

    #[test]
    fn a_policy_with_probability_zero_is_never_drawn() {
        // exp(-800) underflows to 0: only policy 1 can be drawn.
        let a = [0.0, 800.0];
        let mut rng = StdRng::seed_from_u64(1);
        assert!((0..1000).all(|_| select(&a, 1.0, &mut rng) == 1));
    }
}
