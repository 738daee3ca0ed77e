//! `improvement.csv`: the probability of improvement of every method over every other,
//! `P(X > Y)` with its 95% interval ([`crate::stats::improvement`]), for the greedy test
//! score and for the training return. A row `score, method, over, p, lo, hi` reads "a run
//! of `method` scores above a run of `over` with probability p"; the rest of the row is
//! what the separation rule ([`crate::stats::separation`]) says of the pair: the rank
//! test's p-value and its Holm adjustment over the table, how many bootstrap seeds'
//! intervals exclude ½, the verdict (`separated`, `fragile`, `not separated`), the runs
//! per method that would detect the difference where it is not separated, and, pooled
//! over tasks, each task's verdict.

use serde::Serialize;

use super::MethodRuns;
use crate::seeds::{self, Part};
use crate::stats::separation::{self, Verdict, BOOTSTRAP_SEEDS};
use crate::stats::{improvement, multiplicity, power, rank_test, Estimate, Scores};

/// One ordered pair's probability of improvement, and what the separation rule
/// ([`separation`]) says of the pair.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Improvement {
    /// `test` (the greedy test score) or `return` (the training return).
    pub score: &'static str,
    pub method: String,
    pub over: String,
    pub p: Estimate,
    /// The two-sided rank test's p-value (Mann–Whitney on one task, van Elteren over
    /// several), and Holm's adjustment of it over every pair of this score's table.
    pub rank_p: f64,
    pub holm_p: f64,
    /// Of the [`BOOTSTRAP_SEEDS`] intervals of `P(X > Y)`, how many exclude ½.
    pub seeds_excluding: usize,
    pub verdict: Verdict,
    /// Where the pair is not separated (or fragile), on one task: the runs per method at
    /// which the
    /// rank test would detect the `P(X > Y)` these runs show, at 80% power and at the level
    /// Holm's adjustment tests the table's first pair (0.05 over the pairs); `None` where
    /// that is no more runs than these (no plan the rule could pass).
    pub runs_needed: Option<usize>,
    /// Pooled over several tasks: the verdict on each task alone, in the report's order
    /// (each task's table its own Holm family).
    pub per_task: Vec<Verdict>,
}

impl Improvement {
    /// The pair's two methods, the better first: the one with `P(X > Y)` ≥ ½ (`method`
    /// on a tie).
    pub fn better_first(&self) -> (&str, &str) {
        if self.p.point >= 0.5 {
            (&self.method, &self.over)
        } else {
            (&self.over, &self.method)
        }
    }

    /// The verdict with its direction in words, the better method first, whichever way
    /// the row reads: `a2t over sapnet, separated` on `sapnet`'s row over `a2t` as on
    /// `a2t`'s over `sapnet`. A pair not separated has no direction: `not separated`.
    pub fn judgement(&self) -> String {
        match self.verdict {
            Verdict::NotSeparated => self.verdict.name().to_string(),
            verdict => {
                let (better, worse) = self.better_first();
                format!("{better} over {worse}, {}", verdict.name())
            }
        }
    }
}

/// What the rule found for one unordered pair `(i, j)`, `i < j`, of one score's methods.
struct Judged {
    /// `P(X_i > X_j)` under each bootstrap seed, the row's own seed first.
    intervals: Vec<Estimate>,
    rank_p: f64,
    holm_p: f64,
}

impl Judged {
    fn verdict(&self) -> Verdict {
        Verdict::of(&self.intervals, self.holm_p)
    }
}

/// `P(X > Y)` for every ordered pair of methods with scores, test scores first, each
/// judged by the separation rule. `tasks` names the tasks the scores are on, in order.
pub(super) fn every_pair(methods: &[MethodRuns], tasks: &[String]) -> Vec<Improvement> {
    let mut rows = Vec::new();
    for score in ["test", "return"] {
        let present: Vec<(&str, &Scores)> = methods
            .iter()
            .filter_map(|m| Some((m.label.as_str(), scores(m, score)?)))
            .collect();
        let judged = judge(score, &present, None);
        let per_task: Vec<Vec<Judged>> = if tasks.len() > 1 {
            tasks
                .iter()
                .enumerate()
                .map(|(t, task)| {
                    let alone: Vec<(&str, Scores)> = present
                        .iter()
                        .map(|(label, s)| {
                            let runs = s.tasks()[t].clone();
                            (*label, Scores::one_task(runs).expect("a task has runs"))
                        })
                        .collect();
                    let alone: Vec<(&str, &Scores)> = alone.iter().map(|(l, s)| (*l, s)).collect();
                    judge(score, &alone, Some(task))
                })
                .collect()
        } else {
            Vec::new()
        };
        let n = present.len();
        // The level Holm's adjustment tests the table's first pair at: a plan of runs that
        // the rule can pass is made there.
        let pairs = (n * n.saturating_sub(1) / 2).max(1);
        let level = power::ALPHA / pairs as f64;
        for i in 0..n {
            for j in 0..n {
                if i == j {
                    continue;
                }
                let (a, b) = (i.min(j), i.max(j));
                let at = pair_index(n, a, b);
                let pair = &judged[at];
                let p = if i < j {
                    pair.intervals[0]
                } else {
                    separation::reversed(pair.intervals[0])
                };
                let verdict = pair.verdict();
                rows.push(Improvement {
                    score,
                    method: present[i].0.to_string(),
                    over: present[j].0.to_string(),
                    p,
                    rank_p: pair.rank_p,
                    holm_p: pair.holm_p,
                    seeds_excluding: separation::excluding_half(&pair.intervals),
                    verdict,
                    runs_needed: (tasks.len() == 1 && verdict != Verdict::Separated)
                        .then(|| power::runs_per_method_at(p.point, level))
                        .flatten()
                        // A plan: more runs than these, which the rule did not separate.
                        .filter(|&needed| needed > present[i].1.runs().min(present[j].1.runs())),
                    per_task: per_task.iter().map(|t| t[at].verdict()).collect(),
                });
            }
        }
    }
    rows
}

