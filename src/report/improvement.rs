//! `improvement.csv`: the probability of improvement of every method over every other,
//! `P(X > Y)` with its 95% interval ([`crate::stats::improvement`]), for the greedy test
//! score and for the training return. A row `score, method, over, p, lo, hi` reads "a run
//! of `method` scores above a run of `over` with probability p"; an interval that holds
//! 0.5 means these runs cannot tell which is better.

use serde::Serialize;

use super::MethodRuns;
use crate::seeds::{self, Part};
use crate::stats::{improvement, Estimate};

/// One ordered pair's probability of improvement.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Improvement {
    /// `test` (the greedy test score) or `return` (the training return).
    pub score: &'static str,
    pub method: String,
    pub over: String,
    pub p: Estimate,
}

/// `P(X > Y)` for every ordered pair of methods with scores, test scores first.
pub(super) fn every_pair(methods: &[MethodRuns]) -> Vec<Improvement> {
    let mut rows = Vec::new();
    for score in ["test", "return"] {
        fn scores<'a>(m: &'a MethodRuns, score: &str) -> Option<&'a crate::stats::Scores> {
            match score {
                "test" => m.test.as_ref().map(|(raw, _)| raw),
                _ => m.training.as_ref().map(|(raw, _)| raw),
            }
        }
        for x in methods {
            for y in methods {
                let (Some(xs), Some(ys)) = (scores(x, score), scores(y, score)) else {
                    continue;
                };
                if x.label == y.label {
                    continue;
                }
                let seed = seeds::derive(
                    0,
                    &[
                        Part::Name("improvement"),
                        Part::Name(score),
                        Part::Name(&x.label),
                        Part::Name(&y.label),
                    ],
                );
                rows.push(Improvement {
                    score,
                    method: x.label.clone(),
                    over: y.label.clone(),
                    p: improvement::interval(xs, ys, seed),
                });
            }
        }
    }
    rows
}

/// The header and rows of `improvement.csv`.
pub fn records(rows: &[Improvement]) -> (Vec<String>, Vec<Vec<String>>) {
    let header = ["score", "method", "over", "p", "lo", "hi"]
        .map(String::from)
        .to_vec();
    let records = rows
        .iter()
        .map(|row| {
            vec![
                row.score.to_string(),
                row.method.clone(),
                row.over.clone(),
                format!("{:?}", row.p.point),
                format!("{:?}", row.p.lo),
                format!("{:?}", row.p.hi),
            ]
        })
        .collect();
    (header, records)
}
