"""What the hostile-folder generators share: a results folder as sapnet writes it, in
either of the two layouts `sapnet open` and `plot` read.

- shipped: `summary.json` and the top-level `episodes.csv` (or `.xz`), no run records:
  docs/cartpole's summary, its config cut to `runs` SAP-Net runs of `episodes` episodes.
- records: a real finished protocol (DQN, a few seconds, made by the sapnet binary
  given) whose run records `runs/<run>/` are then given other episodes.

Only the standard library.
"""

import json
import os
import shutil
import subprocess
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# The header the training writes into each run's episodes.csv (src/results/files.rs).
RUN_HEADER = "run,method,episode,reward,steps,loss,statistic_loss,epsilon,policy,wall_s\n"


def shipped(out, runs, episodes):
    """A shipped folder in `out` from docs/cartpole's summary.json: SAP-Net's first `runs`
    runs, each said to have `episodes` episodes. The caller writes episodes.csv(.xz)."""
    os.makedirs(out)
    with open(os.path.join(REPO, "docs/cartpole/summary.json")) as f:
        summary = json.load(f)
    summary["config"]["protocol"]["runs"] = runs
    summary["config"]["protocol"]["episodes"] = episodes
    summary["config"]["protocol"]["methods"] = ["SapNet"]
    listed = [r for r in summary["runs"] if r["method"] == "sapnet"][:runs]
    for r in listed:
        r["episodes"] = episodes
    summary["runs"] = listed
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(summary, f)
    shutil.copy(os.path.join(REPO, "docs/cartpole/tests.csv"), out)


def records(out, sapnet, runs, episodes):
    """A finished DQN protocol of `runs` runs in `out`, made by `sapnet`, each run's record
    then said to have `episodes` episodes; returns the run folders, in run order. The
    caller writes each one's episodes.csv(.xz) (the one there is removed)."""
    with tempfile.TemporaryDirectory() as tmp:
        config = os.path.join(tmp, "config.ron")
        with open(config, "w") as f:
            f.write(
                "(env: CartPole(), dqn: (replay_start_size: 50, target_update_interval: 100),"
                f" protocol: (episodes: 30, runs: {runs}, test_episodes: 2,"
                " methods: [Dqn(hidden: [16])]), seed: 0)"
            )
        subprocess.run(
            [sapnet, "--headless", "--config", config, "--out", out],
            check=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    path = os.path.join(out, "summary.json")
    with open(path) as f:
        summary = json.load(f)
    summary["config"]["protocol"]["budget"] = {"Episodes": episodes}
    for r in summary["runs"]:
        r["episodes"] = episodes
    with open(path, "w") as f:
        json.dump(summary, f)
    dirs = []
    for run in range(runs):
        d = os.path.join(out, "runs", f"dqn-16-run{run}")
        with open(os.path.join(d, "run.json")) as f:
            record = json.load(f)
        record["episodes"] = episodes
        with open(os.path.join(d, "run.json"), "w") as f:
            json.dump(record, f)
        os.remove(os.path.join(d, "episodes.csv"))
        dirs.append(d)
    # The top-level copy is put together from the records; `plot` makes it again.
    os.remove(os.path.join(out, "episodes.csv"))
    return dirs


def set_steps(run_dir, steps):
    """Run `run_dir`'s record said to have trained `steps` steps (its episodes' lengths)."""
    path = os.path.join(run_dir, "run.json")
    with open(path) as f:
        record = json.load(f)
    record["steps"] = steps
    with open(path, "w") as f:
        json.dump(record, f)


def xz(path, chunks):
    """`path` written as `xz -9` of the text `chunks` yields (the `xz` command: its
    dictionary is what a bomb made with it declares)."""
    with open(path, "wb") as f:
        xz = subprocess.Popen(["xz", "-9", "-T1", "-c"], stdin=subprocess.PIPE, stdout=f)
        for chunk in chunks:
            xz.stdin.write(chunk.encode())
        xz.stdin.close()
        if xz.wait() != 0:
            raise SystemExit("xz failed")
