#!/usr/bin/env bash
# The Verlet step before and after a kernel change: node-steps per second of bench_step at 256²,
# 1024² and 4096² on 1 and 2 threads, and of each combination of model terms (verlet_step_terms,
# 1024², 1 thread), for this build and for BEFORE, a bench_step binary built from the older
# revision with the same preset. The two binaries run alternately, each case twice, so drift of
# the machine shows in both. Results into benchmarks/results/NAME-<host>-<date>.{json,md}, NAME
# "kernel" unless RESULT_NAME says otherwise (so that a later comparison keeps an earlier one).
#   BEFORE=/path/to/old/bench_step BEFORE_REVISION=abc1234 benchmarks/run_kernel.sh
#   RESULT_NAME=kernel-fused BEFORE=... benchmarks/run_kernel.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh "${RESULT_NAME:-kernel}" benchmark bench_step
: "${BEFORE:?set BEFORE to the bench_step of the revision to compare with}"
: "${BEFORE_REVISION:=unknown}"

after=build/benchmark/benchmarks/bench_step
filters=('verlet_step/nodes:(256|1024|4096)/')
runs=()
for round in 1 2; do
  for which in before after; do
    binary=$after
    [ "$which" = before ] && binary=$BEFORE
    out="$stem-$which-$round.json"
    OMP_PROC_BIND=close "$binary" --benchmark_filter="${filters[0]}" \
      --benchmark_min_time=2 --benchmark_repetitions=1 \
      --benchmark_out="$out" --benchmark_out_format=json >/dev/null
    runs+=("$which:$out")
  done
done
terms="$stem-terms.json"
OMP_PROC_BIND=close "$after" --benchmark_filter='verlet_step_terms' --benchmark_min_time=2 \
  --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
  --benchmark_out="$terms" --benchmark_out_format=json >/dev/null
# Peak resident memory per node: the difference of two grid sizes, so that the process's own
# footprint cancels.
memory() {
  local binary=$1 nodes=$2
  /usr/bin/time -f "%M" "$binary" --benchmark_filter="verlet_step/nodes:$nodes/threads:1" \
    --benchmark_min_time=0.01 2>&1 >/dev/null | tail -1
}
mem="$(memory "$BEFORE" 1024) $(memory "$BEFORE" 2048) $(memory "$after" 1024) $(memory "$after" 2048)"

/usr/bin/python3 - "$stem" "$cpu" "$compiler" "$revision" "$date" "$BEFORE_REVISION" "$terms" \
  "$mem" "${runs[@]}" <<'PY'
import json, statistics, sys
stem, cpu, compiler, revision, date, before_revision, terms_file, mem = sys.argv[1:9]
rates, cpu_rates = {}, {}
for run in sys.argv[9:]:
    which, path = run.split(":", 1)
    for b in json.load(open(path))["benchmarks"]:
        fields = dict(p.split(":") for p in b["name"].split("/")[1:] if ":" in p)
        key = (which, int(fields["nodes"]), int(fields["threads"]))
        rates.setdefault(key, []).append(b["items_per_second"])
        # The main thread's CPU time: on one thread, the step's own time even when other work
        # shares the cores.
        cpu_rates.setdefault(key, []).append(int(fields["nodes"]) ** 2 / (b["cpu_time"] * 1e-3))
lines = [f"# The Verlet step before and after the kernel work, {date}", "",
         f"Machine: {cpu}; compiler: {compiler}, -O3 -march=native; 1 rank.",
         f"Before: git {before_revision}; after: git {revision}. `benchmarks/run_kernel.sh`: the two",
         "binaries alternately, each case twice (at least 2 s each); both runs listed.", "",
         "Rates by wall time; on one thread also by CPU time, which other work on the machine",
         "does not inflate.", "",
         "| grid | threads | before (node-steps/s) | after (node-steps/s) | speed-up | "
         "after, 2 threads over 1 | 1 thread by CPU time, before → after |",
         "|---|---|---|---|---|---|---|"]
for nodes in sorted({k[1] for k in rates}):
    for threads in (1, 2):
        b, a = rates.get(("before", nodes, threads)), rates.get(("after", nodes, threads))
        if not b or not a:
            continue
        one = statistics.median(rates[("after", nodes, 1)])
        lines.append(f"| {nodes}² | {threads} | {', '.join(f'{r:.3g}' for r in b)} | "
                     f"{', '.join(f'{r:.3g}' for r in a)} | "
                     f"{statistics.median(a) / statistics.median(b):.2f} | "
                     f"{statistics.median(a) / one:.2f} | " +
                     (f"{statistics.median(cpu_rates[('before', nodes, 1)]):.3g} → "
                      f"{statistics.median(cpu_rates[('after', nodes, 1)]):.3g} |" if threads == 1
                      else " |"))
b1, b2, a1, a2 = (float(x) * 1024 for x in mem.split())
per_node = lambda small, large: (large - small) / (2048 ** 2 - 1024 ** 2)
lines += ["", "Peak resident memory per node (difference of the 2048² and 1024² runs, "
          "`/usr/bin/time -f %M`): "
          f"before {per_node(b1, b2):.0f} B, after {per_node(a1, a2):.0f} B.", ""]
names = {1: "curvature ξ", 2: "coupling φ", 4: "damping", 8: "fluid", 16: "point loads"}
lines += ["## Each term present or absent (1024², 1 thread, after)", "",
          "Median of 3 repetitions. The flat sheet of bench_step with gravity; each term on or off.",
          "", "| terms present | node-steps/s |", "|---|---|"]
for b in json.load(open(terms_file))["benchmarks"]:
    if b.get("aggregate_name") != "median":
        continue
    mask = int(b["name"].split("terms:")[1].split("/")[0])
    present = ", ".join(n for bit, n in names.items() if mask & bit) or "none (membrane and gravity)"
    lines.append(f"| {present} | {b['items_per_second']:.3e} |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
