#!/usr/bin/env python3
"""Per run of an episodes.csv: the first episode (and total steps by then) at which the
moving average of 10 returns reaches each threshold.

Usage: python3 benches/first_reaching.py OUT/episodes.csv [THRESHOLD ...]   (default 195 475)
"""
import collections
import csv
import sys


def main():
    path = sys.argv[1]
    thresholds = [float(t) for t in sys.argv[2:]] or [195.0, 475.0]
    runs = collections.defaultdict(list)
    for row in csv.DictReader(open(path)):
        runs[(row["method"], int(row["run"]))].append(row)
    header = ["method", "run", "best MA10"] + [f"MA10 >= {t:g}: episode (steps)" for t in thresholds]
    print("| " + " | ".join(header) + " |")
    print("|" + " --- |" * len(header))
    for (method, run), rows in runs.items():
        rewards = [float(r["reward"]) for r in rows]
        steps = [int(r["steps"]) for r in rows]
        averages = [sum(rewards[i - 9 : i + 1]) / 10 for i in range(9, len(rewards))]
        cells = [method, str(run + 1), f"{max(averages):.1f}" if averages else "-"]
        for t in thresholds:
            hit = next((i for i, a in enumerate(averages) if a >= t), None)
            cells.append("never" if hit is None else f"{hit + 10} ({sum(steps[: hit + 10]):,})")
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
