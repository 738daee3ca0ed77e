"""The expected numbers of src/stats/{rank_test,multiplicity,power,normal}.rs's tests.

Prints, for each data set the tests use, what scipy (and statsmodels, where it has the
method) computes, floats in `repr` form (the shortest text that reads back to the same
f64, so Rust parses exactly what Python printed):

- `mann_whitney`: scipy.stats.mannwhitneyu(x, y, alternative="two-sided", method="auto")
  with its default continuity correction, and which method "auto" chose (scipy's rule:
  exact when either sample has at most 8 runs and no value is tied, else the normal
  approximation);
- `van_elteren`: scipy has no van Elteren test, so it is computed here by the textbook
  formula (Lehmann, Nonparametrics, 1975, pp. 132-141) from scipy's midranks; for one task
  it is mannwhitneyu(..., method="asymptotic", use_continuity=False), printed beside it;
- `holm`: statsmodels.stats.multitest.multipletests(p, method="holm")[1], and a direct
  re-implementation of Holm's formula for when statsmodels is missing;
- `normal`: scipy.stats.norm.ppf and norm.sf;
- `noether`: runs per method from Noether's (1987) formula with scipy's quantiles.

    /work/shared/bench/.venv-peers/bin/python scripts/stats_reference.py

Needs numpy and scipy (>= 1.9, for mannwhitneyu's "auto" rule); statsmodels if present.
"""

import math

import numpy as np
import scipy
from scipy import stats

try:
    import statsmodels
    from statsmodels.stats.multitest import multipletests
except ImportError:
    statsmodels = None


def chosen_method(x, y):
    """scipy's own choice for method="auto" (scipy.stats._mannwhitneyu._mwu_choose_method)."""
    ties = len(np.unique(np.concatenate([x, y]))) < len(x) + len(y)
    if (len(x) > 8 and len(y) > 8) or ties:
        return "asymptotic"
    return "exact"


# One task each. Runs as a protocol would have them: a few, sometimes tied (CartPole's
# returns stop at 500), sometimes all above the other method's.
TASK_SETS = {
    # scipy's own docstring example: U = 17, exact p = 1/9.
    "scipy_doc_example": ([19, 22, 16, 29, 24], [20, 11, 17, 12]),
    "exact_small": ([1.5, 3.2, 7.7, 4.1, 9.0, 6.3], [2.2, 0.4, 5.5, 1.1, 3.9]),
    # Exact although y has 20 runs: scipy needs only one sample with at most 8.
    "exact_unequal": (
        [12.5, 33.1, 27.4, 8.9, 41.0, 19.6],
        [5.2, 14.8, 22.3, 3.7, 9.9, 17.1, 28.6, 11.4, 6.6, 20.5,
         2.8, 15.9, 24.7, 7.3, 13.2, 1.9, 18.4, 10.6, 4.5, 16.3],
    ),
    "exact_8_vs_30": (
        [float(v) + 0.5 for v in [31, 7, 44, 18, 26, 39, 12, 35]],
        [float(v) for v in range(0, 60, 2)],
    ),
    # C(508, 8) ≈ 1.1e17 orderings, past 2^53: sapnet's f64 counts round, scipy's uint64 ones do not.
    "exact_8_vs_500": (
        [61.5 * i + 0.25 for i in range(8)],
        [float(v) for v in range(500)],
    ),
    "ties_small": ([1, 2, 2, 3, 4, 4, 5], [2, 3, 3, 4, 6, 6]),
    "unequal_ties": (
        [3, 5, 5, 8, 9, 12, 12, 14, 15, 15, 17, 20],
        [1, 2, 4, 5, 6, 6, 7, 8, 8, 9, 10, 11, 11, 12, 13, 14, 16, 18, 19, 21, 22, 24, 25, 26, 27],
    ),
    "unequal_no_ties_9_vs_15": (
        [10.1, 12.4, 15.8, 9.3, 20.2, 17.6, 13.9, 11.7, 18.5],
        [8.2, 9.9, 7.1, 12.0, 6.4, 10.8, 14.3, 5.5, 11.1, 8.8, 13.3, 4.6, 9.6, 7.7, 10.4],
    ),
    # The project's common case: ten runs each, CartPole-v1 greedy returns capped at 500.
    "ten_runs_capped": (
        [500, 500, 487, 312, 500, 455, 198, 500, 421, 389],
        [210, 500, 156, 98, 305, 187, 500, 244, 129, 176],
    ),
    "ten_runs_no_ties": (
        [181.5, 240.25, 199.0, 310.75, 150.5, 275.0, 222.125, 198.5, 260.0, 205.75],
        [170.0, 188.25, 145.5, 230.0, 160.75, 120.5, 210.0, 175.25, 139.0, 197.5],
    ),
    "forty_runs": (
        [float((17 * i) % 40 + 3) for i in range(40)],
        [float((23 * i) % 40) for i in range(40)],
    ),
    "identical": ([3, 1, 4, 1, 5, 9, 2, 6], [3, 1, 4, 1, 5, 9, 2, 6]),
    "all_tied": ([7, 7, 7], [7, 7, 7]),
    "separated_exact": ([4.2, 5.0, 6.1], [1.1, 2.3, 3.7, 0.9]),
    "separated_ten": (
        [float(v) for v in range(11, 21)],
        [float(v) for v in range(1, 11)],
    ),
    "one_each": ([2.0], [1.0]),
    # U = m·n/2: twice the upper tail exceeds 1 and is clipped.
    "exact_at_the_centre": ([1.0, 4.0], [2.0, 3.0]),
}

