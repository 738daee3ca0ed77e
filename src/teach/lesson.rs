//! The teach file: a small SAP-Net to step through by hand.
//!
//! The graph is given either by its `edges` (the weights of M directly, as in the paper's
//! Fig. 2) or by policy `descriptions` with `prototypes`, `delta` and `base_graph`, which
//! build M from categories (eq. 3–5). Everything else defaults to Table II. See
//! `assets/teach_fig2.ron` and `assets/teach_table2.ron`.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::questions::{self, Question};
use crate::ron_file::{parse_ron, sapnet_field, ConfigError};
use crate::sapnet::{
    BaseGraph, Graph, Paths, PolicyDescription, Prototype, SapNet, SapNetError, SapNetParams,
    WeightedPrototype,
};

/// The paper's Fig. 2, used when no teach file is given.
pub const FIG2: &str = include_str!("../../assets/teach_fig2.ron");

/// A teach file as written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TeachConfig {
    /// N, the number of policies. May be left out (or 0) when `names` or `descriptions`
    /// count them.
    pub policies: usize,
    /// Names shown for the policies; default π0, π1, …
    pub names: Vec<String>,
    /// The graph as undirected edges `(i, j, M_ij)`, 0-based. Leave empty to build the
    /// graph from `descriptions`.
    pub edges: Vec<(usize, usize, f64)>,
    /// The policies' features; when given, M is built from their categories (eq. 3–5)
    /// and `edges` must be empty.
    pub descriptions: Vec<PolicyDescription>,
    /// The prototypes in use with their ω_c (with `descriptions`).
    pub prototypes: Vec<WeightedPrototype>,
    /// δ of eq. 5 (with `descriptions`).
    pub delta: f64,
    /// Which pairs eq. 3 joins (with `descriptions`).
    pub base_graph: BaseGraph,
    /// T_ω of eq. 10.
    pub threshold: f64,
    /// 𝒜 of eq. 8.
    pub coefficient: f64,
    /// τ of eq. 6.
    pub temperature: f64,
    pub paths: Paths,
    /// Activations before the first activation; default all 0.
    pub initial: Option<Vec<f64>>,
    /// Where the walk on screen stood when the lesson was saved (`w`): teach mode reopens
    /// there, and `--headless` without `--activate` prints that walk so far.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub walk: Option<WalkPosition>,
    /// D, the share of every activation lost between two activations (A ← (1−D)·A). The
    /// paper has no decay (eq. 8–11): D = 0, the default, is the paper.
    #[serde(skip_serializing_if = "is_zero")]
    pub decay: f64,
    /// Questions asked when a walk ends, each with its hidden answer.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub questions: Vec<Question>,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// Where a saved walk stood: the policy activated (from `initial`) and the `spread` calls
/// made so far.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WalkPosition {
    pub activate: usize,
    pub calls: usize,
}

impl Default for TeachConfig {
    fn default() -> Self {
        let p = SapNetParams::default();
        Self {
            policies: 0,
            names: Vec::new(),
            edges: Vec::new(),
            descriptions: Vec::new(),
            prototypes: p.prototypes,
            delta: p.delta,
            base_graph: p.base_graph,
            threshold: p.threshold,
            coefficient: p.coefficient,
            temperature: p.temperature,
            paths: p.paths,
            initial: None,
            walk: None,
            decay: 0.0,
            questions: Vec::new(),
        }
    }
}

/// The most policies a lesson may have: a lesson is stepped by hand and drawn on one screen,
/// and the bound is checked before the graph is allocated (100 million policies once took
/// 7 GB and ran on without a word).
pub const MAX_LESSON_POLICIES: usize = 1000;

/// A teach file made ready: the SAP-Net and what to call its policies.
#[derive(Debug, Clone, PartialEq)]
pub struct Lesson {
    pub names: Vec<String>,
    pub net: SapNet,
    /// Each policy's category under the first prototype, where the lesson gives
    /// `descriptions`: the screen draws a category's policies together.
    pub groups: Option<Vec<usize>>,
    /// The saved walk's position, checked against the walk it names.
    pub walk: Option<WalkPosition>,
    /// D between activations (0: the paper).
    pub decay: f64,
    pub questions: Vec<Question>,
}

