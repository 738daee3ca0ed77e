//! Rank tests of "a run of X scores like a run of Y": the two-sided Mann–Whitney U test
//! (the Wilcoxon rank-sum test) on one task, computed as scipy ≥ 1.9 computes
//! `mannwhitneyu(x, y, alternative="two-sided", method="auto")`, and van Elteren's
//! stratified version over several tasks, which compares runs only within their task.
//!
//! U counts the pairs (x_i, y_j) with x_i > y_j, ties counted half, so U/(n·m) is the
//! `P(X > Y)` of [`super::improvement`]; these tests say how surprising that value would
//! be if both methods' runs came from one distribution.
//!
//! Scores are compared with `<` and `==`; NaN is not expected (a precondition, checked
//! in debug builds).

use serde::Serialize;

use super::{normal, Scores};

/// scipy's "auto" rule: the exact null distribution when either sample has at most this
/// many runs and no value is tied, the normal approximation otherwise
/// (`scipy.stats._mannwhitneyu._mwu_choose_method`, scipy 1.17).
const EXACT_AT_MOST: usize = 8;

/// A two-sided Mann–Whitney U test of one task's runs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MannWhitney {
    /// U of x: the pairs (x_i, y_j) with x_i > y_j, ties counted half (scipy's
    /// `statistic`). Y's U is n·m − U.
    pub u: f64,
    /// The two-sided p-value.
    pub p_value: f64,
    /// How the p-value was computed.
    pub method: Method,
}

/// How a Mann–Whitney p-value was computed, named as scipy names its methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Method {
    /// From the exact distribution of U when every ordering of the runs is equally
    /// likely.
    Exact,
    /// From the normal approximation, with the tie and continuity corrections.
    Asymptotic,
}

/// The two-sided Mann–Whitney U test of `x` against `y` (Mann and Whitney, "On a Test of
/// Whether One of Two Random Variables is Stochastically Larger than the Other", Annals of
/// Mathematical Statistics 18, 50–60, 1947), as `scipy.stats.mannwhitneyu(x, y,
/// alternative="two-sided", method="auto")` of scipy ≥ 1.9 computes it.
///
/// With midranks R over the pooled runs, `U = Σ_{x} R(x_i) − n(n+1)/2` and, for the
/// larger of the two U's, `U* = max(U, n·m − U)`:
/// - *exact* when min(n, m) ≤ 8 and no value appears twice (scipy's rule):
///   `p = 2·P(U ≥ U*)` under U's exact null distribution, counted by Mann and Whitney's
///   recurrence rather than by listing the C(n + m, n) orderings;
/// - *asymptotic* otherwise: `z = (U* − n·m/2 − ½) / σ`, with
///   `σ² = n·m/12 · ((N + 1) − Σ(t³ − t)/(N(N − 1)))` over the groups of t tied values
///   among the N = n + m runs, and `p = 2·Q(z)`.
///
/// Either p is clipped to 1 (twice a tail that holds U's centre exceeds 1). When every
/// run has the same value σ = 0 and p = 1, as in scipy.
///
/// Preconditions: both samples hold runs; no score is NaN.
pub fn mann_whitney(x: &[f64], y: &[f64]) -> MannWhitney {
    let ranked = RankedTask::of(x, y);
    let pairs = ranked.n * ranked.m;
    let larger_u = ranked.u.max(pairs as f64 - ranked.u);
    let exact = ranked.n.min(ranked.m) <= EXACT_AT_MOST && ranked.tied_cubes == 0.0;
    let (p_value, method) = if exact {
        // No ties: U is a whole number.
        let tail = exact_upper_tail(larger_u as usize, ranked.n, ranked.m);
        (2.0 * tail, Method::Exact)
    } else {
        // Subtracting ½ moves U* towards the centre: the continuity correction counts
        // the whole probability of U = U* in the tail. With all runs tied σ = 0 and
        // z = −∞, whose tail is 1.
        let z = (larger_u - ranked.null_mean() - 0.5) / ranked.null_variance().sqrt();
        (2.0 * normal::upper_tail(z), Method::Asymptotic)
    };
    MannWhitney {
        u: ranked.u,
        p_value: p_value.min(1.0),
        method,
    }
}

