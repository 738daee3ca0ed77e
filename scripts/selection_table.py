"""Per method, from a results folder's comparison.csv and summary.json (as `sapnet` wrote
them): the share of acting steps per source task, the policy each run handed over for
testing (the three most frequent), and the categories excluded per run (SAP-Net's
`exclusion`), as the Markdown table of docs/FUTURE_WORK.md.

    python3 scripts/selection_table.py DIR

Only the standard library.
"""
import csv, json, sys, collections
d = sys.argv[1]
s = json.load(open(f"{d}/summary.json"))
rows = list(csv.DictReader(open(f"{d}/comparison.csv", newline="")))
share_cols = [c for c in rows[0] if c.startswith("share_")]
print("| method | " + " | ".join(c[6:] for c in share_cols) + " | chosen (runs) | exclusions per run |")
print("| --- |" + " --- |" * (len(share_cols) + 2))
by = collections.defaultdict(list)
for r in s["runs"]:
    by[r["method"]].append(r)
for row in rows:
    m = row["method"]
    chosen = collections.Counter((r["chosen"] or {}).get("name", "-") for r in by[m])
    ch = ", ".join(f"{k} ×{v}" for k, v in chosen.most_common(3)) if chosen.get("-", 0) < len(by[m]) else "–"
    ex = sum(r["exclusions"] for r in by[m]) / max(1, len(by[m]))
    shares = []
    for c in share_cols:
        v = row[c]
        shares.append(f"{float(v)*100:.0f}%" if v not in ("", None) else "–")
    print(f"| {m} | " + " | ".join(shares) + f" | {ch} | {ex:.1f} |")
