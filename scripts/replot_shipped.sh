#!/usr/bin/env bash
# Makes a folder shipped in docs/ again with today's `sapnet plot` (its report by today's
# rules: improvement.csv's separation rule, the figures): a copy made again from its
# top-level files (it ships no run records; `sapnet plot` reads episodes.csv.xz as it is),
# and the report, summary.json and figures copied back. episodes.csv.xz and tests.csv, the data,
# are not changed; figures drawn from activations.csv, which did not ship, stay as shipped.
#
#     scripts/replot_shipped.sh DIR [SAPNET]   # SAPNET: the binary, default target/release/sapnet
set -euo pipefail
dir=$1 sapnet=${2:-target/release/sapnet}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp -r "$dir" "$tmp/folder"
"$sapnet" plot "$tmp/folder" > "$tmp/table.txt"
for f in comparison.csv improvement.csv scores.csv summary.json sample_efficiency.csv \
    intervals.png profiles.png improvement.png learning_curve.png sample_efficiency.png \
    tests.png activations.png selections.png; do
    if [ -f "$tmp/folder/$f" ]; then cp "$tmp/folder/$f" "$dir/$f"; fi
done
cp "$tmp/table.txt" "$dir/table.txt"
