"""A results folder whose episodes.csv.xz is an xz bomb: about 230 KB that decompress to
1.5 GiB of one row repeated, every row episode 1 of run 0 (issue 52: refused by `plot`
and `open` within 600 MB of peak memory). The row is a shipped folder's shortest
(`0,sapnet,1,9.0,9,`), so a reader meets its bound on the values it keeps (2^25) before
the bound on what it decompresses (1 GiB).

    python3 scripts/hostile/xz_bomb.py OUT                      # shipped layout
    python3 scripts/hostile/xz_bomb.py OUT --layout records --sapnet target/release/sapnet
    python3 scripts/hostile/xz_bomb.py OUT --gib 0.1            # a scaled-down bomb
    python3 scripts/hostile/xz_bomb.py OUT --plain [--numbered] # what the reader keeps
                                                                 # without the xz dictionary
                                                                 # (and without a sort index)

then, e.g.: /usr/bin/time -v target/release/sapnet plot OUT (and `open OUT`: refused
before its screen opens), reading "Maximum resident set size".
"""

import argparse
import os

import folders

parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
parser.add_argument("out", help="the folder to make (must not exist)")
parser.add_argument("--gib", type=float, default=1.5, help="decompressed size, GiB")
parser.add_argument("--layout", choices=["shipped", "records"], default="shipped")
parser.add_argument("--sapnet", help="the binary that makes a records folder")
parser.add_argument("--plain", action="store_true", help="episodes.csv uncompressed (no dictionary)")
parser.add_argument(
    "--numbered", action="store_true", help="episodes 1, 2, 3… (no sort index), not all 1"
)
args = parser.parse_args()

total = int(args.gib * (1 << 30))
if args.layout == "shipped":
    folders.shipped(args.out, runs=1, episodes=5000)
    header, row = "run,method,episode,reward,steps,policy\n", "0,sapnet,1,9.0,9,\n"
    target = os.path.join(args.out, "episodes.csv.xz")
else:
    if not args.sapnet:
        parser.error("--layout records needs --sapnet")
    run = folders.records(args.out, args.sapnet, runs=1, episodes=5000)[0]
    header, row = folders.RUN_HEADER, "0,dqn[16],1,9.0,9,,,,,0\n"
    target = os.path.join(run, "episodes.csv.xz")


def chunks():
    yield header
    block = row * ((1 << 20) // len(row))
    written, episode = len(header), 1
    while written < total:
        if args.numbered:
            lines = [row.replace(",1,", f",{e},", 1) for e in range(episode, episode + 40_000)]
            episode += len(lines)
            block = "".join(lines)
        piece = block[: total - written]
        written += len(piece)
        yield piece


if args.plain:
    target = target[: -len(".xz")]
    with open(target, "w") as f:
        for chunk in chunks():
            f.write(chunk)
else:
    folders.xz(target, chunks())
print(f"{target}: {os.path.getsize(target)} bytes, {total} decompressed")
