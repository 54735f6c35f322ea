#!/usr/bin/env bash
# The default thread count (the ThreadTuner, docs/parallel.md "Threads that fit the machine")
# against one and two threads set by hand, on an idle machine and with another program busy on
# one core (a shell loop that never sleeps): S2 (20², 10 000 steps), S6 (60², 5 000 steps), a
# 1024² sheet (60 steps) and the round tablecloth (40², 0.5 s with its solids), on 1 and 2
# ranks, REPEATS times each (default 3), interleaved. Wall time of the step loop from the run
# summary (frames included). Writes benchmarks/results/thread-load-<host>-<date>.md.
#   benchmarks/run_thread_load.sh [REPEATS]
set -euo pipefail
cd "$(dirname "$0")/.."
repeats=${1:-3}
source benchmarks/context.sh thread-load release cosserat
unset OMP_NUM_THREADS OMP_PROC_BIND OMP_PLACES OMP_WAIT_POLICY GOMP_SPINCOUNT
work=$(mktemp -d)
spinner=""
trap '[ -n "$spinner" ] && kill "$spinner" 2>/dev/null; rm -rf "$work"' EXIT
binary=build/release/cosserat
big_dt=$(/usr/bin/python3 -c "print(0.02 * (10.0 / 1023) ** 2)")
scenes=(
  "S2|scenes/s2_cape.toml|"
  "S6|scenes/s6_compression.toml|--set time.steps=5000"
  "1024²|scenes/s1_clothesline.toml|--set grid.nodes=[1024,1024] --set time.dt=$big_dt --set time.steps=60 --set time.output_every=60 --set output.fields=[]"
  "tablecloth|scenes/contact/tablecloth_round_table.toml|--set time.duration=0.5"
)
settings=("default|" "--threads 1|--threads 1" "--threads 2|--threads 2")

for repeat in $(seq "$repeats"); do
  for load in idle busy; do
    if [ "$load" = busy ]; then
      sh -c 'while :; do :; done' &
      spinner=$!
      sleep 0.5
    fi
    for entry in "${scenes[@]}"; do
      IFS='|' read -r scene file extra <<<"$entry"
      read -r -a sets <<<"$extra"
      for ranks in 1 2; do
        for setting in "${settings[@]}"; do
          IFS='|' read -r label flags <<<"$setting"
          read -r -a flag_words <<<"$flags"
          launcher=()
          [ "$ranks" = 2 ] && launcher=(mpirun --oversubscribe -np 2)
          "${launcher[@]}" "$binary" run "$file" "${sets[@]}" "${flag_words[@]}" -q \
            -o "$work/run.h5" --overwrite \
            --summary "$work/$scene~$load~$ranks~$label~$repeat.json" >/dev/null 2>&1 ||
            echo "failed: $scene $load $ranks $label" >&2
        done
      done
    done
    if [ -n "$spinner" ]; then
      kill "$spinner"
      wait "$spinner" 2>/dev/null || true
      spinner=""
    fi
  done
done

/usr/bin/python3 - "$work" "$stem" "$cpu" "$compiler" "$revision" "$date" "$repeats" <<'PY'
import glob, json, os, statistics, sys
work, stem, cpu, compiler, revision, date, repeats = sys.argv[1:]
runs = {}
for path in sorted(glob.glob(f"{work}/*.json")):
    scene, load, ranks, setting, _ = os.path.basename(path)[:-5].split("~")
    runs.setdefault((scene, int(ranks)), {}).setdefault(load, {}).setdefault(setting, []).append(
        json.load(open(path)))
lines = [f"# Threads on an idle and a busy machine, {date}", "",
         f"Machine: {cpu}, {len(os.sched_getaffinity(0))} CPUs; compiler: {compiler}, release "
         f"preset; git {revision}. Wall seconds of the run's step loop (frames included) from "
         f"the run summary, median of {repeats} runs (all runs in brackets); busy: a shell loop "
         "that never sleeps runs beside it. `default` is the ThreadTuner; its steps with 1 and "
         "2 threads (summary `thread_steps`, rank 0, first run) follow its time. Command: "
         "`benchmarks/run_thread_load.sh`.", "",
         "| scene | ranks | machine | default | default's steps at 1, 2 threads | --threads 1 | --threads 2 | default against the better |",
         "|---|---|---|---|---|---|---|---|"]
for (scene, ranks), by_load in runs.items():
    for load in ("idle", "busy"):
        cells = {}
        for setting in ("default", "--threads 1", "--threads 2"):
            rs = by_load.get(load, {}).get(setting, [])
            walls = [r["wall_seconds"] for r in rs]
            cells[setting] = (statistics.median(walls) if walls else float("nan"), walls, rs)
        best = min(cells["--threads 1"][0], cells["--threads 2"][0])
        fmt = lambda c: f"{c[0]:.3g} ({', '.join(f'{w:.3g}' for w in c[1])})"
        steps = cells["default"][2][0].get("thread_steps") if cells["default"][2] else None
        lines.append(f"| {scene} | {ranks} | {load} | {fmt(cells['default'])} | {steps} | "
                     f"{fmt(cells['--threads 1'])} | {fmt(cells['--threads 2'])} | "
                     f"{cells['default'][0] / best:.2f} × |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
