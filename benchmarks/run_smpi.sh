#!/usr/bin/env bash
# Strong and weak scaling of the S1-like sheet on a simulated 1024-node cluster: the solver's
# own step loop under SimGrid's SMPI (benchmarks/smpi; docs/parallel.md, "Simulated clusters").
#   benchmarks/run_smpi.sh
# Settings, from the environment:
#   STUDIES      of weak-256, weak-1024 (nodes a rank), strong-4096, strong-16384 (nodes in all)
#                (default "weak-256 strong-4096 weak-1024")
#   RANKS        rank counts of weak-256 and strong-4096   (default "1 4 16 64 256 1024")
#   LARGE_RANKS  rank counts of weak-1024 and strong-16384 (default "1 4 16 64")
#   STEPS        timed steps a run, after one more          (default 2)
#   CALIBRATION  a calibration CSV of an earlier run to use instead of calibrating again
#   APPEND       1: add the runs to the studies' logs of the day instead of starting them afresh
# The simulation runs every rank's steps on this machine, one after another, on folded memory:
# about 0.9 us a node to build a run and 0.2 us a node-step, so 1024² a rank on 1024 ranks
# took an hour here beside other work, and each rank count of strong-16384 10-15 minutes.
# 1. Builds benchmarks/smpi with smpicxx (Debian: libsimgrid-dev, simgrid) into build/smpi.
# 2. Calibrates: the one-core step of a B x B block, B = 128 ... 4096, timed on this machine (one
#    simulated rank computing for real), as ns a node-step.
# 3. Runs each study on benchmarks/smpi/fat_tree_1024.xml, one rank a node. The fields are
#    folded (--fold) and each step's computation is the calibrated time of the rank's block
#    (--compute-ns, interpolated in B; past 4096 the 4096 figure, where the block streams from
#    memory); the halo exchanges and reductions are the solver's own, timed by the simulation.
# Writes benchmarks/results/smpi-<host>-<date>{-calibration.csv,-<study>.csv} (-2, -3, ... after
# the date for a later run the same day, unless APPEND=1) and the tables
# and plots of jobs/plot_scaling.py, -<strong>-<weak>.{md,png} (or -<study>.{md,png} alone).
set -euo pipefail
cd "$(dirname "$0")/.."
studies=${STUDIES:-weak-256 strong-4096 weak-1024}
ranks_small=${RANKS:-1 4 16 64 256 1024}
ranks_large=${LARGE_RANKS:-1 4 16 64}
steps=${STEPS:-2}
platform=benchmarks/smpi/fat_tree_1024.xml
for tool in smpicxx smpirun; do
  command -v "$tool" >/dev/null || {
    echo "error: $tool not found (Debian: apt-get install libsimgrid-dev simgrid)" >&2
    exit 2
  }
done
cmake -S benchmarks/smpi -B build/smpi -G Ninja -DCMAKE_CXX_COMPILER=smpicxx >/dev/null
cmake --build build/smpi -j "$(nproc)" >/dev/null
CONTEXT_BUILD=0 source benchmarks/context.sh smpi none none
# APPEND adds to the day's own logs, not to a fresh stem's.
[[ ${APPEND:-0} == 1 ]] && stem=$stem_base
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1
# Open MPI's choice of collective algorithms: with SMPI's defaults, building a 256-rank run
# took 33-52 s of SimGrid's time, with these 0.9 s.
# Folded memory is mapped in blocks of 64 MiB rather than SimGrid's 1 MiB: 1024 ranks of 1024²
# nodes needed more maps than Linux allows a process (vm.max_map_count, 65530) and stopped.
smpi=(smpirun --cfg=smpi/coll-selector:ompi --cfg=smpi/shared-malloc-blocksize:67108864
  --log=root.thres:warning -platform "$platform")

calibrate() {  # the one-core step of each block size, into $1
  echo "block,nodes,steps,seconds_per_step,ns_per_node_step" >"$1"
  for b in 128 256 512 1024 2048 4096; do
    jobs/make_large_sheet.sh "$b" 100 "$work/calibrate.toml"
    n=$((30000000 / (b * b)))
    n=$((n < 3 ? 3 : n > 2000 ? 2000 : n))
    line=$("${smpi[@]}" -np 1 --cfg=smpi/host-speed:1Gf build/smpi/smpi_step \
      "$work/calibrate.toml" "$n" --warmup 2 | tail -1)
    /usr/bin/python3 - "$b" "$n" "$line" >>"$1" <<'PY'
import sys
b, n, line = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3].split(",")
seconds = float(line[4])
print(f"{b},{b * b},{n},{seconds:.9g},{seconds / (b * b) * 1e9:.6g}")
PY
    echo "calibrated: $(tail -1 "$1")"
  done
}
if [[ -n ${CALIBRATION:-} ]]; then
  [[ -f $CALIBRATION ]] || {
    echo "error: no calibration file $CALIBRATION" >&2
    exit 2
  }
  calibration=$CALIBRATION
