#!/usr/bin/env bash
# Copies what the docs count from out of a results folder into docs/: the report
# (comparison.csv, improvement.csv, scores.csv), tests.csv, summary.json, the plots, and
# episodes.csv cut to the columns the docs read (run, method, episode, reward, steps,
# policy), compressed with xz (pandas reads it as is: pd.read_csv("episodes.csv.xz")).
#
#     scripts/ship_results.sh RESULTS DEST
set -euo pipefail
src=$1 dest=$2
mkdir -p "$dest"
for f in comparison.csv improvement.csv scores.csv tests.csv summary.json \
    sample_efficiency.csv intervals.png profiles.png improvement.png learning_curve.png \
    sample_efficiency.png tests.png selections.png activations.png; do
    if [ -f "$src/$f" ]; then cp "$src/$f" "$dest/$f"; fi
done
# A CSV reader, not cut: labels such as dqn[100,100] are quoted and hold commas.
python3 -c '
import csv, sys
rows = csv.DictReader(open(sys.argv[1], newline=""))
out = csv.writer(sys.stdout, lineterminator="\n")
columns = ["run", "method", "episode", "reward", "steps", "policy"]
out.writerow(columns)
for row in rows:
    out.writerow([row[c] for c in columns])
' "$src/episodes.csv" | xz -9 -T2 > "$dest/episodes.csv.xz"