impl TeachConfig {
    /// Reads a teach file, or the embedded Fig. 2 without one.
    pub fn load(path: Option<&Path>) -> Result<Lesson, ConfigError> {
        match path {
            Some(path) => {
                let text = crate::ron_file::read_text(path)?;
                Self::lesson_from_ron(&text, &path.display().to_string())
            }
            None => Self::lesson_from_ron(FIG2, "teach_fig2.ron (embedded)"),
        }
    }

    /// Reads a teach file, or the embedded Fig. 2 without one, unbuilt (to be edited
    /// first), with what names it in errors.
    pub fn read(path: Option<&Path>) -> Result<(Self, String), ConfigError> {
        match path {
            Some(path) => {
                let origin = path.display().to_string();
                let text = crate::ron_file::read_text(path)?;
                Ok((Self::from_ron(&text, &origin)?, origin))
            }
            None => {
                let origin = "the embedded Fig. 2".to_string();
                Ok((Self::from_ron(FIG2, &origin)?, origin))
            }
        }
    }

    /// Reads and builds a teach file from RON text; `origin` names it in errors.
    pub fn lesson_from_ron(text: &str, origin: &str) -> Result<Lesson, ConfigError> {
        Self::from_ron(text, origin)?
            .lesson()
            .map_err(|message| ConfigError::Invalid {
                origin: origin.to_string(),
                message,
            })
    }

    /// Reads a teach file from RON text, unbuilt.
    fn from_ron(text: &str, origin: &str) -> Result<Self, ConfigError> {
        parse_ron(text, origin).map_err(|e| {
            // A training config given where a lesson is expected: say what teach reads.
            if crate::config::Config::from_ron(text, origin).is_ok() {
                ConfigError::Invalid {
                    origin: origin.to_string(),
                    message: "this is a training config; `sapnet teach --config` reads a \
                              lesson (a graph and SAP-Net's parameters, e.g. \
                              assets/teach_fig2.ron, assets/teach_table2.ron); `t` on the \
                              dashboard teaches on a training config's live graph"
                        .to_string(),
                }
            } else {
                e
            }
        })
    }

    /// The SAP-Net parameters this file sets.
    pub fn params(&self) -> SapNetParams {
        SapNetParams {
            prototypes: self.prototypes.clone(),
            delta: self.delta,
            threshold: self.threshold,
            coefficient: self.coefficient,
            temperature: self.temperature,
            base_graph: self.base_graph,
            paths: self.paths,
        }
    }

    /// Checks the file and builds its SAP-Net. The message names the field at fault.
    pub fn lesson(&self) -> Result<Lesson, String> {
        let n = self.count()?;
        let params = self.params();
        params
            .validate()
            .map_err(|e| sapnet_field(&e, "").unwrap_or_else(|| e.to_string()))?;
        let graph = if self.descriptions.is_empty() {
            self.no_category_fields()?;
            Graph::from_edges(n, self.edges.iter().copied()).map_err(in_field("edges"))?
        } else if !self.edges.is_empty() {
            return Err("give the graph by `edges` or by `descriptions`, not both".into());
        } else {
            Graph::from_categories(&self.descriptions, &params).map_err(in_field("descriptions"))?
        };
        let initial = self.initial.clone().unwrap_or_else(|| vec![0.0; n]);
        let net = SapNet::with_activations(graph, params, initial).map_err(|e| match e {
            SapNetError::UnboundedSpreading { .. } => {
                format!("fields `edges` and `threshold`: {e}")
            }
            SapNetError::ActivationOverflow { .. } => in_field("coefficient")(e),
            SapNetError::BadParameter { .. } => sapnet_field(&e, "").unwrap_or_default(),
            other => in_field("initial")(other),
        })?;
        let names = if self.names.is_empty() {
            (0..n).map(|i| format!("π{i}")).collect()
        } else {
            self.names.clone()
        };
        let groups = (!self.descriptions.is_empty()).then(|| {
            let prototype = self
                .prototypes
                .first()
                .map_or(Prototype::HiddenLayers, |p| p.prototype.clone());
            prototype.group_indices(&self.descriptions)
        });
        check_decay(self.decay).map_err(|e| format!("field `decay`: {e}"))?;
        questions::validate(&self.questions, n)?;
        if let Some(walk) = self.walk {
            check_walk(&net, walk)?;
        }
        Ok(Lesson {
            names,
            net,
            groups,
            walk: self.walk,
            decay: self.decay,
            questions: self.questions.clone(),
        })
    }

