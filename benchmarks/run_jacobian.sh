#!/usr/bin/env bash
# The exact Jacobian's node Hessians per node (bench_jacobian) against one force evaluation, on
# a bent 120² sheet, one thread, in the release preset's portable build that `cosserat` runs as,
# into benchmarks/results/jacobian-<host>-<date>.{json,md} with the machine, compiler, git
# revision and date. The Jacobian's whole cost, with the PETSc insertion, is the run summary's
# "Jacobian" time (docs/semi-implicit.md, "The Jacobian").
#   benchmarks/run_jacobian.sh [extra Google Benchmark flags]
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh jacobian release bench_jacobian

run_step_benchmark build/release/benchmarks/bench_jacobian "$@"

/usr/bin/python3 - "$stem" "$cpu" "$compiler" "$revision" "$date" <<'PY'
import json, sys
stem, cpu, compiler, revision, date = sys.argv[1:]
runs = [b for b in json.load(open(stem + ".json"))["benchmarks"] if b.get("aggregate_name") == "median"]
lines = [f"# The exact Jacobian's node Hessians, {date}", "",
         f"Machine: {cpu}; compiler: {compiler}, release preset (portable -O3); git {revision};",
         "1 rank x 1 thread. Median of 3 repetitions (`benchmarks/run_jacobian.sh`).", "",
         "| benchmark | µs a node |", "|---|---|"]
for b in runs:
    lines.append(f"| {b['run_name']} | {1e6 / b['items_per_second']:.3f} |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