else
  calibration=$stem-calibration.csv
  calibrate "$calibration"
fi

jobs/make_large_sheet.sh 256 100 "$work/sheet.toml"
revision=$(git rev-parse --short=12 HEAD 2>/dev/null || echo unknown)
run_study() {  # name kind grid|per-rank ranks...
  local name=$1 kind=$2 size=$3 log=$stem-$1.csv
  shift 3
  [[ ${APPEND:-0} == 1 ]] || rm -f "$log"
  for p in "$@"; do
    local grid=$size
    [[ $kind == weak ]] && grid=$(/usr/bin/python3 -c "print(round($size * $p ** 0.5))")
    local ns
    ns=$(/usr/bin/python3 - "$calibration" "$grid" "$p" <<'PY'
import csv, math, sys
rows = [(int(r["block"]), float(r["ns_per_node_step"])) for r in csv.DictReader(open(sys.argv[1]))]
grid, ranks = int(sys.argv[2]), int(sys.argv[3])
block = grid / math.sqrt(ranks)
if block <= rows[0][0]:
    print(rows[0][1])
elif block >= rows[-1][0]:
    print(rows[-1][1])
else:
    for (b0, t0), (b1, t1) in zip(rows, rows[1:]):
        if b0 <= block <= b1:
            w = math.log(block / b0) / math.log(b1 / b0)
            print(math.exp((1 - w) * math.log(t0) + w * math.log(t1)))
            break
PY
)
    local line
    line=$("${smpi[@]}" -np "$p" --cfg=smpi/simulate-computation:no build/smpi/smpi_step \
      "$work/sheet.toml" "$steps" --warmup 1 --fold --compute-ns "$ns" \
      --set "grid.nodes=[$grid,$grid]" | tail -1)
    /usr/bin/python3 - "$line" "$revision" "$cpu" "$ns" "$log" <<'PY'
# A line of the scaling log jobs/log_scaling.py writes, from smpi_step's CSV line.
import csv, datetime, os, sys
sys.path.insert(0, "jobs")
from log_scaling import FIELDS
ranks, grid, block, steps, per_step, rate, halo_share, status = sys.argv[1].split(",")
revision, cpu, ns, log = sys.argv[2:]
seconds = float(per_step) * int(steps)
bx, by = (int(v) for v in block.split("x"))
gx, gy = (int(v) for v in grid.split("x"))
row = dict(date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
           revision=revision, machine="simulated: benchmarks/smpi/fat_tree_1024.xml",
           cpu=f"calibrated {float(ns):.3g} ns a node-step on {cpu}", launcher="smpi",
           machines=ranks, ranks=ranks, threads=1, split=f"{round(gx / bx)}x{round(gy / by)}",
           grid=grid, steps=steps, wall_seconds=f"{seconds:.9g}", node_steps_per_second=rate,
           halo_seconds=f"{float(halo_share) * seconds:.9g}", status=status, summary="")
new = not os.path.exists(log)
with open(log, "a", newline="") as f:
    writer = csv.DictWriter(f, fieldnames=FIELDS)
    if new:
        writer.writeheader()
    writer.writerow(row)
PY
    echo "$name: $(tail -1 "$log" | cut -d, -f6,9,10,13)"
  done
}
for study in $studies; do
  case $study in
    weak-256) run_study weak-256 weak 256 $ranks_small ;;
    strong-4096) run_study strong-4096 strong 4096 $ranks_small ;;
    weak-1024) run_study weak-1024 weak 1024 $ranks_large ;;
    strong-16384) run_study strong-16384 strong 16384 $ranks_large ;;
    *) echo "error: unknown study $study" >&2; exit 2 ;;
  esac
done
title="Simulated 1024-node fat tree (benchmarks/run_smpi.sh)"
plot() {  # output stem, then --strong/--weak logs
  local out=$1
  shift
  /usr/bin/python3 jobs/plot_scaling.py "$@" --cores 1024 --title "$title" --output "$out"
}
ran() { [[ " $studies " == *" $1 "* ]]; }
for pair in "strong-4096 weak-256" "strong-16384 weak-1024"; do
  set -- $pair
  if ran "$1" && ran "$2"; then
    plot "$stem-$1-$2" --strong "$stem-$1.csv" --weak "$stem-$2.csv"
  elif ran "$1"; then
    plot "$stem-$1" --strong "$stem-$1.csv"
  elif ran "$2"; then
    plot "$stem-$2" --weak "$stem-$2.csv"
  fi
done