    /// With the graph given by its `edges`, the fields that build M from categories would
    /// be silently ignored: a file that sets them is refused instead.
    fn no_category_fields(&self) -> Result<(), String> {
        let defaults = Self::default();
        let set = [
            ("prototypes", self.prototypes != defaults.prototypes),
            ("delta", self.delta != defaults.delta),
            ("base_graph", self.base_graph != defaults.base_graph),
        ];
        match set.iter().find(|(_, differs)| *differs) {
            Some((field, _)) => Err(format!(
                "field `{field}` builds M from categories (eq. 3-5) and needs `descriptions`; \
                 with `edges` the weights are given directly, so leave `{field}` out"
            )),
            None => Ok(()),
        }
    }

    /// N, from whichever of `policies`, `names` and `descriptions` are given; they must agree.
    pub(super) fn count(&self) -> Result<usize, String> {
        let given = [
            ("policies", self.policies),
            ("names", self.names.len()),
            ("descriptions", self.descriptions.len()),
        ];
        let mut n = None;
        for (field, count) in given.into_iter().filter(|&(_, c)| c > 0) {
            match n {
                None => n = Some((field, count)),
                Some((first, m)) if m != count => {
                    return Err(format!(
                        "field `{field}` gives {count} policies but `{first}` gives {m}"
                    ))
                }
                Some(_) => {}
            }
        }
        match n {
            None => Err("no policies: give `policies`, `names` or `descriptions`".into()),
            Some((field, count)) if count > MAX_LESSON_POLICIES => Err(format!(
                "field `{field}` gives {count} policies: a lesson has at most \
                 {MAX_LESSON_POLICIES} (it is stepped by hand and drawn on one screen)"
            )),
            Some((_, count)) => Ok(count),
        }
    }
}

/// D must leave some of every activation and take none away twice: 0 ≤ D ≤ 1.
pub fn check_decay(decay: f64) -> Result<(), String> {
    if (0.0..=1.0).contains(&decay) {
        Ok(())
    } else {
        Err(format!(
            "expected a number from 0 to 1 (the share of every activation lost between two \
             activations; 0 is the paper), got {decay}"
        ))
    }
}

/// A saved walk names a policy of the lesson and no more calls than its walk makes.
fn check_walk(net: &SapNet, walk: WalkPosition) -> Result<(), String> {
    let n = net.len();
    if walk.activate >= n {
        return Err(format!(
            "field `walk`: expected `activate` to name a policy, 0 to {}, got {}",
            n.saturating_sub(1),
            walk.activate
        ));
    }
    let mut calls = crate::sapnet::CallCount::default();
    net.clone().activate_traced(walk.activate, true, &mut calls);
    if walk.calls > calls.0 {
        return Err(format!(
            "field `walk`: expected at most {} calls (the walk from policy {} makes {}), got {}",
            calls.0, walk.activate, calls.0, walk.calls
        ));
    }
    Ok(())
}

