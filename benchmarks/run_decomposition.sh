#!/usr/bin/env bash
# Ranks against threads on one machine: the whole `cosserat run` of an S1-like sheet of
# NODES² nodes (default 1024) for STEPS Verlet steps (default 200) as 1 rank x 1 thread,
# 1 rank x 2 threads and 2 ranks x 1 thread, REPEATS times each (default 3), recording
# node-steps/s and the time spent in halo exchange (the largest over the ranks) from each run
# summary. Writes benchmarks/results/decomposition-<host>-<date>.{json,md} with the machine,
# compiler, git revision and date.
#   benchmarks/run_decomposition.sh [NODES] [STEPS] [REPEATS]
set -euo pipefail
cd "$(dirname "$0")/.."
nodes=${1:-1024}
steps=${2:-200}
repeats=${3:-3}
source benchmarks/context.sh decomposition release cosserat
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The step S1's Verlet survives on this grid: the stable step shrinks with h² (docs/equations.md
# §4.2); 0.02 h² is well inside it. One frame at the start and one at the end.
dt=$(/usr/bin/python3 -c "print(0.02 * (10.0 / ($nodes - 1)) ** 2)")
for layout in 1x1 1x2 2x1; do
  ranks=${layout%x*}
  threads=${layout#*x}
  for repeat in $(seq "$repeats"); do
    # Each rank bound to its own `threads` cores and its threads to those: with OMP_PROC_BIND
    # alone, every rank's first thread would be pinned to core 0.
    OMP_NUM_THREADS=$threads OMP_PROC_BIND=close OMP_PLACES=cores \
      mpirun -np "$ranks" --map-by "slot:PE=$threads" --bind-to core \
      build/release/cosserat run scenes/s1_clothesline.toml -q \
      --set "grid.nodes=[$nodes,$nodes]" --set "time.dt=$dt" --set "time.steps=$steps" \
      --set "time.output_every=$steps" -o "$work/run.h5" --overwrite \
      --summary "$work/$layout-$repeat.json"
  done
done

/usr/bin/python3 - "$work" "$stem" "$cpu" "$compiler" "$revision" "$date" "$nodes" "$steps" <<'PY'
import glob, json, statistics, sys
work, stem, cpu, compiler, revision, date, nodes, steps = sys.argv[1:]
runs = {}
for path in sorted(glob.glob(f"{work}/*.json")):
    layout = path.rsplit("/", 1)[1].split("-")[0]
    runs.setdefault(layout, []).append(json.load(open(path)))
result = {"date": date, "cpu": cpu, "compiler": compiler, "git": revision, "nodes": int(nodes),
          "steps": int(steps), "runs": runs}
json.dump(result, open(stem + ".json", "w"), indent=1)
lines = [f"# Ranks against threads, {nodes}² S1-like sheet, {steps} Verlet steps, {date}", "",
         f"Machine: {cpu}; compiler: {compiler}, release preset (-O3); git {revision}.",
         "Whole `cosserat run` loop (steps and the final frame), median over "
         f"{len(next(iter(runs.values())))} runs (`benchmarks/run_decomposition.sh`).", "",
         "| ranks x threads | split | node-steps/s (median) | all runs | halo exchange, % of wall |",
         "|---|---|---|---|---|"]
for layout in ("1x1", "1x2", "2x1"):
    rs = runs.get(layout, [])
    if not rs:
        continue
    rate = statistics.median(r["node_steps_per_second"] for r in rs)
    halo = statistics.median(100 * r["halo_seconds"] / r["wall_seconds"] for r in rs)
    split = "x".join(str(p) for p in rs[0]["split"])
    every = ", ".join(f"{r['node_steps_per_second']:.3g}" for r in rs)
    lines.append(f"| {layout.replace('x', ' x ')} | {split} | {rate:.3e} | {every} | {halo:.2f} |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
