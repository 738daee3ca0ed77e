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
    draw(activations.iter().map(|&a| term(a)), total, rng)
}

/// Eq. 6's unnormalised terms `exp((A_i − max_j A_j)/τ)` and their sum, kept between
/// activations: the transfer loop selects at every step but activates only after a
/// positive transition, so this saves N `exp` calls on most steps. Draws and
/// probabilities are bit-identical to [`select`] and [`probabilities`].
#[derive(Debug, Clone, PartialEq)]
pub struct SelectionTerms {
    terms: Vec<f64>,
    total: f64,
}

impl SelectionTerms {
    pub fn new(activations: &[f64], tau: f64) -> Self {
        let mut terms = Self {
            terms: Vec::with_capacity(activations.len()),
            total: 0.0,
        };
        terms.update(activations, tau);
        terms
    }

    /// Recomputes the terms after the activations changed.
    pub fn update(&mut self, activations: &[f64], tau: f64) {
        let max = max(activations);
        self.terms.clear();
        self.terms
            .extend(activations.iter().map(|&a| ((a - max) / tau).exp()));
        self.total = self.terms.iter().sum();
    }

    /// As [`select`] on the activations of the last update.
    ///
    /// # Panics
    /// If there are no policies.
    pub fn draw(&self, rng: &mut impl Rng) -> usize {
        assert!(!self.terms.is_empty(), "selecting from no policies");
        draw(self.terms.iter().copied(), self.total, rng)
    }

    /// The largest probability: the largest term over the sum.
    pub fn top(&self) -> f64 {
        let largest = self.terms.iter().copied().fold(0.0, f64::max);
        largest / self.total
    }

    /// As [`probabilities`] on the activations of the last update.
    pub fn probabilities(&self) -> Vec<f64> {
        self.terms.iter().map(|t| t / self.total).collect()
    }
}

/// Eq. 6 over the candidates only (`excluded[i]` false): the others' probabilities are 0,
/// and the candidates' are renormalised among themselves. The largest activation of the
/// candidates is subtracted, not of all: an excluded policy far ahead would otherwise
/// round every candidate's term to 0.
///
/// # Panics
/// If `excluded` differs in length from `activations` or excludes every policy.
pub fn candidate_probabilities(activations: &[f64], tau: f64, excluded: &[bool]) -> Vec<f64> {
    let term = candidate_term(activations, tau, excluded);
    let total: f64 = (0..activations.len()).map(&term).sum();
    (0..activations.len()).map(|i| term(i) / total).collect()
}

/// As [`select`] over the candidates, with the probabilities of
/// [`candidate_probabilities`]; one uniform number, as [`select`] draws, and no
/// allocation (it runs at every step while a category is excluded).
pub fn select_candidate(
    activations: &[f64],
    tau: f64,
    excluded: &[bool],
    rng: &mut impl Rng,
) -> usize {
    let term = candidate_term(activations, tau, excluded);
    let total = (0..activations.len()).map(&term).sum();
    draw((0..activations.len()).map(term), total, rng)
}

/// Policy i's unnormalised term among the candidates: `exp((A_i − max_cand A)/τ)`, 0 for
/// an excluded one.
fn candidate_term<'a>(
    activations: &'a [f64],
    tau: f64,
    excluded: &'a [bool],
) -> impl Fn(usize) -> f64 + 'a {
    assert_eq!(activations.len(), excluded.len(), "one flag per policy");
    assert!(excluded.iter().any(|e| !e), "no candidate is left");
    let max = activations
        .iter()
        .zip(excluded)
        .filter(|(_, &e)| !e)
        .map(|(&a, _)| a)
        .fold(f64::NEG_INFINITY, f64::max);
    move |i| {
        if excluded[i] {
            0.0
        } else {
            ((activations[i] - max) / tau).exp()
        }
    }
}

fn draw(terms: impl Iterator<Item = f64>, total: f64, rng: &mut impl Rng) -> usize {
    let target = rng.random::<f64>() * total;
    let mut running = 0.0;
    let mut last_possible = 0;
    for (i, t) in terms.enumerate() {
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

    /// By hand: A = (0, ln 3, 1000) at τ 1 with the third excluded: e^0 and e^{ln 3}
    /// over their sum, 1/4 and 3/4, and the third never drawn.
    #[test]
    fn an_excluded_policy_is_never_drawn_and_the_others_renormalise() {
        let a = [0.0, 3f64.ln(), 1000.0];
        let excluded = [false, false, true];
        let p = candidate_probabilities(&a, 1.0, &excluded);
        assert!(
            (p[0] - 0.25).abs() < 1e-12 && (p[1] - 0.75).abs() < 1e-12,
            "{p:?}"
        );
        assert_eq!(p[2], 0.0);
        let mut rng = StdRng::seed_from_u64(3);
        for _ in 0..10_000 {
            assert_ne!(select_candidate(&a, 1.0, &excluded, &mut rng), 2);
        }
    }

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

    #[test]
    fn kept_terms_draw_and_weigh_exactly_as_the_formula() {
        let mut rng_formula = StdRng::seed_from_u64(3);
        let mut rng_kept = StdRng::seed_from_u64(3);
        let mut terms = SelectionTerms::new(&[0.0; 4], 0.5);
        for a in [[0.0, 0.3, 2.5, 1e-9], [5e5, 5e5 + 0.25, 4e5, 5e5 - 1.0]] {
            terms.update(&a, 0.5);
            assert_eq!(terms.probabilities(), probabilities(&a, 0.5));
            for _ in 0..1000 {
                assert_eq!(terms.draw(&mut rng_kept), select(&a, 0.5, &mut rng_formula));
            }
        }
    }
}
