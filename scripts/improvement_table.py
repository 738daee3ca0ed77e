"""P(X > Y) of chosen methods over chosen others, from a results folder's improvement.csv
(as `sapnet` wrote it: the probability that a run of X scores above a run of Y, with its
95% stratified bootstrap interval), as the Markdown table of docs/FUTURE_WORK.md.

    python3 scripts/improvement_table.py DIR --methods X1,X2 --over Y1,Y2 [--score test|return]

One row per X, one column per Y; `**` where the interval excludes 0.5 (the runs separate
the two). Only the standard library.
"""

import argparse
import csv

parser = argparse.ArgumentParser()
parser.add_argument("directory")
parser.add_argument("--methods", required=True)
parser.add_argument("--over", required=True)
parser.add_argument("--score", default="test", choices=["test", "return"])
args = parser.parse_args()

with open(f"{args.directory}/improvement.csv", newline="") as f:
    rows = list(csv.DictReader(f))
score = {"test": "test", "return": "return"}[args.score]
known = {r["score"] for r in rows}
if score not in known:
    raise SystemExit(f"{args.directory}/improvement.csv: no score {score!r}; it has {sorted(known)}")
table = {(r["method"], r["over"]): r for r in rows if r["score"] == score}

methods = args.methods.split(",")
over = args.over.split(",")
print(f"| P(X > Y), {args.score} | " + " | ".join(over) + " |")
print("| --- |" + " --- |" * len(over))
for x in methods:
    cells = []
    for y in over:
        r = table.get((x, y))
        if r is None:
            raise SystemExit(f"{args.directory}/improvement.csv: no row {score},{x},{y}")
        p, lo, hi = float(r["p"]), float(r["lo"]), float(r["hi"])
        mark = " **" if lo > 0.5 or hi < 0.5 else ""
        cells.append(f"{p:.2f} [{lo:.2f}, {hi:.2f}]{mark}")
    print(f"| {x} | " + " | ".join(cells) + " |")
