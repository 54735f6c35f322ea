#!/usr/bin/python3
"""Share of the Verlet step's time in each source file, sampled by perf.

Runs sheet_steps under `perf record -e cpu-clock` (a software clock: this VM has no hardware
counters) at two step counts and subtracts the samples of each function, so the setup
cancels, as in count_flops.py; functions are mapped to the source file whose object defines
them. The force kernel's share gives its own rate: the step's rate divided by the share.
Works on any build, -march=native included.

  /usr/bin/python3 benchmarks/time_share.py build/benchmark/benchmarks/sheet_steps \\
      [--nodes 1024] [--steps 4 16] [--threads 1] [--json out.json]
"""

import argparse
import collections
import json
import os
import subprocess
import sys
import tempfile

from count_flops import symbol_sources


def samples(binary, nodes, steps, threads, workdir):
    """{(dso, source-or-symbol): samples} of one sheet_steps run, and its report."""
    data = os.path.join(workdir, f"perf.{steps}.data")
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), OMP_PROC_BIND="close")
    run = subprocess.run(["perf", "record", "-q", "-e", "cpu-clock", "-o", data, binary,
                          str(nodes), str(steps)], env=env, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"perf record of {binary} failed:\n{run.stderr[-3000:]}")
    out = subprocess.run(["perf", "report", "-i", data, "--stdio", "--no-demangle",
                          "--sort=dso,sym", "-F", "sample,dso,sym"],
                         check=True, capture_output=True, text=True).stdout
    counts = collections.Counter()
    for line in out.splitlines():
        words = line.split()
        if len(words) >= 4 and words[0].isdigit() and words[2] in ("[.]", "[k]"):
            counts[(words[1], " ".join(words[3:]))] += int(words[0])
    return counts, json.loads(run.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("binary", help="sheet_steps of the build to measure")
    parser.add_argument("--nodes", type=int, default=1024)
    parser.add_argument("--steps", type=int, nargs=2, default=[4, 16], metavar=("FEW", "MORE"))
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--build-dir", help="default: two levels above the binary")
    parser.add_argument("--json", help="write the shares here")
    args = parser.parse_args()
    if args.steps[1] <= args.steps[0]:
        parser.error("--steps: the second count must be larger")
    build_dir = args.build_dir or os.path.dirname(os.path.dirname(os.path.abspath(args.binary)))
    sources = symbol_sources(build_dir)
    binary_name = os.path.basename(args.binary)
    with tempfile.TemporaryDirectory(prefix="time_share.") as workdir:
        (few, few_report), (more, more_report) = (
            samples(args.binary, args.nodes, s, args.threads, workdir) for s in args.steps)
    by_source = collections.Counter()
    for key in set(few) | set(more):
        dso, symbol = key
        source = sources.get(symbol, "other") if dso == binary_name else dso
        by_source[source] += more[key] - few[key]
    total = sum(by_source.values())
    seconds = more_report["seconds"] - few_report["seconds"]
    node_steps = args.nodes * args.nodes * (args.steps[1] - args.steps[0])
    result = {"binary": args.binary, "nodes": args.nodes, "steps": args.steps,
              "threads": args.threads, "samples": total,
              "node_steps_per_second": node_steps / seconds,
              "share": {s: n / total for s, n in by_source.most_common()}}
    print(f"{args.binary}: {args.nodes}² sheet, {args.threads} thread(s), steps "
          f"{args.steps[0]} → {args.steps[1]}: {total} samples, "
          f"{result['node_steps_per_second']:.3e} node-steps/s")
    for source, share in result["share"].items():
        if share >= 0.001:
            print(f"  {share:7.1%}  {source}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