fn in_field(field: &'static str) -> impl Fn(SapNetError) -> String {
    move |e| format!("field `{field}`: {e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lesson(text: &str) -> Result<Lesson, String> {
        TeachConfig::lesson_from_ron(text, "test.ron").map_err(|e| e.to_string())
    }

    #[test]
    fn a_lesson_of_descriptions_groups_its_policies_by_category() {
        let table2 = lesson(include_str!("../../assets/teach_table2.ron")).unwrap();
        assert_eq!(table2.groups, Some(vec![0, 0, 0, 1, 1, 1, 1, 2, 2, 2]));
        // Edges given by hand have no categories to group by.
        assert_eq!(lesson(FIG2).unwrap().groups, None);
    }

    #[test]
    fn the_embedded_fig2_is_eq4_with_weights_0_4() {
        let l = TeachConfig::load(None).unwrap();
        assert_eq!(l.names, ["π0", "π1", "π2", "π3"]);
        let edges: Vec<_> = l.net.graph().edges().collect();
        assert_eq!(edges, [(0, 1, 0.4), (0, 2, 0.4), (1, 2, 0.4), (1, 3, 0.4)]);
        assert_eq!(l.net.params().threshold, 1.0);
        assert_eq!(l.net.activations(), [0.0; 4]);
    }

    #[test]
    fn the_table2_asset_has_three_hidden_layer_categories_at_0_95() {
        let text = include_str!("../../assets/teach_table2.ron");
        let l = lesson(text).unwrap();
        assert_eq!(l.net.len(), 10);
        assert!(l.net.graph().edges().all(|(_, _, w)| w == 0.95));
        // Categories of 3, 4 and 3 policies are cliques: 3 + 6 + 3 edges.
        assert_eq!(l.net.graph().edges().count(), 12);
    }

    #[test]
    fn a_bad_edge_is_named_with_its_file_and_field() {
        let e = lesson("(policies: 3, edges: [(0, 1, 0.4), (1, 2, -0.1)])").unwrap_err();
        assert!(e.contains("test.ron"), "{e}");
        assert!(e.contains("field `edges`: edge (1, 2) weighs -0.1"), "{e}");
        let e = lesson("(policies: 3, edges: [(0, 3, 0.4)])").unwrap_err();
        assert!(e.contains("edge (0, 3)"), "{e}");
    }

    #[test]
    fn a_typo_is_located() {
        let e = lesson("(policies: 3,\n edgs: [])").unwrap_err();
        assert!(e.contains("line 2"), "{e}");
        assert!(e.contains("edgs"), "{e}");
    }

    #[test]
    fn category_fields_beside_edges_are_refused_not_ignored() {
        let err = lesson("(policies: 2, edges: [(0, 1, 0.4)], delta: -0.2)").unwrap_err();
        assert!(err.contains("test.ron"), "{err}");
        assert!(err.contains("field `delta`"), "{err}");
        assert!(err.contains("needs `descriptions`"), "{err}");
        // Their defaults are no setting: Fig. 2 itself leaves them out.
        assert!(lesson("(policies: 2, edges: [(0, 1, 0.4)])").is_ok());
    }

    #[test]
    fn counts_must_agree() {
        let e = lesson(r#"(policies: 3, names: ["a", "b"])"#).unwrap_err();
        assert!(
            e.contains("`names` gives 2 policies but `policies` gives 3"),
            "{e}"
        );
        let e = lesson("(policies: 100000000)").unwrap_err();
        assert!(
            e.contains("field `policies` gives 100000000 policies: a lesson has at most 1000"),
            "{e}"
        );
        assert!(lesson("(policies: 1000)").is_ok());
        let e = lesson("(policies: 2, initial: Some([1.0]))").unwrap_err();
        assert!(e.contains("field `initial`"), "{e}");
        let e = lesson("(threshold: 1.0)").unwrap_err();
        assert!(e.contains("no policies"), "{e}");
    }

    #[test]
    fn a_saved_walk_decay_and_questions_are_checked_by_field() {
        let ok = lesson(
            "(policies: 4, edges: [(0, 1, 0.4), (1, 3, 0.4)], walk: Some(activate: 1, \
             calls: 2), decay: 0.5, questions: [(ask: \"Which?\", answer: Policy(3))])",
        )
        .unwrap();
        assert_eq!(
            ok.walk,
            Some(WalkPosition {
                activate: 1,
                calls: 2
            })
        );
        assert_eq!(ok.decay, 0.5);
        let cases = [
            (
                "walk: Some(activate: 4, calls: 0)",
                "field `walk`: expected `activate`",
            ),
            // From π1: to π0 and π3 (Ω = 0.4), each back to π1 (Ω = 0.8), which calls its
            // two neighbours at Ω = 1.2 (stopped): 2 × (1 + 1 + 2) = 8 calls.
            (
                "walk: Some(activate: 1, calls: 9)",
                "expected at most 8 calls",
            ),
            ("decay: 1.5", "field `decay`: expected a number from 0 to 1"),
            (
                "questions: [(ask: \"Which?\", answer: Policy(4))]",
                "field `questions[0].answer`",
            ),
        ];
        for (field, says) in cases {
            let text = format!("(policies: 4, edges: [(0, 1, 0.4), (1, 3, 0.4)], {field})");
            let e = lesson(&text).unwrap_err();
            assert!(e.starts_with("config test.ron: "), "{e}");
            assert!(e.contains(says), "{field}: {e}");
        }
    }

    #[test]
    fn a_bad_threshold_names_the_parameter() {
        let e = lesson("(policies: 2, threshold: 0.0)").unwrap_err();
        assert_eq!(
            e,
            "config test.ron: field `threshold`: expected a finite number > 0, got 0.0"
        );
    }
}
