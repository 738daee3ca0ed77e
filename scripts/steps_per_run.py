"""The environment steps each method's runs took in a results folder, from its
episodes.csv (or the shipped episodes.csv.xz): mean, least and most per run. What an
episode budget gave each method (docs/BASELINES.md). Only the standard library.

    python3 scripts/steps_per_run.py DIR
"""
import collections
import csv
import lzma
import os
import sys

d = sys.argv[1]
tot = collections.defaultdict(int)
path = f"{d}/episodes.csv.xz"
opened = lzma.open(path, "rt", newline="") if os.path.exists(path) else open(f"{d}/episodes.csv", newline="")
with opened as f:
    for r in csv.DictReader(f):
        tot[(r["method"], r["run"])] += int(r["steps"])
by = collections.defaultdict(list)
for (m, run), s in tot.items():
    by[m].append(s)
for m, v in by.items():
    print(f"{m:14s} runs {len(v):3d} mean steps/run {sum(v)/len(v):>12,.0f}  min {min(v):,} max {max(v):,}")