/// van Elteren's stratified rank-sum test over several tasks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct VanElteren {
    /// `V = Σ_t U_t/(N_t + 1)`: each task's U of x, weighted.
    pub statistic: f64,
    /// V standardised by its null mean and standard deviation: above 0 when X's runs
    /// rank above Y's.
    pub z: f64,
    /// The two-sided p-value, `2·Q(|z|)`.
    pub p_value: f64,
}

/// van Elteren's test of `x` against `y` over their tasks (P. H. van Elteren, "On the
/// combination of independent two-sample tests of Wilcoxon", Bulletin of the
/// International Statistical Institute 37, 351–361, 1960; Lehmann, *Nonparametrics:
/// Statistical Methods Based on Ranks*, 1975, pp. 132–141): runs are ranked within their
/// task only, so a task with larger scores cannot outweigh another, and the tasks' rank
/// sums are combined with van Elteren's weights `1/(N_t + 1)`, N_t = n_t + m_t, the most
/// efficient weights when X is shifted by a like amount on every task:
///
/// `V = Σ_t U_t/(N_t + 1)`, `E₀V = Σ_t (n_t·m_t/2)/(N_t + 1)`,
/// `Var₀V = Σ_t σ_t²/(N_t + 1)²` with each task's tie-corrected
/// `σ_t² = n_t·m_t/12 · ((N_t + 1) − Σ(t³ − t)/(N_t(N_t − 1)))`,
/// `z = (V − E₀V)/√Var₀V` and `p = 2·Q(|z|)`.
///
/// Always the normal approximation, with no continuity correction (V's steps differ
/// from task to task): on one task it is the Mann–Whitney test of scipy's
/// `mannwhitneyu(x, y, method="asymptotic", use_continuity=False)`. When every task's
/// runs are all tied Var₀V = 0 and there is nothing to test: z = 0, p = 1.
///
/// Preconditions: `x` and `y` have the same tasks, in the same order; no score is NaN.
pub fn van_elteren(x: &Scores, y: &Scores) -> VanElteren {
    assert_eq!(
        x.tasks().len(),
        y.tasks().len(),
        "scores on different tasks"
    );
    let (mut statistic, mut deviation, mut variance) = (0.0, 0.0, 0.0);
    for (x, y) in x.tasks().iter().zip(y.tasks()) {
        let ranked = RankedTask::of(x, y);
        let weight = 1.0 / (ranked.n + ranked.m + 1) as f64;
        statistic += weight * ranked.u;
        deviation += weight * (ranked.u - ranked.null_mean());
        variance += weight * weight * ranked.null_variance();
    }
    let z = if variance > 0.0 {
        deviation / variance.sqrt()
    } else {
        0.0
    };
    VanElteren {
        statistic,
        z,
        p_value: (2.0 * normal::upper_tail(z.abs())).min(1.0),
    }
}

/// The two-sided rank test's p-value of X against Y: [`mann_whitney`] on one task (exact
/// or asymptotic, as scipy chooses), [`van_elteren`] on several.
///
/// Preconditions: `x` and `y` have the same tasks, in the same order; no score is NaN.
pub fn p_value(x: &Scores, y: &Scores) -> f64 {
    match (x.tasks(), y.tasks()) {
        ([x], [y]) => mann_whitney(x, y).p_value,
        _ => van_elteren(x, y).p_value,
    }
}

/// One task's two samples, ranked together.
struct RankedTask {
    /// Runs of x.
    n: usize,
    /// Runs of y.
    m: usize,
    /// U of x, from its midranks.
    u: f64,
    /// Σ(t³ − t) over the groups of t equal values among all runs: 0 without ties.
    tied_cubes: f64,
}

