"""Which sources a results folder's runs used, per method, from its summary.json: the
source each run handed over for testing (`runs[].chosen`) and the share of the acting
steps that sources matching a name prefix took (`runs[].source_steps`, mean of runs).

    python3 scripts/sources_used.py DIR [PREFIX]

PREFIX (default `sb3`) picks the sources whose share is summed: in docs/IMPORT.md, the
imported Stable-Baselines3 agents. Only the standard library.
"""

import collections
import json
import sys

directory = sys.argv[1]
prefix = sys.argv[2] if len(sys.argv) > 2 else "sb3"
with open(f"{directory}/summary.json") as f:
    summary = json.load(f)
names = [entry["name"] for entry in summary["library"]]
picked = [i for i, name in enumerate(names) if name.startswith(prefix)]
chosen = collections.defaultdict(collections.Counter)
shares = collections.defaultdict(list)
for run in summary["runs"]:
    method = run["method"]
    if run.get("chosen"):
        chosen[method][run["chosen"]["name"]] += 1
    steps = run.get("source_steps") or []
    if sum(steps):
        shares[method].append(sum(steps[i] for i in picked) / sum(steps))
print(f"| method | handed over for testing | {prefix}* share of acting steps (mean of runs) |")
print("| --- | --- | --- |")
for method in dict.fromkeys(run["method"] for run in summary["runs"]):
    if method not in chosen and method not in shares:
        continue
    handed = ", ".join(f"{name} {n}" for name, n in chosen[method].most_common()) or "-"
    share = shares[method]
    mean = f"{sum(share) / len(share):.3f}" if share else "-"
    print(f"| {method} | {handed} | {mean} |")