fn scores<'a>(m: &'a MethodRuns, score: &str) -> Option<&'a Scores> {
    match score {
        "test" => m.test.as_ref().map(|(raw, _)| raw),
        _ => m.training.as_ref().map(|(raw, _)| raw),
    }
}

/// The position of the unordered pair `(a, b)`, `a < b`, in [`judge`]'s list.
fn pair_index(n: usize, a: usize, b: usize) -> usize {
    a * n - a * (a + 1) / 2 + (b - a - 1)
}

/// Every unordered pair of `methods` (in order: (0, 1), (0, 2), …, (1, 2), …) judged on
/// one score: its intervals under every bootstrap seed, its rank test, and Holm's
/// adjustment over all of them. `task` names the one task judged alone from a pooled
/// report (its seeds its own).
fn judge(score: &str, methods: &[(&str, &Scores)], task: Option<&str>) -> Vec<Judged> {
    let mut judged = Vec::new();
    for (a, (x_label, xs)) in methods.iter().enumerate() {
        for (y_label, ys) in &methods[a + 1..] {
            let intervals = (0..BOOTSTRAP_SEEDS)
                .map(|k| {
                    let mut parts = vec![
                        Part::Name("improvement"),
                        Part::Name(score),
                        Part::Name(x_label),
                        Part::Name(y_label),
                    ];
                    if let Some(task) = task {
                        parts.push(Part::Name(task));
                    }
                    // The first seed is the one the row's interval has always had.
                    if k > 0 {
                        parts.push(Part::Index(k as u64));
                    }
                    improvement::interval(xs, ys, seeds::derive(0, &parts))
                })
                .collect();
            judged.push(Judged {
                intervals,
                rank_p: rank_test::p_value(xs, ys),
                holm_p: f64::NAN,
            });
        }
    }
    let raw: Vec<f64> = judged.iter().map(|j| j.rank_p).collect();
    for (j, adjusted) in judged.iter_mut().zip(multiplicity::holm(&raw)) {
        j.holm_p = adjusted;
    }
    judged
}

/// The header and rows of `improvement.csv`. `tasks` names the columns of `per_task`
/// (`cartpole=separated;acrobot=fragile`), empty on one task.
pub fn records(rows: &[Improvement], tasks: &[String]) -> (Vec<String>, Vec<Vec<String>>) {
    let header = [
        "score",
        "method",
        "over",
        "p",
        "lo",
        "hi",
        "rank_p",
        "holm_p",
        "seeds_excluding",
        "verdict",
        "runs_needed",
        "per_task",
    ]
    .map(String::from)
    .to_vec();
    let records = rows
        .iter()
        .map(|row| {
            let per_task: Vec<String> = tasks
                .iter()
                .zip(&row.per_task)
                .map(|(task, v)| format!("{task}={}", v.name()))
                .collect();
            vec![
                row.score.to_string(),
                row.method.clone(),
                row.over.clone(),
                format!("{:?}", row.p.point),
                format!("{:?}", row.p.lo),
                format!("{:?}", row.p.hi),
                format!("{:?}", row.rank_p),
                format!("{:?}", row.holm_p),
                format!("{}/{BOOTSTRAP_SEEDS}", row.seeds_excluding),
                row.verdict.name().to_string(),
                row.runs_needed.map_or(String::new(), |n| n.to_string()),
                per_task.join(";"),
            ]
        })
        .collect();
    (header, records)
}