# Three tasks, sizes and ties differing, for the van Elteren test.
STRATA = (
    [
        [12.0, 15.5, 9.0, 20.0, 18.25],
        [300, 500, 500, 420, 275, 500, 390, 460, 500, 350],
        [0.42, 0.61, 0.55, 0.70],
    ],
    [
        [10.0, 11.5, 14.0, 8.5, 16.0, 13.0],
        [250, 500, 310, 180, 420, 500, 205, 330, 295, 260],
        [0.38, 0.44, 0.50, 0.61, 0.29, 0.47, 0.35],
    ],
)

HOLM_SETS = {
    "five": [0.01, 0.04, 0.03, 0.005, 0.2],
    "ties_and_clip": [0.02, 0.02, 0.5, 0.9, 0.001, 0.3],
    "one": [0.03],
}

QUANTILE_LEVELS = [1e-300, 1e-20, 1e-10, 1e-5, 0.01, 0.025, 0.075, 0.2, 0.5, 0.8, 0.925,
                   0.975, 0.999999]
TAIL_POINTS = [-3.0, -0.5, 0.0, 0.5, 1.0, 1.959963984540054, 3.0, 8.0, 20.0, 37.0]

NOETHER_PS = [0.75, 0.6, 0.9, 1.0, 0.0, 0.3, 0.55, 0.52, 0.625]
ALPHA, POWER = 0.05, 0.8


def van_elteren(x_tasks, y_tasks):
    """van Elteren's statistic, z and two-sided p: the rank sums' U_t weighted by
    1/(N_t + 1), the tie-corrected null variance of each, the normal approximation."""
    statistic, deviation, variance = 0.0, 0.0, 0.0
    for x, y in zip(x_tasks, y_tasks):
        n, m = len(x), len(y)
        total = n + m
        ranks = stats.rankdata(np.concatenate([x, y]))
        u = ranks[:n].sum() - n * (n + 1) / 2
        _, counts = np.unique(np.concatenate([x, y]), return_counts=True)
        ties = float(np.sum(counts**3 - counts))
        weight = 1.0 / (total + 1)
        statistic += weight * u
        deviation += weight * (u - n * m / 2)
        variance += weight**2 * n * m / 12 * ((total + 1) - ties / (total * (total - 1)))
    z = deviation / math.sqrt(variance)
    return statistic, z, 2 * stats.norm.sf(abs(z))


def holm_by_hand(p):
    """adjusted p_(i) = max_{j<=i} min(1, (m - j + 1) p_(j)), back in the input order."""
    m = len(p)
    order = sorted(range(m), key=lambda i: p[i])
    adjusted, running = [0.0] * m, 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * p[i]))
        adjusted[i] = running
    return adjusted


def main():
    print(f"# scipy {scipy.__version__}, numpy {np.__version__}, "
          f"statsmodels {statsmodels.__version__ if statsmodels else 'not installed'}")

    print("\n## mann_whitney: U of x, two-sided p, method (scipy method='auto')")
    for name, (x, y) in TASK_SETS.items():
        x, y = np.asarray(x, float), np.asarray(y, float)
        result = stats.mannwhitneyu(x, y, alternative="two-sided", method="auto")
        print(f"{name}: u = {float(result.statistic)!r}, p = {float(result.pvalue)!r}, "
              f"method = {chosen_method(x, y)}")

    print("\n## van_elteren, three tasks (textbook formula): statistic, z, p")
    statistic, z, p = van_elteren(*STRATA)
    print(f"three_tasks: statistic = {float(statistic)!r}, z = {float(z)!r}, p = {float(p)!r}")
    print("van_elteren of one task beside mannwhitneyu(asymptotic, no continuity)")
    for name in ["ties_small", "ten_runs_capped", "unequal_no_ties_9_vs_15"]:
        x, y = TASK_SETS[name]
        _, z, p = van_elteren([x], [y])
        scipy_p = stats.mannwhitneyu(x, y, method="asymptotic", use_continuity=False).pvalue
        print(f"{name}: z = {float(z)!r}, p = {float(p)!r}, scipy p = {float(scipy_p)!r}")

    print("\n## holm: adjusted p in input order")
    for name, p in HOLM_SETS.items():
        ours = holm_by_hand(p)
        if statsmodels is not None:
            theirs = [float(v) for v in multipletests(p, method="holm")[1]]
            assert np.allclose(ours, theirs, rtol=0, atol=1e-15), (ours, theirs)
            print(f"{name}: {p} -> {theirs} (statsmodels; the formula agrees)")
        else:
            print(f"{name}: {p} -> {ours} (the formula; statsmodels not installed)")

    print("\n## normal: norm.ppf(q)")
    for q in QUANTILE_LEVELS:
        print(f"({q!r}, {float(stats.norm.ppf(q))!r}),")
    print("## normal: norm.sf(z)")
    for z in TAIL_POINTS:
        print(f"({z!r}, {float(stats.norm.sf(z))!r}),")

    print(f"\n## noether: runs per method, two-sided alpha {ALPHA}, power {POWER}")
    z_sum = stats.norm.ppf(1 - ALPHA / 2) + stats.norm.ppf(POWER)
    for p in NOETHER_PS:
        if p == 0.5:
            continue
        total = z_sum**2 / (12 * 0.5 * 0.5 * (p - 0.5) ** 2)
        per_method = total / 2
        # A value within 1e-9 of an integer would make the rounding up fragile.
        assert abs(per_method - round(per_method)) > 1e-9, (p, per_method)
        print(f"({p!r}, {math.ceil(per_method)}),  // N = {total:.4f}")


if __name__ == "__main__":
    main()