impl RankedTask {
    fn of(x: &[f64], y: &[f64]) -> Self {
        assert!(
            !x.is_empty() && !y.is_empty(),
            "a rank test needs runs on both sides"
        );
        debug_assert!(
            x.iter().chain(y).all(|v| !v.is_nan()),
            "NaN among the scores"
        );
        let mut pooled: Vec<(f64, bool)> = x
            .iter()
            .map(|&v| (v, true))
            .chain(y.iter().map(|&v| (v, false)))
            .collect();
        pooled.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (mut x_rank_sum, mut tied_cubes) = (0.0, 0.0);
        let mut start = 0;
        for group in pooled.chunk_by(|a, b| a.0 == b.0) {
            // Ranks start + 1 ..= start + t share their mean, start + (t + 1)/2.
            let t = group.len() as f64;
            let midrank = start as f64 + (t + 1.0) / 2.0;
            let xs = group.iter().filter(|(_, from_x)| *from_x).count();
            x_rank_sum += xs as f64 * midrank;
            tied_cubes += t * t * t - t;
            start += group.len();
        }
        let n = x.len();
        RankedTask {
            n,
            m: y.len(),
            u: x_rank_sum - (n * (n + 1)) as f64 / 2.0,
            tied_cubes,
        }
    }

    /// E₀U = n·m/2.
    fn null_mean(&self) -> f64 {
        (self.n * self.m) as f64 / 2.0
    }

    /// Var₀U with the tie correction, `n·m/12 · ((N + 1) − Σ(t³ − t)/(N(N − 1)))`, in
    /// scipy's order of operations.
    fn null_variance(&self) -> f64 {
        let total = (self.n + self.m) as f64;
        (self.n * self.m) as f64 / 12.0
            * ((total + 1.0) - self.tied_cubes / (total * (total - 1.0)))
    }
}

/// `P(U ≥ u)` for samples of n and m runs without ties, when all C(n + m, n) orderings of
/// the runs are equally likely.
fn exact_upper_tail(u: usize, n: usize, m: usize) -> f64 {
    let counts = arrangements_by_u(n, m);
    let total: f64 = counts.iter().sum();
    counts[u..].iter().sum::<f64>() / total
}

/// How many orderings of n x's and m y's (no ties) give U = 0, 1, …, n·m, by Mann and
/// Whitney's (1947) recurrence: the largest of the n + m runs is either an x, which beats
/// all m y's, or a y, which beats no x, so
///
/// `c(n, m; u) = c(n − 1, m; u − m) + c(n, m − 1; u)`, `c(i, 0; 0) = c(0, j; 0) = 1`.
///
/// U's distribution is the same with the samples' roles swapped, so the table runs over
/// the smaller one: (s + 1) rows of s·l + 1 counts, built in about s²·l²/4 additions. The
/// counts are f64 sums of positive numbers: exact up to 2⁵³, to within a few ulps past it.
fn arrangements_by_u(n: usize, m: usize) -> Vec<f64> {
    let (small, large) = (n.min(m), n.max(m));
    // counts[i] is c(i, j; ·) for the j y's placed so far (0 at first: only U = 0).
    let mut counts: Vec<Vec<f64>> = (0..=small)
        .map(|i| {
            let mut row = vec![0.0; i * large + 1];
            row[0] = 1.0;
            row
        })
        .collect();
    for j in 1..=large {
        // Rows in increasing i: row i − 1 already holds c(i − 1, j; ·) when row i,
        // still c(i, j − 1; ·), takes it in.
        for i in 1..=small {
            let (fewer, from_i) = counts.split_at_mut(i);
            let (one_fewer, row) = (&fewer[i - 1], &mut from_i[0]);
            for (count, &added) in row[j..=i * j].iter_mut().zip(one_fewer) {
                *count += added;
            }
        }
    }
    counts
        .pop()
        .expect("a row per run of the smaller sample, and one for none")
}

#[cfg(test)]
mod tests {
    use super::*;

    // Expected values: scipy 1.17.1's `mannwhitneyu(x, y, alternative="two-sided",
    // method="auto")`, and the textbook van Elteren formula, as printed by
    // scripts/stats_reference.py (its data sets of the same names).

    fn close(got: f64, want: f64) -> bool {
        (got - want).abs() <= 1e-12 * want.abs()
    }

