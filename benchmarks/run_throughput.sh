#!/usr/bin/env bash
# Node-steps per second of one Verlet step (bench_step) on 256², 1024², 2048², 4096² with 1 and 2
# threads, into benchmarks/results/NAME-<host>-<date>.{json,md} (NAME "throughput" unless
# RESULT_NAME says otherwise) with the machine, compiler, git revision, ranks x threads and date
# beside every number, and against the force kernel's targets (docs/kernel.md: 4 × 10⁷
# node-steps/s on one core, 1.9 times that on two).
# REPETITIONS runs of each case (default 3), interleaved in random order so that a VM's drift
# falls on every case alike; the median of each is reported.
#   benchmarks/run_throughput.sh [extra Google Benchmark flags]
#   REPETITIONS=7 benchmarks/run_throughput.sh
#   RESULT_NAME=throughput-balance benchmarks/run_throughput.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh "${RESULT_NAME:-throughput}" benchmark bench_step

run_step_benchmark build/benchmark/benchmarks/bench_step --benchmark_filter='verlet_step/' \
  --benchmark_repetitions="${REPETITIONS:-3}" --benchmark_enable_random_interleaving=true "$@"

/usr/bin/python3 - "$stem" "$cpu" "$compiler" "$revision" "$date" <<'PY'
import json, sys
stem, cpu, compiler, revision, date = sys.argv[1:]
runs = [b for b in json.load(open(stem + ".json"))["benchmarks"] if b.get("aggregate_name") == "median"]
repetitions = runs[0]["repetitions"]
rate = {(int(b["name"].split("nodes:")[1].split("/")[0]), int(b["threads"])): b["items_per_second"] for b in runs}
lines = [f"# Verlet step throughput, {date}", "",
         f"Machine: {cpu}; compiler: {compiler}, -O3 -march=native; git {revision}; 1 rank.",
         f"Median of {repetitions} repetitions of at least 2 s each, interleaved in random order",
         "(`benchmarks/run_throughput.sh`). Targets: 4 × 10⁷ node-steps/s on one core, 1.9 times",
         "that on two.", "",
         "| grid | threads | node-steps/s | speed-up over 1 thread | target |", "|---|---|---|---|---|"]
for (nodes, threads), r in sorted(rate.items()):
    speed_up = r / rate[(nodes, 1)]
    met = r >= 4e7 if threads == 1 else speed_up >= 1.9 if threads == 2 else None
    lines.append(f"| {nodes}² | {threads} | {r:.3e} | {speed_up:.2f} | "
                 f"{'' if met is None else 'met' if met else 'missed'} |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
