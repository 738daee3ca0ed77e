#!/usr/bin/env python3
"""The workbench's budget (issue 36, item 7), measured side by side on one config.

For each of --pairs rounds, interleaved in one sitting:
  1. `sapnet --headless --jobs J --config C [--quick] --out A`;
  2. `sapnet --jobs J --config C [--quick] --out B`: the protocol run in the UI, in a tmux
     pane of 120x40 left on the Run view (the dashboard of the followed run, drawn 30 times
     a second), until its summary.json says `complete`; then `q`.
Training throughput is each folder's steps (the `steps` column of episodes.csv, summed)
over its summary.json's `wall_s` (the protocol's time, the same clock on both sides);
their ratio is the UI's share of headless's.

While the UI's protocol trains, the UI thread's CPU is read from
/proc/PID/task/PID/stat (utime + stime: the UI loop runs on the process's main thread)
over the protocol's time, as a share of one core; and --keys times, once two jobs
train, a key is answered: `c` and `r` switch between the Comparison and the Runs view,
and the time from `tmux send-keys` until `tmux capture-pane` shows the other view is the
latency (capture-pane's own few ms included: an upper bound).

    python3 benches/workbench_budget.py --config assets/reuse_cartpole.ron --quick
"""

import argparse
import csv
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TICKS = os.sysconf("SC_CLK_TCK")


def steps_per_second(out):
    with open(os.path.join(out, "episodes.csv")) as f:
        steps = sum(int(row["steps"]) for row in csv.DictReader(f))
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    assert summary["status"] == "complete", summary["status"]
    return steps, summary["wall_s"]


def status(out):
    try:
        with open(os.path.join(out, "summary.json")) as f:
            return json.load(f)["status"]
    except (OSError, ValueError, KeyError):
        return None


def thread_cpu_s(pid):
    """utime + stime of the process's main thread, in seconds."""
    with open(f"/proc/{pid}/task/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    # After the command's name: state is field 3; utime and stime are fields 14 and 15.
    return (int(fields[11]) + int(fields[12])) / TICKS


def tmux(*args, check=True):
    return subprocess.run(["tmux", *args], check=check, capture_output=True, text=True).stdout


def pane(session):
    return tmux("capture-pane", "-p", "-t", session)


def headless(binary, args, out):
    started = time.monotonic()
    subprocess.run(
        [binary, "--headless", *args, "--out", out],
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    return time.monotonic() - started


def ui(binary, args, out, session, keys):
    command = " ".join([binary, *args, "--out", out]) + "; sleep 30"
    tmux("new-session", "-d", "-s", session, "-x", "120", "-y", "40", command)
    try:
        pid = None
        while pid is None:
            found = subprocess.run(
                ["pgrep", "-f", "-x", " ".join([binary, *args, "--out", out])],
                capture_output=True,
                text=True,
            ).stdout.split()
            pid = int(found[0]) if found else None
            time.sleep(0.05)
        while status(out) != "running":
            time.sleep(0.05)
        cpu0, wall0 = thread_cpu_s(pid), time.monotonic()
        latencies = []
        # Keys once two jobs train (the library loaded, the first runs started).
        time.sleep(2.0)
        tmux("send-keys", "-t", session, "r")
        time.sleep(1.0)
        # `?` lays the keys over the Runs view, any key takes them off: each is timed.
        shown = "every planned run, its status"
        for k in range(keys):
            if status(out) != "running":
                break
            sent = time.monotonic()
            tmux("send-keys", "-t", session, "?")
            while (shown in pane(session)) == (k % 2 == 1):
                if time.monotonic() - sent > 2.0:
                    raise SystemExit(f"no answer to key {k} in 2 s:\n{pane(session)}")
            latencies.append(time.monotonic() - sent)
            time.sleep(0.3)
        # Back to the Run view for the rest of the protocol: the dashboard at 30 frames/s.
        tmux("send-keys", "-t", session, "f")
        cpu_mid, wall_mid = thread_cpu_s(pid), time.monotonic()
        while status(out) == "running":
            time.sleep(0.2)
            try:
                cpu_mid_last = thread_cpu_s(pid)
            except OSError:
                break
            wall_mid_last = time.monotonic()
        tmux("send-keys", "-t", session, "q")
        cpu_share = (cpu_mid_last - cpu0) / (wall_mid_last - wall0)
        run_view_share = (cpu_mid_last - cpu_mid) / max(wall_mid_last - wall_mid, 1e-9)
        return cpu_share, run_view_share, latencies
    finally:
        time.sleep(1.0)
        tmux("kill-session", "-t", session, check=False)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--config", default="assets/reuse_cartpole.ron")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--jobs", default="2")
    parser.add_argument("--pairs", type=int, default=2)
    parser.add_argument("--keys", type=int, default=20)
    parser.add_argument("--binary", default=os.path.join(ROOT, "target/release/sapnet"))
    opts = parser.parse_args()
    args = ["--jobs", opts.jobs, "--config", opts.config] + (["--quick"] if opts.quick else [])
    tmp = tempfile.mkdtemp(prefix="workbench-budget-")
    rows = []
    try:
        for k in range(opts.pairs):
            a, b = os.path.join(tmp, f"headless{k}"), os.path.join(tmp, f"ui{k}")
            headless(opts.binary, args, a)
            cpu, run_cpu, latencies = ui(
                opts.binary, args, b, f"workbench-budget-{os.getpid()}-{k}", opts.keys
            )
            (sa, wa), (sb, wb) = steps_per_second(a), steps_per_second(b)
            same = all(
                open(os.path.join(a, f), "rb").read() == open(os.path.join(b, f), "rb").read()
                for f in ["comparison.csv", "improvement.csv", "scores.csv"]
            )
            rows.append((sa / wa, sb / wb, cpu, run_cpu, latencies, same))
            print(
                f"pair {k}: headless {sa / wa:,.0f} steps/s ({sa:,} steps in {wa:.1f} s), "
                f"UI {sb / wb:,.0f} steps/s ({sb:,} steps in {wb:.1f} s), "
                f"ratio {(sb / wb) / (sa / wa):.1%}; UI thread {cpu:.1%} of a core "
                f"({run_cpu:.1%} on the Run view); keys median "
                f"{statistics.median(latencies) * 1000:.0f} ms, max "
                f"{max(latencies) * 1000:.0f} ms over {len(latencies)}; "
                f"comparison/improvement/scores identical: {same}",
                flush=True,
            )
        h = statistics.mean(r[0] for r in rows)
        u = statistics.mean(r[1] for r in rows)
        lat = [x for r in rows for x in r[4]]
        print(
            f"mean: headless {h:,.0f} steps/s, UI {u:,.0f} steps/s, ratio {u / h:.1%}; "
            f"UI thread {statistics.mean(r[2] for r in rows):.1%} of a core; keys median "
            f"{statistics.median(lat) * 1000:.0f} ms, max {max(lat) * 1000:.0f} ms"
        )
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
