"""Per run, the share of the acting steps each source task took, from a results folder's
summary.json (`runs[].source_steps`, the library's `task` per source, as `sapnet` wrote
them): for one task (a substring of its name), every run's share, how many runs gave it
most of their steps, and the share over all runs' steps (comparison.csv's `share_<task>`).
A share is of the steps that followed a source (`source_steps`' sum); "of all steps" divides
by the run's steps instead, for the methods whose learner also acts (GPI's learner winning
the max, the Q-switch's learner followed, A2T's base outweighing every source). For A2T,
which acts on a mixture, it also prints the attention's mean weight on the task's sources
over each run's steps, from DIR/activations.csv when the folder has it.

    python3 scripts/task_shares.py DIR TASK [METHOD ...]

Only the standard library.
"""
import collections
import csv
import json
import os
import sys

directory, task = sys.argv[1], sys.argv[2]
wanted = sys.argv[3:]
with open(f"{directory}/summary.json") as f:
    summary = json.load(f)
tasks = [entry["task"] for entry in summary["library"]]
hit = [i for i, t in enumerate(tasks) if task in t]
if not hit:
    raise SystemExit(f"no source task matches {task!r}: {sorted(set(tasks))}")
by = collections.defaultdict(list)
for run in summary["runs"]:
    steps = run.get("source_steps") or []
    if sum(steps):
        by[run["method"]].append(
            (run["run"], sum(steps[i] for i in hit), sum(steps), run.get("chosen"), run["steps"]))
for method, runs in by.items():
    if wanted and method not in wanted:
        continue
    shares = [h / t for _, h, t, _, _ in runs]
    most = sum(1 for s in shares if s > 0.5)
    pooled = sum(r[1] for r in runs) / sum(r[2] for r in runs)
    of_all = sum(r[1] for r in runs) / sum(r[4] for r in runs)
    handed = sum(1 for r in runs if r[3] and r[3]["index"] in hit)
    print(f"{method:24} pooled {pooled:.0%} ({of_all:.0%} of all steps), "
          f"runs above half {most}/{len(runs)}, "
          f"handed over a {task} source {handed}/{len(runs)}, per run "
          + " ".join(f"{s:.2f}" for s in shares))

# A2T acts on a mixture, not on one source: its attention's mean weight on the task's
# sources over each run's steps (activations.csv's A_<source> at the run's last episode).
path = f"{directory}/activations.csv"
if os.path.exists(path) and (not wanted or any(m.startswith("a2t") for m in wanted)):
    last = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["method"].startswith("a2t"):
                last[(row["method"], int(row["run"]))] = row
    names = [entry.get("name", f"source-{i}") for i, entry in enumerate(summary["library"])]
    for method in sorted({m for m, _ in last}):
        weights = [sum(float(row[f"A_{names[i]}"]) for i in hit)
                   for (m, _), row in sorted(last.items()) if m == method]
        print(f"{method:24} mean attention weight on {task} sources, per run "
              + " ".join(f"{w:.2f}" for w in weights)
              + f" (mean {sum(weights) / len(weights):.2f})")
