"""The tables of docs/REUSE.md, VARIANTS.md and RESULTS.md, recounted from a results
folder's own files (comparison.csv, improvement.csv, scores.csv as `sapnet` wrote them).

    python3 scripts/report_tables.py DIR [REFERENCE]

Prints, in Markdown:
- per method: runs, what it hands over for testing, the greedy test score's IQM and mean
  with their 95% stratified bootstrap intervals, the training return's, the share of runs
  whose moving average reached each threshold (Wilson interval) and the lock-in step;
- P(REFERENCE > Y) for every other method Y, test score and training return, with its
  interval (REFERENCE: `sapnet`, SAP-Net as the paper specifies it, by default);
- which pairs of methods the runs separate: intervals of the mean that do not overlap;
- roughly how many runs per method would separate the two leading methods (the usual
  two-sample estimate, 5% two-sided, 80% power, from the runs' own spread):
  n ≈ (1.96 + 0.84)² (s₁² + s₂²) / Δ².

Only the standard library: no numpy, no pandas.
"""

import csv
import math
import statistics
import sys

directory = sys.argv[1]
reference = sys.argv[2] if len(sys.argv) > 2 else "sapnet"


def rows(name):
    with open(f"{directory}/{name}", newline="") as f:
        return list(csv.DictReader(f))


comparison = rows("comparison.csv")
improvement = rows("improvement.csv")
scores = rows("scores.csv")
digits = 1 if comparison[0]["units"] == "return" else 3


def interval(row, name):
    if row[name] == "":
        return "–"
    point, lo, hi = (float(row[name + s]) for s in ("", "_lo", "_hi"))
    return f"{point:.{digits}f} [{lo:.{digits}f}, {hi:.{digits}f}]"


thresholds = [h[len("reached_"):-len("_share")] for h in comparison[0] if h.startswith("reached_") and h.endswith("_share")]
header = ["method", "runs", "tested", "test IQM [95% CI]", "test mean [95% CI]",
          "return IQM [95% CI]", "return mean [95% CI]"]
header += [f"reached MA ≥ {t} [95% CI]" for t in thresholds] + ["lock-in step (median, runs)"]
print("| " + " | ".join(header) + " |")
print("|" + " --- |" * len(header))
for row in comparison:
    cells = [row["method"], row["runs"], row["tested"], interval(row, "test_iqm"),
             interval(row, "test_mean"), interval(row, "return_iqm"), interval(row, "return_mean")]
    for t in thresholds:
        share = float(row[f"reached_{t}_share"])
        lo, hi = float(row[f"reached_{t}_share_lo"]), float(row[f"reached_{t}_share_hi"])
        cells.append(f"{row[f'reached_{t}']}/{row['runs']} [{lo:.0%}, {hi:.0%}]")
    lock = row["lock_in_median_step"]
    cells.append(f"{float(lock):.0f} ({row['locked_runs']}/{row['runs']})" if lock else "–")
    print("| " + " | ".join(cells) + " |")

print()
print(f"| P({reference} > Y) | test score [95% CI] | training return [95% CI] |")
print("| --- | --- | --- |")
by_pair = {(r["score"], r["method"], r["over"]): r for r in improvement}
for row in comparison:
    y = row["method"]
    if y == reference:
        continue
    cells = [y]
    for score in ("test", "return"):
        r = by_pair.get((score, reference, y))
        if r is None:
            cells.append("–")
            continue
        p, lo, hi = float(r["p"]), float(r["lo"]), float(r["hi"])
        flag = "" if lo <= 0.5 <= hi else " **"
        cells.append(f"{p:.2f} [{lo:.2f}, {hi:.2f}]{flag}")
    print("| " + " | ".join(cells) + " |")
print("\n(** the interval excludes 0.5: these runs separate the two)")


def mean_interval(row, score):
    return tuple(float(row[f"{score}_mean{s}"]) for s in ("", "_lo", "_hi"))


for score, name in (("test", "test score"), ("return", "training return")):
    ranked = sorted(comparison, key=lambda r: -mean_interval(r, score)[0])
    separated = []
    for i, a in enumerate(ranked):
        for b in ranked[i + 1:]:
            (_, alo, _), (_, _, bhi) = mean_interval(a, score), mean_interval(b, score)
            if alo > bhi:
                separated.append(f"{a['method']} > {b['method']}")
    print(f"\n{name}: pairs whose intervals of the mean do not overlap: {len(separated)} of "
          f"{len(ranked) * (len(ranked) - 1) // 2}")
    if comparison[0]["units"] != "return":
        # scores.csv holds each task's own returns: a pooled report's spread is per task.
        continue
    column = "test" if score == "test" else "return"
    first, second = ranked[0]["method"], ranked[1]["method"]
    values = {m: [float(s[column]) for s in scores if s["method"] == m and s[column] != ""]
              for m in (first, second)}
    delta = abs(statistics.mean(values[first]) - statistics.mean(values[second]))
    spread = statistics.variance(values[first]) + statistics.variance(values[second])
    n = math.inf if delta == 0 else (1.96 + 0.84) ** 2 * spread / delta ** 2
    print(f"leading two by mean: {first} and {second}, Δ = {delta:.{digits}f}, sd "
          f"{statistics.stdev(values[first]):.{digits}f} and {statistics.stdev(values[second]):.{digits}f}: "
          f"about {math.ceil(n)} runs per method to separate them")
