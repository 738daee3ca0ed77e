#!/usr/bin/env python3
"""The per-method table of docs/RESULTS.md from one headless output directory.

For each method: how many runs; the first episode at which the moving average of 10
returns reaches each threshold, for the mean-over-runs curve (the paper's figures) and
per run (median, and how many runs got there); the best and final MA10 of the mean curve;
the mean greedy test return over every test episode of every run (with the runs' spread);
and for SAP-Net, which policy each run chose.

Usage: python3 benches/results_table.py OUT_DIR THRESHOLD [THRESHOLD ...]
"""
import collections
import csv
import json
import statistics
import sys


def moving_average(values, window=10):
    return [sum(values[i - window + 1 : i + 1]) / window for i in range(window - 1, len(values))]


def first_reaching(averages, threshold, window=10):
    hit = next((i for i, a in enumerate(averages) if a >= threshold), None)
    return None if hit is None else hit + window


def main():
    out, thresholds = sys.argv[1], [float(t) for t in sys.argv[2:]]
    runs = collections.defaultdict(dict)
    for row in csv.DictReader(open(f"{out}/episodes.csv")):
        runs[row["method"]].setdefault(int(row["run"]), []).append(float(row["reward"]))
    tests = collections.defaultdict(lambda: collections.defaultdict(list))
    for row in csv.DictReader(open(f"{out}/tests.csv")):
        tests[row["method"]][int(row["run"])].append(float(row["return"]))
    summary = json.load(open(f"{out}/summary.json"))

    header = ["method", "runs"]
    for t in thresholds:
        header += [f"mean curve MA10 ≥ {t:g}", f"runs reaching {t:g}: median episode"]
    header += ["best / final MA10 of mean curve", "greedy test return, mean (run means)", "train wall s (mean per run)"]
    print("| " + " | ".join(header) + " |")
    print("|" + " --- |" * len(header))
    for method, by_run in runs.items():
        series = [moving_average(r) for r in by_run.values()]
        length = max(len(s) for s in series)
        mean_curve = [
            statistics.fmean(s[i] for s in series if i < len(s)) for i in range(length)
        ]
        cells = [method, str(len(by_run))]
        for t in thresholds:
            hit = first_reaching(mean_curve, t)
            cells.append("never" if hit is None else str(hit))
            per_run = [first_reaching(s, t) for s in series]
            reached = [h for h in per_run if h is not None]
            cells.append(
                f"{statistics.median(reached):.0f} ({len(reached)}/{len(per_run)})" if reached else f"never (0/{len(per_run)})"
            )
        cells.append(f"{max(mean_curve):.1f} / {mean_curve[-1]:.1f}")
        run_means = [statistics.fmean(v) for v in tests[method].values()]
        every = [x for v in tests[method].values() for x in v]
        cells.append(
            f"{statistics.fmean(every):.1f} ({', '.join(f'{m:.0f}' for m in run_means)})" if every else "-"
        )
        walls = [r["wall_s"] for r in summary["runs"] if r["method"] == method]
        cells.append(f"{statistics.fmean(walls):.0f}" if walls else "-")
        print("| " + " | ".join(cells) + " |")

    chosen = [r for r in summary["runs"] if r.get("chosen")]
    if chosen:
        library = {p["name"]: p for p in summary.get("library") or []}
        print()
        print("| SAP-Net run | chosen policy | hidden layers | source greedy score | final score (A for SAP-Net) | test returns |")
        print("| --- | --- | --- | --- | --- | --- |")
        for r in chosen:
            c = r["chosen"]
            score = library.get(c["name"], {}).get("final_score")
            print(
                f"| {r['run'] + 1} | {c['name']} | {c['hidden']} | {score if score is not None else '-'} | "
                f"{c.get('score', c.get('activation')):.4g} | {', '.join(f'{x:.0f}' for x in r['test_returns'])} |"
            )
    print()
    print(f"Experiment wall time: {summary['wall_s']:.0f} s")


if __name__ == "__main__":
    main()
