//! The SAP-Net graph 𝔾 = (Π, E, ω) (eq. 2) and its weight matrix M (eq. 3–5).
//!
//! M is stored as neighbour lists in index order, since spreading only ever asks "who are
//! the neighbours of j, and how far away": eq. 3's zeros are simply absent. A weight is a
//! *distance*: the smaller, the further activation spreads.

use super::error::SapNetError;
use super::params::{BaseGraph, SapNetParams};
use super::policy::PolicyDescription;
use super::prototype::prototype_matrix;

/// An undirected graph of N policies with positive, finite edge weights.
#[derive(Debug, Clone, PartialEq)]
pub struct Graph {
    /// Neighbours of policy i are `targets[offsets[i]..offsets[i + 1]]`, ascending.
    offsets: Vec<usize>,
    targets: Vec<usize>,
    weights: Vec<f64>,
    /// The lightest edge at each policy (∞ when it has none): a walk that arrives with
    /// Ω + lightest ≥ T_ω cannot go on, which lets spreading skip a whole neighbour list.
    lightest: Vec<f64>,
}

impl Graph {
    /// A graph of `n` policies from an undirected edge list `(i, j, M_ij)`.
    ///
    /// Every weight must be finite and > 0: with a weight ≤ 0 the path weight Ω of eq. 10
    /// need never reach T_ω and spreading would not end.
    pub fn from_edges(
        n: usize,
        edges: impl IntoIterator<Item = (usize, usize, f64)>,
    ) -> Result<Self, SapNetError> {
        let mut adjacency: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for (i, j, weight) in edges {
            if i >= n || j >= n {
                return Err(SapNetError::EdgeOutOfRange { i, j, n });
            }
            if i == j {
                return Err(SapNetError::SelfLoop { i });
            }
            if !(weight > 0.0 && weight.is_finite()) {
                return Err(SapNetError::BadWeight { i, j, weight });
            }
            if adjacency[i].iter().any(|&(l, _)| l == j) {
                return Err(SapNetError::DuplicateEdge { i, j });
            }
            adjacency[i].push((j, weight));
            adjacency[j].push((i, weight));
        }

        let mut graph = Graph {
            offsets: Vec::with_capacity(n + 1),
            targets: Vec::new(),
            weights: Vec::new(),
            lightest: Vec::with_capacity(n),
        };
        graph.offsets.push(0);
        for mut neighbours in adjacency {
            neighbours.sort_unstable_by_key(|&(l, _)| l);
            graph.lightest.push(
                neighbours
                    .iter()
                    .map(|&(_, w)| w)
                    .fold(f64::INFINITY, f64::min),
            );
            graph.targets.extend(neighbours.iter().map(|&(l, _)| l));
            graph.weights.extend(neighbours.iter().map(|&(_, w)| w));
            graph.offsets.push(graph.targets.len());
        }
        Ok(graph)
    }

