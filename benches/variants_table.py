"""The table of docs/VARIANTS.md from a results folder's comparison.csv.

    python3 benches/variants_table.py OUT_DIR CLOSEST_TASK MIRRORED_TASK

e.g. `python3 benches/variants_table.py out/variants 'force_mag=5.0' 'force_mag=-10.0'`: the
task columns are the share of each method's acting steps taken by each source task's
policies, the two named tasks marked.
"""
import csv, sys
d, closest, mirrored = sys.argv[1], sys.argv[2], sys.argv[3]
rows = list(csv.DictReader(open(d + '/comparison.csv')))
thr = [k[len('episodes_to_'):] for k in rows[0] if k.startswith('episodes_to_')]
tasks = [k[len('share_'):] for k in rows[0] if k.startswith('share_')]
def m(x): return x.replace('-', '−')
def ep(r, t):
    e, n = r['episodes_to_' + t], r['reached_' + t]
    return f"{float(e):.0f} ({n}/{r['runs']})" if e else f"never (0/{r['runs']})"
def num(x): return m(f"{float(x):.1f}") if x else '–'
def label(t):
    inner = t[t.index('(') + 1:-1]
    mark = ' (closest)' if inner == closest else (' (mirrored)' if inner == mirrored else '')
    return f"`{inner}`{mark}"
print("| method | " + " | ".join(f"MA10 ≥ {m(t)}: median episode (runs)" for t in thr) + " | mean return (area under the curve ÷ episodes) | greedy test, mean ± sd over runs | lock-in step, median (runs) | " + " | ".join(label(t) for t in tasks) + " |")
print("| --- " * (len(thr) + 4 + len(tasks)) + "|")
for r in rows:
    test = f"{num(r['test_mean'])} ± {num(r['test_std'])}" if r['test_mean'] else '–'
    lock = f"{float(r['lock_in_median_step']):.0f} ({r['locked_runs']}/{r['runs']})" if r['lock_in_median_step'] else ('–' if r['method'].startswith('dqn') or r['method'] in ('ucb1', 'random-episode') else f"never (0/{r['runs']})")
    shares = " | ".join(f"{float(r['share_' + t]) * 100:.0f}%" if r['share_' + t] else '–' for t in tasks)
    print(f"| {r['method']} | " + " | ".join(ep(r, t) for t in thr) + f" | {num(r['mean_return'])} | {test} | {lock} | {shares} |")
