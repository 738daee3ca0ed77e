"""The separation rule's verdicts of a results folder, read from its improvement.csv
(the columns `sapnet plot` writes: p, lo, hi, holm_p, seeds_excluding, verdict,
runs_needed), as the docs quote them. Only the standard library.

    python3 scripts/verdicts.py DIR              # counts of verdicts per score
    python3 scripts/verdicts.py DIR X            # Markdown table of P(X > Y) for every Y
    python3 scripts/verdicts.py DIR X Y [SCORE]  # one pair, as a sentence's numbers
    python3 scripts/verdicts.py DIR --grid X1,X2,.. Y1,Y2,.. [SCORE]
                                                 # P(X > Y) for each X (rows) and Y (columns):
                                                 # ** separated, * fragile, unmarked not separated

SCORE is `return` (the training return, default) or `test`. `runs_needed` is the runs
per method that would detect the observed P at 80% power; empty when P is 0.5.
"""
import collections
import csv
import sys


def holm(p):
    p = float(p)
    if p < 0.001:
        mantissa, exponent = f"{p:.0e}".split("e")
        return f"{mantissa}e{int(exponent)}"
    return f"{p:.3f}"


def interval(row):
    return f"{float(row['p']):.2f} [{float(row['lo']):.2f}, {float(row['hi']):.2f}]"


def needed(row):
    return f"{int(row['runs_needed']):,}" if row["runs_needed"] else "–"


def said(row):
    text = f"P = {interval(row)}, Holm p = {holm(row['holm_p'])}, {row['seeds_excluding']} seeds: {row['verdict']}"
    if row["verdict"] != "separated":
        text += f" (runs needed {needed(row)})"
    return text


directory = sys.argv[1]
with open(f"{directory}/improvement.csv", newline="") as f:
    rows = list(csv.DictReader(f))
pair = {(r["score"], r["method"], r["over"]): r for r in rows}

if len(sys.argv) == 2:
    for score in ("return", "test"):
        seen, counts = set(), collections.Counter()
        for r in rows:
            key = frozenset((r["method"], r["over"]))
            if r["score"] == score and key not in seen:
                seen.add(key)
                counts[r["verdict"]] += 1
        print(f"{score}: {len(seen)} pairs: " + ", ".join(
            f"{counts[v]} {v}" for v in ("separated", "fragile", "not separated")))
elif sys.argv[2] == "--grid":
    xs, ys = sys.argv[3].split(","), sys.argv[4].split(",")
    score = sys.argv[5] if len(sys.argv) > 5 else "return"
    mark = {"separated": " **", "fragile": " *", "not separated": ""}
    print(f"| P(X > Y), {score} | " + " | ".join(ys) + " |")
    print("| --- |" + " --- |" * len(ys))
    for x in xs:
        cells = [interval(pair[(score, x, y)]) + mark[pair[(score, x, y)]["verdict"]] for y in ys]
        print(f"| {x} | " + " | ".join(cells) + " |")
elif len(sys.argv) == 3:
    x = sys.argv[2]
    print(f"| Y | P({x} > Y), training return [95% CI] | Holm p | seeds excluding 0.5 | verdict | runs needed | test score [95% CI] | test verdict |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        if r["score"] == "return" and r["method"] == x:
            t = pair[("test", x, r["over"])]
            print(f"| {r['over']} | {interval(r)} | {holm(r['holm_p'])} | {r['seeds_excluding']} | "
                  f"{r['verdict']} | {needed(r)} | {interval(t)} | {t['verdict']} |")
else:
    x, y = sys.argv[2:4]
    score = sys.argv[4] if len(sys.argv) > 4 else "return"
    print(said(pair[(score, x, y)]))