    /// The SAP-Net of a policy library, built from its categories.
    ///
    /// Eq. 3: policies are joined with weight 1 when they share a category under at least
    /// one prototype (`BaseGraph::SharedCategory`) or always (`BaseGraph::Complete`).
    /// Eq. 5: then `M = M + δ(P_1 + … + P_n)`, the prototype matrices P_c adding ω_c
    /// for each prototype a pair shares. With Table II (δ = −0.5, ω_c = 0.1) a pair in the
    /// same category ends at 1 − 0.5·0.1 = 0.95.
    pub fn from_categories(
        policies: &[PolicyDescription],
        params: &SapNetParams,
    ) -> Result<Self, SapNetError> {
        params.validate()?;
        let n = policies.len();
        let mut related = vec![0.0; n * n];
        for weighted in &params.prototypes {
            let p = prototype_matrix(policies, weighted);
            related.iter_mut().zip(&p).for_each(|(r, p)| *r += p);
        }
        let shares_category = |i: usize, j: usize| {
            params
                .prototypes
                .iter()
                .any(|w| w.prototype.relates(&policies[i], &policies[j]))
        };
        let joined = |i: usize, j: usize| match params.base_graph {
            BaseGraph::Complete => true,
            BaseGraph::SharedCategory => shares_category(i, j),
        };
        let edges = (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .filter(|&(i, j)| joined(i, j))
            .map(|(i, j)| (i, j, 1.0 + params.delta * related[i * n + j]));
        Self::from_edges(n, edges)
    }

    /// N, the number of policies.
    pub fn len(&self) -> usize {
        self.lightest.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// k of eq. 9: the number of edges at policy `i`.
    pub fn degree(&self, i: usize) -> usize {
        self.offsets[i + 1] - self.offsets[i]
    }

    /// The neighbours of `i` with the weights M_ij, in ascending index order.
    pub fn neighbours(
        &self,
        i: usize,
    ) -> impl DoubleEndedIterator<Item = (usize, f64)> + ExactSizeIterator + '_ {
        let range = self.offsets[i]..self.offsets[i + 1];
        self.targets[range.clone()]
            .iter()
            .copied()
            .zip(self.weights[range].iter().copied())
    }

    /// M_ij, or `None` when i and j are not joined (eq. 3's zero).
    pub fn weight(&self, i: usize, j: usize) -> Option<f64> {
        let range = self.offsets[i]..self.offsets[i + 1];
        self.targets[range.clone()]
            .binary_search(&j)
            .ok()
            .map(|k| self.weights[range.start + k])
    }

    /// Every edge once, as `(i, j, M_ij)` with i < j.
    pub fn edges(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        (0..self.len()).flat_map(move |i| {
            self.neighbours(i)
                .filter(move |&(j, _)| i < j)
                .map(move |(j, w)| (i, j, w))
        })
    }

    /// The same graph with the edge (i, j) at `weight`, for a front end that edits M live.
    ///
    /// # Errors
    /// If i and j are not joined, or `weight` is not a finite number > 0.
    pub fn with_weight(&self, i: usize, j: usize, weight: f64) -> Result<Self, SapNetError> {
        let n = self.len();
        if i >= n || j >= n {
            return Err(SapNetError::EdgeOutOfRange { i, j, n });
        }
        if self.weight(i, j).is_none() {
            return Err(SapNetError::NoEdge { i, j });
        }
        let edges = self.edges().map(|(a, b, w)| {
            if (a, b) == (i.min(j), i.max(j)) {
                (a, b, weight)
            } else {
                (a, b, w)
            }
        });
        Self::from_edges(self.len(), edges)
    }

    /// The dense N×N matrix M of eq. 4, row-major, 0 where there is no edge.
    pub fn matrix(&self) -> Vec<f64> {
        let n = self.len();
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            for (j, w) in self.neighbours(i) {
                m[i * n + j] = w;
            }
        }
        m
    }

    /// The lightest edge weight at `i`, ∞ for an isolated policy.
    pub(crate) fn lightest(&self, i: usize) -> f64 {
        self.lightest[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fig2_as_an_adjacency_matrix_is_eq4() {
        let g = Graph::from_edges(4, [(0, 1, 0.4), (0, 2, 0.4), (1, 2, 0.4), (1, 3, 0.4)]).unwrap();
        #[rustfmt::skip]
        let eq4 = [
            0.0, 0.4, 0.4, 0.0,
            0.4, 0.0, 0.4, 0.4,
            0.4, 0.4, 0.0, 0.0,
            0.0, 0.4, 0.0, 0.0,
        ];
        assert_eq!(g.matrix(), eq4);
        assert_eq!(
            (0..4).map(|i| g.degree(i)).collect::<Vec<_>>(),
            [2, 3, 2, 1]
        );
        assert_eq!(g.weight(3, 1), Some(0.4));
        assert_eq!(g.weight(3, 0), None);
        assert_eq!(g.edges().count(), 4);
    }

    #[test]
    fn neighbours_come_in_index_order_whatever_the_edge_order() {
        let g = Graph::from_edges(4, [(0, 3, 1.0), (0, 1, 2.0), (2, 0, 3.0)]).unwrap();
        let n: Vec<_> = g.neighbours(0).collect();
        assert_eq!(n, [(1, 2.0), (2, 3.0), (3, 1.0)]);
        assert_eq!(g.lightest(0), 1.0);
        assert_eq!(g.lightest(1), 2.0);
    }

    #[test]
    fn malformed_edge_lists_are_refused_naming_the_edge() {
        assert_eq!(
            Graph::from_edges(3, [(0, 3, 1.0)]),
            Err(SapNetError::EdgeOutOfRange { i: 0, j: 3, n: 3 })
        );
        assert_eq!(
            Graph::from_edges(3, [(1, 1, 1.0)]),
            Err(SapNetError::SelfLoop { i: 1 })
        );
        assert_eq!(
            Graph::from_edges(3, [(0, 1, 1.0), (1, 0, 1.0)]),
            Err(SapNetError::DuplicateEdge { i: 1, j: 0 })
        );
    }
}