    fn assert_test(x: &[f64], y: &[f64], u: f64, p: f64, method: Method) {
        let test = mann_whitney(x, y);
        assert_eq!(test.u, u, "{x:?} {y:?}");
        assert!(close(test.p_value, p), "p {} ≠ scipy's {p}", test.p_value);
        assert_eq!(test.method, method, "{x:?} {y:?}");
    }

    fn floats(values: &[i32]) -> Vec<f64> {
        values.iter().map(|&v| f64::from(v)).collect()
    }

    #[test]
    fn the_exact_distribution_is_counted_by_the_recurrence() {
        // Two x's and two y's: orderings xxyy yxxy … give U = 0, 1, 2, 2, 3, 4:
        // counts [1, 1, 2, 1, 1] of C(4, 2) = 6.
        assert_eq!(arrangements_by_u(2, 2), [1.0, 1.0, 2.0, 1.0, 1.0]);
        // One of each: U = 0 or 1.
        assert_eq!(arrangements_by_u(1, 1), [1.0, 1.0]);
        // Sizes swapped, the same distribution; 3 and 30 runs: C(33, 3) = 5456 orderings,
        // symmetric about n·m/2.
        assert_eq!(arrangements_by_u(3, 30), arrangements_by_u(30, 3));
        let counts = arrangements_by_u(3, 30);
        assert_eq!(counts.len(), 91);
        assert_eq!(counts.iter().sum::<f64>(), 5456.0);
        assert!(counts.iter().eq(counts.iter().rev()));
        // 8 and 30 runs: C(38, 8) = 48,903,492 orderings, every one counted.
        assert_eq!(arrangements_by_u(8, 30).iter().sum::<f64>(), 48_903_492.0);
    }

    #[test]
    fn small_samples_without_ties_get_scipys_exact_p() {
        // scipy's docstring example: U = 17 of 20; U ≥ 17 ⇔ y's U ≤ 3, which 1 + 1 + 2 + 3
        // = 7 of the C(9, 4) = 126 orderings give: p = 2·7/126 = 1/9.
        let males = floats(&[19, 22, 16, 29, 24]);
        let females = floats(&[20, 11, 17, 12]);
        assert_test(&males, &females, 17.0, 0.1111111111111111, Method::Exact);
        assert_test(
            &[1.5, 3.2, 7.7, 4.1, 9.0, 6.3],
            &[2.2, 0.4, 5.5, 1.1, 3.9],
            24.0,
            0.12554112554112554,
            Method::Exact,
        );
    }

    #[test]
    fn one_small_sample_is_enough_for_the_exact_p() {
        // 6 against 20 runs: scipy's rule wants either sample ≤ 8, not both.
        let x = [12.5, 33.1, 27.4, 8.9, 41.0, 19.6];
        let y = [
            5.2, 14.8, 22.3, 3.7, 9.9, 17.1, 28.6, 11.4, 6.6, 20.5, 2.8, 15.9, 24.7, 7.3, 13.2,
            1.9, 18.4, 10.6, 4.5, 16.3,
        ];
        assert_test(&x, &y, 92.0, 0.05358120140728836, Method::Exact);
        let x: Vec<f64> = [31, 7, 44, 18, 26, 39, 12, 35]
            .iter()
            .map(|&v| f64::from(v) + 0.5)
            .collect();
        let y: Vec<f64> = (0..60).step_by(2).map(f64::from).collect();
        assert_test(&x, &y, 112.0, 0.7923333164020273, Method::Exact);
        // 8 against 500: C(508, 8) ≈ 1.1e17 orderings, past f64's whole numbers (2⁵³),
        // counted exactly by scipy in uint64.
        let x: Vec<f64> = (0..8).map(|i| 61.5 * f64::from(i) + 0.25).collect();
        let y: Vec<f64> = (0..500).map(f64::from).collect();
        assert_test(&x, &y, 1728.0, 0.5167584534233481, Method::Exact);
    }

