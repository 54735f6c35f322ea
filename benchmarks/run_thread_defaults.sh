#!/usr/bin/env bash
# The thread count a user gets by default against the best one set by hand (docs/parallel.md,
# "Threads per rank"): S2 (20², 10 000 steps), S6 (60², 20 000 steps) and an S1-like 1024²
# sheet (200 steps) as shipped, frames included, on 1 and 2 ranks, REPEATS times each
# (default 3). Each layout is run
#   - as a user runs it, OMP_NUM_THREADS unset, no binding flags: `cosserat run` alone,
#     `mpirun -np 1` and `mpirun -np 2` (Open MPI binds each of one or two ranks to a core);
#   - with the threads set by hand and each rank bound to its own cores
#     (`--map-by slot:PE=T --bind-to core`), for every T that fits the machine's cores.
# Writes benchmarks/results/thread-defaults-<host>-<date>.{json,md} with the machine, compiler,
# git revision and date.
#   benchmarks/run_thread_defaults.sh [REPEATS]
set -euo pipefail
cd "$(dirname "$0")/.."
repeats=${1:-3}
source benchmarks/context.sh thread-defaults release cosserat
unset OMP_NUM_THREADS OMP_PROC_BIND OMP_PLACES
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cores=$(nproc)
binary=build/release/cosserat

# scene name, scene file, extra --set flags. The 1024² sheet's step is S1's scaled with h²
# (docs/equations.md §4.2), 0.02 h², well inside Verlet's limit.
big_dt=$(/usr/bin/python3 -c "print(0.02 * (10.0 / 1023) ** 2)")
scenes=(
  "S2|scenes/s2_cape.toml|"
  "S6|scenes/s6_compression.toml|"
  "1024²|scenes/s1_clothesline.toml|--set grid.nodes=[1024,1024] --set time.dt=$big_dt --set time.steps=200 --set time.output_every=100"
)

run() {  # label, summary name, then the command
  local label=$1 name=$2
  shift 2
  "$@" -q -o "$work/run.h5" --overwrite --summary "$work/$name.json" >/dev/null 2>&1 ||
    echo "failed: $label" >&2
}

for entry in "${scenes[@]}"; do
  IFS='|' read -r scene file extra <<<"$entry"
  read -r -a sets <<<"$extra"
  for repeat in $(seq "$repeats"); do
    run "$scene default, no mpirun" "$scene~1~default (no mpirun)~$repeat" \
      "$binary" run "$file" "${sets[@]}"
    for ranks in 1 2; do
      run "$scene default, $ranks ranks" "$scene~$ranks~default (mpirun -np $ranks)~$repeat" \
        mpirun -np "$ranks" "$binary" run "$file" "${sets[@]}"
      for threads in $(seq $((cores / ranks))); do
        run "$scene $ranks x $threads" "$scene~$ranks~--threads $threads, bound~$repeat" \
          mpirun -np "$ranks" --map-by "slot:PE=$threads" --bind-to core \
          "$binary" run "$file" "${sets[@]}" --threads "$threads"
      done
    done
  done
done

/usr/bin/python3 - "$work" "$stem" "$cpu" "$compiler" "$revision" "$date" "$repeats" <<'PY'
import glob, json, statistics, sys
work, stem, cpu, compiler, revision, date, repeats = sys.argv[1:]
runs = {}
for path in sorted(glob.glob(f"{work}/*.json")):
    scene, ranks, setting, _ = path.rsplit("/", 1)[1][:-5].split("~")
    runs.setdefault(scene, {}).setdefault(int(ranks), {}).setdefault(setting, []).append(
        json.load(open(path)))
json.dump({"date": date, "cpu": cpu, "compiler": compiler, "git": revision, "runs": runs},
          open(stem + ".json", "w"), indent=1)
lines = [f"# Default thread count against the best set by hand, {date}", "",
         f"Machine: {cpu}, {len(__import__('os').sched_getaffinity(0))} CPUs; compiler: {compiler}, "
         f"release preset (-O3); git {revision}.",
         "Whole `cosserat run` of the shipped scene (frames included), node-steps/s from the "
         f"run summary, median of {repeats} runs (`benchmarks/run_thread_defaults.sh`).", "",
         "| scene | ranks | setting | threads per rank | node-steps/s (median) | all runs | of the best |",
         "|---|---|---|---|---|---|---|"]
for scene, by_ranks in runs.items():
    best = max(statistics.median(r["node_steps_per_second"] for r in rs)
               for settings in by_ranks.values() for rs in settings.values())
    for ranks, settings in sorted(by_ranks.items()):
        for setting, rs in settings.items():
            rate = statistics.median(r["node_steps_per_second"] for r in rs)
            every = ", ".join(f"{r['node_steps_per_second']:.3g}" for r in rs)
            lines.append(f"| {scene} | {ranks} | {setting} | {rs[0]['threads']} | {rate:.3e} | "
                         f"{every} | {100 * rate / best:.0f} % |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