/// The pairs of one score as the separation rule says them, for stdout: each separated
/// or fragile pair once, the better method first, then the pairs not separated with the
/// runs per method that would detect what these runs show.
pub fn verdicts(rows: &[Improvement], score: &str) -> String {
    let mut separated = Vec::new();
    let mut fragile = Vec::new();
    let mut apart = Vec::new();
    // Each pair has two rows; the one with P(X > Y) ≥ ½ says it (X first on a tie).
    for row in rows.iter().filter(|r| r.score == score) {
        let says_it = row.p.point > 0.5 || (row.p.point == 0.5 && row.method < row.over);
        if !says_it {
            continue;
        }
        let line = format!(
            "{} over {}: P = {:.2} [{:.2}, {:.2}], Holm p = {}, {}/{BOOTSTRAP_SEEDS} seeds",
            row.method,
            row.over,
            row.p.point,
            row.p.lo,
            row.p.hi,
            p_value(row.holm_p),
            row.seeds_excluding
        );
        match row.verdict {
            Verdict::Separated => separated.push(line),
            Verdict::Fragile => fragile.push(line),
            Verdict::NotSeparated => apart.push(match row.runs_needed {
                Some(n) => format!("{} ~ {} ({n} runs each to detect)", row.method, row.over),
                None => format!("{} ~ {} (no difference seen)", row.method, row.over),
            }),
        }
    }
    if separated.is_empty() && fragile.is_empty() && apart.is_empty() {
        return String::new();
    }
    let mut out = format!(
        "{}: pairs by the separation rule (the 95% interval of P(X > Y) excludes ½ under \
         each of {BOOTSTRAP_SEEDS} bootstrap seeds, and the rank test's Holm-adjusted p < 0.05)\n",
        match score {
            "test" => "test score",
            _ => "training return",
        }
    );
    for (name, lines) in [("separated", &separated), ("fragile", &fragile)] {
        for line in lines.iter() {
            out.push_str(&format!("  {name:<14} {line}\n"));
        }
    }
    if !apart.is_empty() {
        out.push_str(&format!("  not separated  {}\n", apart.join(", ")));
    }
    out
}