    #[test]
    fn ties_or_two_larger_samples_get_scipys_normal_approximation() {
        // Ties among 7 and 6 runs.
        assert_test(
            &floats(&[1, 2, 2, 3, 4, 4, 5]),
            &floats(&[2, 3, 3, 4, 6, 6]),
            14.0,
            0.3443471042330709,
            Method::Asymptotic,
        );
        // Unequal sizes, with ties.
        assert_test(
            &floats(&[3, 5, 5, 8, 9, 12, 12, 14, 15, 15, 17, 20]),
            &floats(&[
                1, 2, 4, 5, 6, 6, 7, 8, 8, 9, 10, 11, 11, 12, 13, 14, 16, 18, 19, 21, 22, 24, 25,
                26, 27,
            ]),
            137.0,
            0.6847699324535599,
            Method::Asymptotic,
        );
        // Unequal sizes, no ties, both above 8.
        assert_test(
            &[10.1, 12.4, 15.8, 9.3, 20.2, 17.6, 13.9, 11.7, 18.5],
            &[
                8.2, 9.9, 7.1, 12.0, 6.4, 10.8, 14.3, 5.5, 11.1, 8.8, 13.3, 4.6, 9.6, 7.7, 10.4,
            ],
            115.0,
            0.005070215938153766,
            Method::Asymptotic,
        );
    }

    #[test]
    fn ten_and_forty_runs_per_method() {
        // The project's common case: ten CartPole-v1 greedy returns each, capped at 500.
        assert_test(
            &floats(&[500, 500, 487, 312, 500, 455, 198, 500, 421, 389]),
            &floats(&[210, 500, 156, 98, 305, 187, 500, 244, 129, 176]),
            81.0,
            0.01946352678956985,
            Method::Asymptotic,
        );
        assert_test(
            &[
                181.5, 240.25, 199.0, 310.75, 150.5, 275.0, 222.125, 198.5, 260.0, 205.75,
            ],
            &[
                170.0, 188.25, 145.5, 230.0, 160.75, 120.5, 210.0, 175.25, 139.0, 197.5,
            ],
            82.0,
            0.017257456083119765,
            Method::Asymptotic,
        );
        // 40 each: x = (17·i mod 40) + 3, y = 23·i mod 40 for i < 40.
        let x: Vec<f64> = (0..40).map(|i| f64::from((17 * i) % 40 + 3)).collect();
        let y: Vec<f64> = (0..40).map(|i| f64::from((23 * i) % 40)).collect();
        assert_test(&x, &y, 915.5, 0.2683682841957815, Method::Asymptotic);
    }

    #[test]
    fn identical_runs_give_p_one_and_separated_runs_the_smallest_p() {
        let runs = floats(&[3, 1, 4, 1, 5, 9, 2, 6]);
        assert_test(&runs, &runs, 32.0, 1.0, Method::Asymptotic);
        // Every run the same value: σ = 0, z = −∞.
        assert_test(&[7.0; 3], &[7.0; 3], 4.5, 1.0, Method::Asymptotic);
        // Twice a tail that starts at U's centre, clipped: U = 2 of 4.
        assert_test(&[1.0, 4.0], &[2.0, 3.0], 2.0, 1.0, Method::Exact);
        assert_test(&[2.0], &[1.0], 1.0, 1.0, Method::Exact);
        // 3 x's above 4 y's: one ordering of C(7, 3) = 35 in each tail, p = 2/35.
        assert_test(
            &[4.2, 5.0, 6.1],
            &[1.1, 2.3, 3.7, 0.9],
            12.0,
            0.05714285714285714,
            Method::Exact,
        );
        let above: Vec<f64> = (11..=20).map(f64::from).collect();
        let below: Vec<f64> = (1..=10).map(f64::from).collect();
        assert_test(
            &above,
            &below,
            100.0,
            0.00018267179110955002,
            Method::Asymptotic,
        );
    }

    #[test]
    fn swapping_the_methods_swaps_u_and_keeps_p() {
        let x = floats(&[1, 2, 2, 3, 4, 4, 5]);
        let y = floats(&[2, 3, 3, 4, 6, 6]);
        let (forward, backward) = (mann_whitney(&x, &y), mann_whitney(&y, &x));
        assert_eq!(forward.u + backward.u, 42.0);
        assert_eq!(forward.p_value, backward.p_value);
    }

