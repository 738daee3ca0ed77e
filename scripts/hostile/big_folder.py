"""A results folder within every bound whose runs hold 24 M episode rows in all (3 runs of
8 M episodes; issue 52: `sapnet open` on it, and Enter on a run, within the ceiling of the
data shown plus 256 MB). Each episode's length cycles through 10..499 steps (its return
the same, as CartPole's), so the curves are not flat.

    python3 scripts/hostile/big_folder.py OUT                     # shipped layout
    python3 scripts/hostile/big_folder.py OUT --layout records --sapnet target/release/sapnet
    python3 scripts/hostile/big_folder.py OUT --episodes 800000   # scaled down

The shipped layout's episodes.csv is plain text (about 24 bytes a row); `--xz` writes it
as docs/ ships it. Measured as in docs/dev/reliability.md.
"""

import argparse
import os

import folders

parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
parser.add_argument("out", help="the folder to make (must not exist)")
parser.add_argument("--runs", type=int, default=3)
parser.add_argument("--episodes", type=int, default=8_000_000, help="per run")
parser.add_argument("--layout", choices=["shipped", "records"], default="shipped")
parser.add_argument("--sapnet", help="the binary that makes a records folder")
parser.add_argument("--xz", action="store_true", help="write episodes.csv.xz instead")
args = parser.parse_args()


steps = {}


def rows(run, method, fields):
    """Run `run`'s rows, a mebibyte or so at a time (its steps counted in `steps`)."""
    lines = []
    steps[run] = 0
    for episode in range(1, args.episodes + 1):
        length = 10 + (episode * 7919 + run * 104729) % 490
        steps[run] += length
        lines.append(fields(run, method, episode, length))
        if len(lines) == 40_000:
            yield "".join(lines)
            lines = []
    yield "".join(lines)


def write(path, header, parts):
    if args.xz:
        folders.xz(path + ".xz", (p for part in [[header]] + parts for p in part))
    else:
        with open(path, "w") as f:
            f.write(header)
            for part in parts:
                for chunk in part:
                    f.write(chunk)


if args.layout == "shipped":
    folders.shipped(args.out, args.runs, args.episodes)
    short = lambda r, m, e, l: f"{r},{m},{e},{l}.0,{l},\n"
    write(
        os.path.join(args.out, "episodes.csv"),
        "run,method,episode,reward,steps,policy\n",
        [rows(run, "sapnet", short) for run in range(args.runs)],
    )
else:
    if not args.sapnet:
        parser.error("--layout records needs --sapnet")
    dirs = folders.records(args.out, args.sapnet, args.runs, args.episodes)
    full = lambda r, m, e, l: f"{r},{m},{e},{l}.0,{l},0.5,0.0,0.05,,{e * 0.01:.2f}\n"
    for run, d in enumerate(dirs):
        write(os.path.join(d, "episodes.csv"), folders.RUN_HEADER, [rows(run, "dqn[16]", full)])
        folders.set_steps(d, steps[run])
print(f"{args.out}: {args.runs} runs of {args.episodes} episodes ({args.layout})")
