#!/usr/bin/env bash
# Node-steps per second of one Verlet step (bench_step) on 256², 1024², 2048², 4096² with 1 and 2
# threads, into benchmarks/results/throughput-<host>-<date>.{json,md} with the machine,
# compiler, git revision, ranks x threads and date beside every number.
#   benchmarks/run_throughput.sh [extra Google Benchmark flags]
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh throughput benchmark bench_step

run_step_benchmark build/benchmark/benchmarks/bench_step --benchmark_filter='verlet_step/' "$@"

/usr/bin/python3 - "$stem" "$cpu" "$compiler" "$revision" "$date" <<'PY'
import json, sys
stem, cpu, compiler, revision, date = sys.argv[1:]
runs = [b for b in json.load(open(stem + ".json"))["benchmarks"] if b.get("aggregate_name") == "median"]
rate = {(int(b["name"].split("nodes:")[1].split("/")[0]), int(b["threads"])): b["items_per_second"] for b in runs}
lines = [f"# Verlet step throughput, {date}", "",
         f"Machine: {cpu}; compiler: {compiler}, -O3 -march=native; git {revision}; 1 rank.",
         "Median of 3 repetitions of at least 2 s each (`benchmarks/run_throughput.sh`).", "",
         "| grid | threads | node-steps/s | speed-up over 1 thread |", "|---|---|---|---|"]
for (nodes, threads), r in sorted(rate.items()):
    lines.append(f"| {nodes}² | {threads} | {r:.3e} | {r / rate[(nodes, 1)]:.2f} |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
