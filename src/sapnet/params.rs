//! SAP-Net's parameters (paper Table II) as read from a config.

use serde::{Deserialize, Serialize};

use super::error::SapNetError;

/// A way of putting policies into categories (paper II-C). Two policies share a category
/// under a prototype when the prototype gives them the same key.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum Prototype {
    /// Number of hidden layers: the paper's only prototype.
    HiddenLayers,
    /// Units per hidden layer (mean over layers) bucketed by `width`.
    UnitsBucket { width: usize },
    /// The task the policy was trained on.
    SourceTask,
    /// The hidden layers' activation function.
    Activation,
}

/// A prototype and its weight ω_c in the prototype matrix P_c (eq. 5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightedPrototype {
    pub prototype: Prototype,
    /// ω_c: the entry `P_c[i][j]` for policies i ≠ j in the same category (Table II: 0.1).
    pub omega: f64,
}

/// Which pairs of policies are joined before the prototypes adjust the weights (eq. 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BaseGraph {
    /// Joined when they share a category under at least one prototype.
    SharedCategory,
    /// Every pair joined.
    Complete,
}

/// Which walks the spreading recursion may take (Algorithm 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Paths {
    /// The paper: only the threshold T_ω bounds a walk, which may step back.
    Literal,
    /// No policy twice on one walk.
    Simple,
}

/// SAP-Net parameters. Defaults are the paper's Table II.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SapNetParams {
    /// The prototypes in use, each with its ω_c.
    pub prototypes: Vec<WeightedPrototype>,
    /// δ, adjustment weight of the prototype matrices (eq. 5; Table II: −0.5).
    pub delta: f64,
    /// T_ω, the spreading threshold on the summed path weight (eq. 10; Table II: 1.0).
    pub threshold: f64,
    /// 𝒜, the activated coefficient (eq. 8; Table II: 1.0).
    pub coefficient: f64,
    /// τ, the softmax temperature of selection (eq. 6; the paper: 1).
    pub temperature: f64,
    pub base_graph: BaseGraph,
    pub paths: Paths,
}

impl Default for SapNetParams {
    fn default() -> Self {
        Self {
            prototypes: vec![WeightedPrototype {
                prototype: Prototype::HiddenLayers,
                omega: 0.1,
            }],
            delta: -0.5,
            threshold: 1.0,
            coefficient: 1.0,
            temperature: 1.0,
            base_graph: BaseGraph::SharedCategory,
            paths: Paths::Literal,
        }
    }
}

impl SapNetParams {
    /// Checks what the types cannot: T_ω, τ and 𝒜 finite and > 0 (a walk must be able to
    /// stop, a softmax must be defined, a good step must be credited), δ and every ω_c finite, bucket widths ≥ 1, and
    /// every edge eq. 5 can produce heavier than 0.
    pub fn validate(&self) -> Result<(), SapNetError> {
        let bad = |name: &str, value: f64, expected| SapNetError::BadParameter {
            name: name.to_string(),
            value,
            expected,
        };
        let positive = |name: &str, value: f64| {
            if value > 0.0 && value.is_finite() {
                Ok(())
            } else {
                Err(bad(name, value, "a finite number > 0"))
            }
        };
        let finite = |name: &str, value: f64| {
            if value.is_finite() {
                Ok(())
            } else {
                Err(bad(name, value, "a finite number"))
            }
        };
        positive("threshold", self.threshold)?;
        positive("temperature", self.temperature)?;
        // A negative transition activates with 0 (Algorithm 3): 𝒜 ≤ 0 would never credit a
        // good step, and activations would fall below the ones nothing ever activated.
        if !(self.coefficient > 0.0 && self.coefficient.is_finite()) {
            return Err(bad(
                "coefficient",
                self.coefficient,
                "a finite number > 0 (𝒜 activates a policy after a positive transition)",
            ));
        }
        finite("delta", self.delta)?;
        for (c, weighted) in self.prototypes.iter().enumerate() {
            finite(&format!("prototypes[{c}].omega"), weighted.omega)?;
            if let Prototype::UnitsBucket { width: 0 } = weighted.prototype {
                return Err(bad(&format!("prototypes[{c}].width"), 0.0, "at least 1"));
            }
        }
        // Two policies that share every category are joined by 1 + δ·Σ ω_c (eq. 3, 5); the
        // lightest that can happen must still be a positive distance.
        let lightest = 1.0
            + self
                .prototypes
                .iter()
                .map(|p| (self.delta * p.omega).min(0.0))
                .sum::<f64>();
        if lightest <= 0.0 {
            return Err(bad(
                "delta",
                self.delta,
                "δ and ω_c with 1 + δ·Σω_c > 0, or policies sharing every category \
                 would be joined by a weight ≤ 0",
            ));
        }
        Ok(())
    }
}
