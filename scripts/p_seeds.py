"""P(X > Y) from a results folder's scores.csv (one row per run, as `sapnet` wrote it),
with its 95% percentile interval from 10,000 independent resamples of X's runs and Y's
runs (per task, averaged over tasks, ties half: `sapnet`'s and rliable's definition),
under several bootstrap seeds: does the interval's side of 0.5 hold with the seed?

    python3 scripts/p_seeds.py DIR SCORE X Y [SEEDS]

SCORE is `return` or `test`; SEEDS (default 5) are Python's random.Random(0..SEEDS-1),
not `sapnet`'s streams, so an end can differ from improvement.csv's by a resample's
luck: that is what this measures. For the folders made before the separation rule, which
carry one seed's interval only. Only the standard library.
"""
import collections
import csv
import random
import sys

directory, score, x, y = sys.argv[1:5]
seeds = int(sys.argv[5]) if len(sys.argv) > 5 else 5
runs = collections.defaultdict(lambda: collections.defaultdict(list))
with open(f"{directory}/scores.csv", newline="") as f:
    for row in csv.DictReader(f):
        runs[row["method"]][row["task"]].append(float(row[score]))
tasks = sorted(set(runs[x]) & set(runs[y]))


def p(xs, ys):
    total = 0.0
    for task in tasks:
        a, b = xs[task], ys[task]
        total += sum(1.0 if u > v else 0.5 if u == v else 0.0 for u in a for v in b) / (len(a) * len(b))
    return total / len(tasks)


def percentile(values, q):
    position = q * (len(values) - 1)
    below, above = int(position), min(int(position) + 1, len(values) - 1)
    return values[below] + (values[above] - values[below]) * (position - below)


point = p(runs[x], runs[y])
excluding = 0
print(f"P({x} > {y}), {score}, {directory}: {point:.3f}")
for seed in range(seeds):
    rng = random.Random(seed)
    values = []
    for _ in range(10_000):
        xs = {t: [rng.choice(runs[x][t]) for _ in runs[x][t]] for t in tasks}
        ys = {t: [rng.choice(runs[y][t]) for _ in runs[y][t]] for t in tasks}
        values.append(p(xs, ys))
    values.sort()
    lo, hi = percentile(values, 0.025), percentile(values, 0.975)
    out = lo > 0.5 or hi < 0.5
    excluding += out
    print(f"  seed {seed}: [{lo:.3f}, {hi:.3f}] {'excludes' if out else 'holds'} 0.5")
print(f"  {excluding} of {seeds} seeds' intervals exclude 0.5")
