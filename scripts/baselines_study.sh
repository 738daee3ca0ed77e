#!/bin/sh
# Issue 40's study (docs/BASELINES.md): each library's protocol in turn, each resumed if its
# folder exists, from the repository's root (the configs name the libraries relative to it).
#
#     nice -n 19 scripts/baselines_study.sh SAPNET OUT [TASK ...]
#
# SAPNET is a copied release binary (so that a rebuild cannot change it mid-study), OUT the
# folder of the tasks' folders; the tasks default to the ones docs/BASELINES.md still waits
# for. Each task logs to OUT/TASK.log; OUT/study.log gets a line as each ends. A task's
# folder is marked `done` once its protocol exits 0; one stopped or killed is resumed on the
# next call, its finished runs kept. LunarLander runs through Gymnasium: put a Python with
# gymnasium[box2d] first on PATH.
set -u
sapnet=$1 out=$2
shift 2
[ $# -gt 0 ] || set -- variants_cartpole lunar_lander mountain_car
cd "$(dirname "$0")/.." || exit 2
mkdir -p "$out"
for task in "$@"; do
    dir=$out/$task
    # A protocol that completed before its `done` was written (a kill in between).
    grep -qs '"status": *"complete"' "$dir/summary.json" && touch "$dir/done"
    [ -f "$dir/done" ] && continue
    if [ -d "$dir" ]; then
        "$sapnet" --headless --resume --out "$dir" --jobs 2 > "$out/$task.log" 2>&1
    else
        "$sapnet" --headless --config "assets/baselines_$task.ron" --out "$dir" --jobs 2 \
            > "$out/$task.log" 2>&1
    fi
    rc=$?
    echo "$(date -u +%FT%TZ) $task rc=$rc" >> "$out/study.log"
    [ $rc -eq 0 ] && touch "$dir/done"
    # A stop (SIGTERM, Ctrl-C) ends the study, not just this task.
    [ $rc -eq 0 ] || exit $rc
done
