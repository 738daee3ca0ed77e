#!/bin/sh
# Peak and idle memory of `sapnet open DIR` in a tmux pane, Enter on its first run, as a
# user would: the peak (ru_maxrss, /usr/bin/time -v) and the resident memory once the
# Runs view is idle, then once the run's dashboard (Enter) is idle.
#
#     scripts/hostile/measure_open.sh target/release/sapnet DIR
#
# Idle means VmRSS unchanged over 4 samples 0.5 s apart. Needs tmux and /usr/bin/time.
set -eu
sapnet=$(realpath "$1")
dir=$(realpath "$2")
session="measure-open-$$"
out=$(mktemp -d)
tmux new-session -d -s "$session" -x 160 -y 45 \
  "/usr/bin/time -v -o $out/time $sapnet open $dir; echo exited > $out/done; sleep 30"
pid=""
while [ -z "$pid" ]; do
  if [ -e "$out/done" ]; then
    tmux capture-pane -p -t "$session"
    tmux kill-session -t "$session"
    exit 1
  fi
  sleep 0.2
  pid=$(pgrep -f -n "^$sapnet open $dir\$" || true)
done
rss() { awk '/VmRSS/ {print $2}' "/proc/$pid/status"; }
hwm() { awk '/VmHWM/ {print $2}' "/proc/$pid/status"; }
# Waits until the screen shows $1, then until the resident memory holds still.
settle() {
  waited=0
  until tmux capture-pane -p -t "$session" | grep -q "$1"; do
    sleep 0.5
    waited=$((waited + 1))
    if [ "$waited" -gt 1200 ]; then
      echo "waited 10 minutes for \"$1\"; the screen:"
      tmux capture-pane -p -t "$session"
      tmux kill-session -t "$session"
      exit 1
    fi
  done
  last=0 same=0
  while [ "$same" -lt 4 ]; do
    sleep 0.5
    now=$(rss)
    if [ "$now" = "$last" ]; then same=$((same + 1)); else same=0 last=$now; fi
  done
}
start=$(date +%s)
settle "runs finished"
echo "Runs view idle after $(( $(date +%s) - start )) s: VmRSS $(rss) KiB (peak so far $(hwm) KiB)"
tmux send-keys -t "$session" Enter
settle "read from its files"
echo "run 0's dashboard idle: VmRSS $(rss) KiB (peak so far $(hwm) KiB)"
tmux send-keys -t "$session" q
until [ -e "$out/done" ]; do sleep 0.2; done
grep -E "Maximum resident|Elapsed|Exit status" "$out/time"
tmux kill-session -t "$session"
rm -r "$out"
