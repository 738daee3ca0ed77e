"""Which runs two or more results folders share, from their episodes.csv.xz (run, method,
episode, reward, steps, policy: every episode of every run, as `sapnet` wrote it).

    python3 scripts/shared_runs.py DIR1 DIR2 [DIR3 ...]

For every method label found in at least two folders, per pair of folders: how many of
the method's runs have identical rows (every episode's reward, steps and policy), and,
where the runs differ in length only, how many share the shorter one's episodes as a
prefix (same seeds, one protocol running more episodes). Only the standard library.
"""

import collections
import csv
import hashlib
import io
import itertools
import lzma
import sys


def runs(directory):
    """{method: {run: [(episode, reward, steps, policy), ...]}}"""
    out = collections.defaultdict(lambda: collections.defaultdict(list))
    with lzma.open(f"{directory}/episodes.csv.xz", "rt", newline="") as f:
        for row in csv.DictReader(f):
            out[row["method"]][int(row["run"])].append(
                (row["episode"], row["reward"], row["steps"], row["policy"]))
    return out


folders = sys.argv[1:]
data = {d: runs(d) for d in folders}
methods = sorted({m for d in folders for m in data[d]})
for method in methods:
    holders = [d for d in folders if method in data[d]]
    for a, b in itertools.combinations(holders, 2):
        ra, rb = data[a][method], data[b][method]
        common = sorted(set(ra) & set(rb))
        same = sum(1 for r in common if ra[r] == rb[r])
        prefix = sum(1 for r in common if ra[r] != rb[r]
                     and min(len(ra[r]), len(rb[r])) > 0
                     and ra[r][:min(len(ra[r]), len(rb[r]))] == rb[r][:min(len(ra[r]), len(rb[r]))])
        first = sum(1 for r in common if ra[r][:1] == rb[r][:1])
        print(f"{method:24} {a} ({len(ra)} runs) vs {b} ({len(rb)} runs): "
              f"identical {same}/{len(common)}, shorter one a prefix {prefix}/{len(common)}, "
              f"first episode equal {first}/{len(common)}")