/// A p-value as a reader scans it: three decimals, or its order when smaller.
pub fn p_value(p: f64) -> String {
    if p >= 0.001 {
        format!("{p:.3}")
    } else {
        format!("{p:.0e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reuse::Method;

    fn method(label: &str, training: Vec<Vec<f64>>) -> MethodRuns {
        let scores = Scores::per_task(training).unwrap();
        MethodRuns {
            label: label.to_string(),
            kind: Method::Ucb1.kind(),
            runs: scores.runs(),
            test: None,
            training: Some((scores.clone(), scores)),
            final_return: None,
            unit: "episode",
            reached: Vec::new(),
            steps: Vec::new(),
            updates: Vec::new(),
            non_greedy: Vec::new(),
            source_shares: Vec::new(),
            task_shares: Vec::new(),
            ranks: Vec::new(),
            lock_in_steps: Vec::new(),
        }
    }

    fn row<'a>(rows: &'a [Improvement], x: &str, y: &str) -> &'a Improvement {
        rows.iter()
            .find(|r| r.method == x && r.over == y)
            .expect("the pair's row")
    }

    #[test]
    fn twenty_runs_apart_are_separated_and_two_alike_are_not() {
        let high: Vec<f64> = (0..20).map(|i| 100.0 + f64::from(i)).collect();
        let low: Vec<f64> = (0..20).map(|i| 10.0 + f64::from(i)).collect();
        let also_low: Vec<f64> = (0..20).map(|i| 10.5 + f64::from(i)).collect();
        let methods = [
            method("a", vec![high]),
            method("b", vec![low]),
            method("c", vec![also_low]),
        ];
        let rows = every_pair(&methods, &["cartpole".into()]);
        assert_eq!(rows.len(), 6, "every ordered pair of the training return");
        let ab = row(&rows, "a", "b");
        assert_eq!((ab.p.point, ab.verdict), (1.0, Verdict::Separated));
        assert_eq!(ab.seeds_excluding, BOOTSTRAP_SEEDS);
        assert_eq!(ab.runs_needed, None, "nothing to power where separated");
        // The reverse row is the same pair: its interval mirrored, its verdict the same.
        let ba = row(&rows, "b", "a");
        assert_eq!(
            (ba.p.point, ba.p.lo, ba.p.hi),
            (0.0, 1.0 - ab.p.hi, 1.0 - ab.p.lo)
        );
        assert_eq!((ba.verdict, ba.holm_p), (ab.verdict, ab.holm_p));
        // b and c interleave: P(c > b) = 0.5 + 20/800, a hair above a coin toss.
        let cb = row(&rows, "c", "b");
        assert_eq!(cb.verdict, Verdict::NotSeparated);
        assert!(cb.runs_needed.unwrap() > 1000, "{:?}", cb.runs_needed);
        assert!(cb.per_task.is_empty(), "one task has no per-task column");
    }

    /// Eleven methods of six runs each, every method's runs above every run of the next:
    /// every P is 0 or 1, yet no pair can pass Holm over 55 pairs at six runs (the smallest
    /// exact p, 2/C(12, 6) = 0.0022, times 55 is above 0.05). The plan each pair is told is
    /// made at Holm's first level, 0.05/55: 12 runs a method, never the 6 it already has.
    #[test]
    fn runs_needed_is_a_plan_the_rule_could_pass() {
        let methods: Vec<MethodRuns> = (0..11)
            .map(|k| {
                let runs: Vec<f64> = (0..6).map(|i| f64::from(k * 10 + i)).collect();
                method(&format!("m{k:02}"), vec![runs])
            })
            .collect();
        let rows = every_pair(&methods, &["cartpole".into()]);
        assert_eq!(rows.len(), 2 * 55);
        for row in &rows {
            assert_ne!(
                row.verdict,
                Verdict::Separated,
                "{} over {}",
                row.method,
                row.over
            );
            assert_eq!(
                row.runs_needed,
                Some(12),
                "{} over {}",
                row.method,
                row.over
            );
        }
    }

    #[test]
    fn holm_adjusts_over_the_pairs_of_the_table() {
        let runs =
            |shift: f64| -> Vec<Vec<f64>> { vec![(0..12).map(|i| shift + f64::from(i)).collect()] };
        let methods = [
            method("a", runs(0.0)),
            method("b", runs(4.0)),
            method("c", runs(30.0)),
        ];
        let rows = every_pair(&methods, &["acrobot".into()]);
        let pairs = [("a", "b"), ("a", "c"), ("b", "c")];
        let raw: Vec<f64> = pairs.iter().map(|(x, y)| row(&rows, x, y).rank_p).collect();
        let adjusted = multiplicity::holm(&raw);
        for ((x, y), holm) in pairs.iter().zip(adjusted) {
            assert_eq!(row(&rows, x, y).holm_p, holm, "{x} over {y}");
            assert!(row(&rows, x, y).holm_p >= row(&rows, x, y).rank_p);
        }
    }

    #[test]
    fn a_pooled_pair_carries_each_tasks_verdict() {
        // Apart on the first task, alike on the second.
        let a = method(
            "a",
            vec![
                (0..15).map(|i| 100.0 + f64::from(i)).collect(),
                vec![1.0, 2.0, 3.0, 4.0],
            ],
        );
        let b = method(
            "b",
            vec![(0..15).map(f64::from).collect(), vec![1.5, 2.5, 3.5, 0.5]],
        );
        let tasks = ["cartpole".to_string(), "acrobot".to_string()];
        let rows = every_pair(&[a, b], &tasks);
        let ab = row(&rows, "a", "b");
        assert_eq!(ab.per_task, vec![Verdict::Separated, Verdict::NotSeparated]);
        assert_eq!(ab.runs_needed, None, "no power count over pooled tasks");
        let (header, records) = records(&rows, &tasks);
        let at = header.iter().position(|h| h == "per_task").unwrap();
        let line = &records[rows.iter().position(|r| r == ab).unwrap()];
        assert_eq!(line[at], "cartpole=separated;acrobot=not separated");
    }

    #[test]
    fn a_verdict_says_the_better_method_first_on_either_row() {
        let methods = [
            method("sapnet", vec![(0..20).map(f64::from).collect()]),
            method("a2t", vec![(0..20).map(|i| 50.0 + f64::from(i)).collect()]),
            method(
                "a2t-too",
                vec![(0..20).map(|i| 50.5 + f64::from(i)).collect()],
            ),
        ];
        let rows = every_pair(&methods, &["cartpole".into()]);
        let ab = row(&rows, "sapnet", "a2t");
        assert_eq!(ab.judgement(), "a2t over sapnet, separated");
        assert_eq!(row(&rows, "a2t", "sapnet").judgement(), ab.judgement());
        assert_eq!(ab.better_first(), ("a2t", "sapnet"));
        assert_eq!(row(&rows, "a2t", "a2t-too").judgement(), "not separated");
    }

    #[test]
    fn the_closing_lines_say_each_pair_once_better_first() {
        let methods = [
            method("low", vec![(0..20).map(f64::from).collect()]),
            method("high", vec![(0..20).map(|i| 50.0 + f64::from(i)).collect()]),
        ];
        let text = verdicts(&every_pair(&methods, &["cartpole".into()]), "return");
        assert!(
            text.contains("  separated      high over low: P = 1.00 [1.00, 1.00]"),
            "{text}"
        );
        assert!(!text.contains("low over high"), "{text}");
        assert_eq!(verdicts(&[], "return"), "");
    }
}
