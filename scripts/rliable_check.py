"""Cross-check a results folder's intervals against rliable itself.

Reads DIR/scores.csv (one row per run) and DIR/comparison.csv, DIR/improvement.csv as
sapnet wrote them, recomputes the aggregates with rliable 1.2 (percentile method,
stratified bootstrap) and prints, per method and aggregate, sapnet's point and interval
beside rliable's: the points must agree to 1e-9, the interval ends within the bootstrap's
noise (both are random; the difference is reported as a share of the interval's width).

    python scripts/rliable_check.py DIR LOW HIGH   # LOW HIGH: the task's range of returns

Needs numpy, pandas<3 and rliable (../shared/bench/README.md's peer venv).
"""

import sys

import numpy as np
import pandas as pd
from rliable import library as rly
from rliable import metrics

directory, low, high = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
scores = pd.read_csv(f"{directory}/scores.csv")
comparison = pd.read_csv(f"{directory}/comparison.csv").set_index("method")
improvement = pd.read_csv(f"{directory}/improvement.csv")
reps = 10_000


def matrix(method, column, normalise=False):
    """The (runs × 1 task) matrix rliable takes."""
    values = scores[scores.method == method][column].dropna().to_numpy(dtype=float)
    if normalise:
        values = (values - low) / (high - low)
    return values.reshape(-1, 1)


methods = list(comparison.index)
aggregates = {
    "mean": metrics.aggregate_mean,
    "iqm": metrics.aggregate_iqm,
    # rliable's aggregate_median is the median of the tasks' means (on one task, the
    # mean); sapnet's is the runs' median, as numpy computes it:
    "median": lambda x: np.median(x),
    "optimality_gap": metrics.aggregate_optimality_gap,
}
worst_point, worst_end, worst_noise = 0.0, 0.0, 0.0
print(f"{'score':<7} {'method':<20} {'aggregate':<15} {'sapnet':>30} {'rliable':>30}")
for score, column in [("test", "test"), ("return", "return")]:
    for name, function in aggregates.items():
        normalise = name == "optimality_gap"
        data = {m: matrix(m, column, normalise) for m in methods}
        points, intervals = rly.get_interval_estimates(
            data, lambda x: np.array([function(x)]), reps=reps, random_state=np.random.RandomState(1)
        )
        # rliable against itself with another seed: the bootstrap's own noise.
        _, again = rly.get_interval_estimates(
            data, lambda x: np.array([function(x)]), reps=reps, random_state=np.random.RandomState(2)
        )
        for m in methods:
            ours = comparison.loc[m, [f"{score}_{name}", f"{score}_{name}_lo", f"{score}_{name}_hi"]]
            theirs = (points[m][0], intervals[m][0][0], intervals[m][1][0])
            width = max(ours.iloc[2] - ours.iloc[1], 1e-12)
            worst_point = max(worst_point, abs(ours.iloc[0] - theirs[0]))
            end = max(abs(ours.iloc[1] - theirs[1]), abs(ours.iloc[2] - theirs[2])) / width
            worst_end = max(worst_end, end)
            noise = max(abs(again[m][0][0] - theirs[1]), abs(again[m][1][0] - theirs[2])) / width
            worst_noise = max(worst_noise, noise)
            print(
                f"{score:<7} {m:<20} {name:<15} "
                f"{ours.iloc[0]:9.3f} [{ours.iloc[1]:8.3f}, {ours.iloc[2]:8.3f}] "
                f"{theirs[0]:9.3f} [{theirs[1]:8.3f}, {theirs[2]:8.3f}]"
            )
pairs = {}
for _, row in improvement.iterrows():
    column = "test" if row.score == "test" else "return"
    pairs[(row.score, row.method, row.over)] = (matrix(row.method, column), matrix(row.over, column))
worst_p, worst_p_end = 0.0, 0.0
for (score, x, y), (xs, ys) in pairs.items():
    theirs_point = metrics.probability_of_improvement(xs, ys)
    ours = improvement[(improvement.score == score) & (improvement.method == x) & (improvement.over == y)].iloc[0]
    worst_p = max(worst_p, abs(ours.p - theirs_point))
# Intervals of P(X > Y) for SAP-Net over every other method (rliable's independent
# stratified bootstrap), a sample of the pairs: each takes seconds in rliable.
for score in ["test", "return"]:
    for y in methods:
        if y == "sapnet":
            continue
        xs, ys = pairs[(score, "sapnet", y)]
        _, interval = rly.get_interval_estimates(
            {"p": (xs, ys)}, metrics.probability_of_improvement, reps=2_000
        )
        ours = improvement[(improvement.score == score) & (improvement.method == "sapnet") & (improvement.over == y)].iloc[0]
        lo, hi = (float(np.ravel(interval["p"])[0]), float(np.ravel(interval["p"])[1]))
        width = max(ours.hi - ours.lo, 1e-12)
        worst_p_end = max(worst_p_end, max(abs(ours.lo - lo), abs(ours.hi - hi)) / width)
print(f"\nlargest difference of a point estimate: {worst_point:.3g}")
print(f"largest difference of an interval end, as a share of the interval's width: {worst_end:.3f}")
print(f"the same between two seeds of rliable itself: {worst_noise:.3f}")
print(f"largest difference of P(X > Y), every ordered pair ({len(pairs)}): {worst_p:.3g}")
print(f"largest difference of its interval's ends (sapnet over each), share of width: {worst_p_end:.3f}")