    #[test]
    fn van_elteren_combines_three_tasks_of_different_sizes() {
        let x = Scores::per_task(vec![
            vec![12.0, 15.5, 9.0, 20.0, 18.25],
            floats(&[300, 500, 500, 420, 275, 500, 390, 460, 500, 350]),
            vec![0.42, 0.61, 0.55, 0.70],
        ])
        .unwrap();
        let y = Scores::per_task(vec![
            vec![10.0, 11.5, 14.0, 8.5, 16.0, 13.0],
            floats(&[250, 500, 310, 180, 420, 500, 205, 330, 295, 260]),
            vec![0.38, 0.44, 0.50, 0.61, 0.29, 0.47, 0.35],
        ])
        .unwrap();
        // scipy has no van Elteren test: the script computes it by the textbook formula
        // from scipy's midranks.
        let test = van_elteren(&x, &y);
        assert!(close(test.statistic, 7.1726190476190474), "{test:?}");
        assert!(close(test.z, 2.675509598223189), "{test:?}");
        assert!(close(test.p_value, 0.007461573662598011), "{test:?}");
        assert_eq!(p_value(&x, &y), test.p_value);
        let reversed = van_elteren(&y, &x);
        assert!(close(reversed.z, -test.z) && close(reversed.p_value, test.p_value));
    }

    #[test]
    fn van_elteren_on_one_task_is_the_mann_whitney_normal_approximation() {
        // On one task V = U/(N + 1) and z is Mann–Whitney's without the continuity
        // correction: scipy's mannwhitneyu(x, y, method="asymptotic",
        // use_continuity=False) gives the same p.
        let cases = [
            (
                floats(&[1, 2, 2, 3, 4, 4, 5]),
                floats(&[2, 3, 3, 4, 6, 6]),
                -1.0183501544346312,
                0.30851158133872325,
            ),
            (
                floats(&[500, 500, 487, 312, 500, 455, 198, 500, 421, 389]),
                floats(&[210, 500, 156, 98, 305, 187, 500, 244, 129, 176]),
                2.3748359016667995,
                0.017556753570568597,
            ),
            (
                vec![10.1, 12.4, 15.8, 9.3, 20.2, 17.6, 13.9, 11.7, 18.5],
                vec![
                    8.2, 9.9, 7.1, 12.0, 6.4, 10.8, 14.3, 5.5, 11.1, 8.8, 13.3, 4.6, 9.6, 7.7, 10.4,
                ],
                2.8323527714997336,
                0.004620683963359919,
            ),
        ];
        for (x, y, z, p) in cases {
            let (x, y) = (Scores::one_task(x).unwrap(), Scores::one_task(y).unwrap());
            let test = van_elteren(&x, &y);
            assert!(close(test.z, z) && close(test.p_value, p), "{test:?}");
            let u = mann_whitney(&x.tasks()[0], &y.tasks()[0]).u;
            let all_runs_and_one = (x.runs() + y.runs() + 1) as f64;
            assert!(
                close(test.statistic, u / all_runs_and_one),
                "{test:?} U = {u}"
            );
        }
    }

    #[test]
    fn one_task_is_tested_as_scipy_does_and_all_ties_say_nothing() {
        // On one task the rule's p-value is scipy's "auto" Mann–Whitney, continuity
        // corrected (0.0195 here, not van Elteren's 0.0176).
        let x = Scores::one_task(floats(&[500, 500, 487, 312, 500, 455, 198, 500, 421, 389]));
        let y = Scores::one_task(floats(&[210, 500, 156, 98, 305, 187, 500, 244, 129, 176]));
        assert!(close(
            p_value(&x.unwrap(), &y.unwrap()),
            0.01946352678956985
        ));
        // Every task's runs tied: no variance, no evidence.
        let flat = Scores::per_task(vec![vec![7.0; 3], vec![2.0; 4]]).unwrap();
        let test = van_elteren(&flat, &flat);
        assert_eq!((test.z, test.p_value), (0.0, 1.0));
    }
}
