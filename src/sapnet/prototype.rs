//! Categories (paper II-C) and prototype matrices (eq. 5).
//!
//! A prototype looks at a policy from one viewpoint and names its category; two policies
//! are related under the prototype when the names agree.

use super::params::{Prototype, WeightedPrototype};
use super::policy::PolicyDescription;

/// The category a prototype puts a policy in. Only equality matters.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Category<'a> {
    HiddenLayers(usize),
    UnitsBucket(usize),
    SourceTask(&'a str),
    Activation(&'a str),
}

impl Prototype {
    /// The category of `policy` under this prototype.
    ///
    /// `UnitsBucket { width }` buckets the mean units per hidden layer, rounded down, by
    /// `width` (a width of 0 is treated as 1); a policy without hidden layers has mean 0.
    pub fn category<'a>(&self, policy: &'a PolicyDescription) -> Category<'a> {
        match self {
            Prototype::HiddenLayers => Category::HiddenLayers(policy.hidden.len()),
            Prototype::UnitsBucket { width } => {
                let layers = policy.hidden.len().max(1);
                let mean = policy.hidden.iter().sum::<usize>() / layers;
                Category::UnitsBucket(mean / (*width).max(1))
            }
            Prototype::SourceTask => Category::SourceTask(&policy.source_task),
            Prototype::Activation => Category::Activation(&policy.activation),
        }
    }

    /// The category of each of `policies`, numbered in order of appearance: what the
    /// screens group the graph's nodes by.
    pub fn group_indices<'a>(
        &self,
        policies: impl IntoIterator<Item = &'a PolicyDescription>,
    ) -> Vec<usize> {
        let mut keys = Vec::new();
        policies
            .into_iter()
            .map(|p| {
                let key = self.category(p);
                keys.iter().position(|k| *k == key).unwrap_or_else(|| {
                    keys.push(key);
                    keys.len() - 1
                })
            })
            .collect()
    }

    /// Whether two policies share a category under this prototype.
    pub fn relates(&self, a: &PolicyDescription, b: &PolicyDescription) -> bool {
        self.category(a) == self.category(b)
    }
}

/// The prototype matrix P_c of eq. 5, row-major N×N: `P_c[i][j] = ω_c` when i ≠ j share
/// a category under c, else 0.
pub fn prototype_matrix(policies: &[PolicyDescription], weighted: &WeightedPrototype) -> Vec<f64> {
    let n = policies.len();
    let mut p = vec![0.0; n * n];
    for (i, a) in policies.iter().enumerate() {
        for (j, b) in policies.iter().enumerate() {
            if i != j && weighted.prototype.relates(a, b) {
                p[i * n + j] = weighted.omega;
            }
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    fn policy(hidden: &[usize]) -> PolicyDescription {
        PolicyDescription::new(hidden.to_vec(), "CartPole-v1")
    }

    #[test]
    fn hidden_layers_counts_layers_not_units() {
        let p = Prototype::HiddenLayers;
        assert!(p.relates(&policy(&[64, 64]), &policy(&[150, 20])));
        assert!(!p.relates(&policy(&[64]), &policy(&[64, 64])));
    }

    #[test]
    fn units_bucket_uses_the_mean_per_layer() {
        let p = Prototype::UnitsBucket { width: 50 };
        // Means 100 and 110 share bucket 2; mean 149 too; 150 is bucket 3.
        assert!(p.relates(&policy(&[100]), &policy(&[100, 120])));
        assert!(p.relates(&policy(&[100]), &policy(&[149])));
        assert!(!p.relates(&policy(&[100]), &policy(&[150])));
    }

    #[test]
    fn source_task_and_activation_compare_names() {
        let a = PolicyDescription::new(vec![10], "CartPole-v1");
        let mut b = PolicyDescription::new(vec![10], "MountainCar-v0");
        assert!(!Prototype::SourceTask.relates(&a, &b));
        assert!(Prototype::Activation.relates(&a, &b));
        b.activation = "tanh".into();
        assert!(!Prototype::Activation.relates(&a, &b));
    }

    #[test]
    fn prototype_matrix_has_omega_off_the_diagonal_within_a_category() {
        let policies = [policy(&[10]), policy(&[20]), policy(&[10, 10])];
        let p = prototype_matrix(
            &policies,
            &WeightedPrototype {
                prototype: Prototype::HiddenLayers,
                omega: 0.1,
            },
        );
        #[rustfmt::skip]
        let expected = [
            0.0, 0.1, 0.0,
            0.1, 0.0, 0.0,
            0.0, 0.0, 0.0,
        ];
        assert_eq!(p, expected);
    }
}
