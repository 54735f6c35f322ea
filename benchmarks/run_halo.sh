#!/usr/bin/env bash
# Time of one halo exchange (bench_halo) on 256², 1024², 4096² grids split over 2 and 4 ranks
# (4 oversubscribed on a 2-core machine: then it measures the scheduler as much as MPI), into
# benchmarks/results/halo-<host>-<date>.{json,md} with the machine, compiler, git revision and
# date.
#   benchmarks/run_halo.sh [RANKS...]   (default: 2 4)
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh halo benchmark bench_halo
cores=$(nproc)
: > "$stem.jsonl"
for ranks in "${@:-2 4}"; do
  for p in $ranks; do
    bind=(--bind-to core)
    if (( p > cores )); then bind=(--oversubscribe --bind-to none); fi
    mpirun -np "$p" "${bind[@]}" build/benchmark/benchmarks/bench_halo >> "$stem.jsonl"
  done
done

/usr/bin/python3 - "$stem" "$cpu" "$compiler" "$revision" "$date" "$cores" <<'PY'
import json, sys
stem, cpu, compiler, revision, date, cores = sys.argv[1:]
rows = [json.loads(line) for line in open(stem + ".jsonl") if line.strip()]
json.dump({"date": date, "cpu": cpu, "cores": int(cores), "compiler": compiler, "git": revision,
           "results": rows}, open(stem + ".json", "w"), indent=1)
lines = [f"# Halo exchange, {date}", "",
         f"Machine: {cpu}, {cores} cores; compiler: {compiler}, -O3 -march=native; git {revision}.",
         "One exchange of a position field, two ghost rings, the split the solver chooses; median "
         "of 7 batches of 200 (slowest rank), min and max batch (`benchmarks/run_halo.sh`).", "",
         "| grid | ranks | split | bytes received (busiest rank) | µs per exchange | min–max |",
         "|---|---|---|---|---|---|"]
for r in rows:
    lines.append(f"| {r['nodes']}² | {r['ranks']}{' (oversubscribed)' if r['ranks'] > int(cores) else ''} | "
                 f"{r['split'][0]} x {r['split'][1]} | {r['received_bytes']} | "
                 f"{1e6 * r['exchange_seconds']:.1f} | {1e6 * r['min_seconds']:.1f}–{1e6 * r['max_seconds']:.1f} |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
rm -f "$stem.jsonl"
