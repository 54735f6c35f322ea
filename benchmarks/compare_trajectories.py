#!/usr/bin/python3
"""Runs scenes with two builds of cosserat and reports how far their trajectories part: the
largest difference of any node position in any frame, relative to the largest displacement
from the first frame. A kernel change that only reorders sums must stay at round-off.

A scene that amplifies round-off (a flag flapping in a steady wind, a sheet sliding off an
edge) parts at round-off too, so beside each scene the old build is run again with the sheet
moved by 1e-12 m, which is the yardstick: a change at round-off parts the trajectories no more
than that.

  benchmarks/compare_trajectories.py OLD_BINARY NEW_BINARY SCENE.toml [...] [--set KEY=VALUE]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import tomllib

import h5py
import numpy as np


def run(binary, scene, out, overrides):
    command = [binary, "run", scene, "-o", out] + [a for o in overrides for a in ("--set", o)]
    env = dict(os.environ, OMP_NUM_THREADS="1")
    result = subprocess.run(command, capture_output=True, text=True, env=env)
    if result.returncode not in (0, 3):
        sys.exit(f"{' '.join(command)} failed ({result.returncode}):\n{result.stderr}")
    return result.returncode


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("scenes", nargs="+")
    parser.add_argument("--set", action="append", default=[], dest="overrides")
    args = parser.parse_args()
    print("| scene | frames | largest displacement (m) | old vs new (m) | relative | "
          "old vs old moved 1e-12 m (m) | relative |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        for scene in args.scenes:
            name = os.path.splitext(os.path.basename(scene))[0]
            files = [os.path.join(work, f"{name}-{tag}.h5") for tag in ("old", "new", "moved")]
            with open(scene, "rb") as f:
                origin = tomllib.load(f).get("grid", {}).get("origin", [0.0, 0.0, 0.0])
            shift = 1e-12
            moved = f"grid.origin=[{origin[0] + shift!r},{origin[1]!r},{origin[2]!r}]"
            codes = [run(args.old, scene, files[0], args.overrides),
                     run(args.new, scene, files[1], args.overrides),
                     run(args.old, scene, files[2], args.overrides + [moved])]
            positions = []
            for file in files:
                with h5py.File(file) as h:
                    positions.append(h["positions"][...])
            frames = min(len(p) for p in positions)
            old, new, again = (p[:frames] for p in positions)
            again[..., 0] -= (origin[0] + shift) - origin[0]
            displacement = np.abs(old - old[0]).max()
            difference = np.abs(old - new).max()
            yardstick = np.abs(old - again).max()
            status = "" if codes == [0, 0, 0] else f" (exit {', '.join(map(str, codes))})"
            print(f"| {name}{status} | {frames} | {displacement:.3g} | {difference:.3g} | "
                  f"{difference / displacement:.2e} | {yardstick:.3g} | "
                  f"{yardstick / displacement:.2e} |", flush=True)


if __name__ == "__main__":
    main()
