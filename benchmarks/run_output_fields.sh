#!/usr/bin/env bash
# What the per-node fields (docs/output.md, "Fields") cost a run's output: S6 on its own grid
# (60 x 60) and on the grid at the default's limit (500 x 500 = 250 000 nodes), each without
# fields (output.fields = []) and with all four, on one rank of one thread, in a folder on the
# repository's disk and in /dev/shm (where fsync costs nothing).
# - Size: the .h5 of S6 with 101 frames, as the full scene writes (20 000 steps, a frame every
#   200), run here as 2000 steps with a frame every 20, whose file differs only in the stored
#   --set text; and the bytes a frame adds.
# - Cost of a frame: (a run writing every one of N steps - the same run writing its first and
#   last step) / (N - 1), and of a step: (the second run - a run of no step) / N, less a frame;
#   in CPU seconds (user + system, of the child) and in wall seconds, each the median of 5
#   repetitions. On a machine shared with other work the wall time is the noisier: the CPU time
#   holds the fields' arithmetic and HDF5's copies, the wall time also the fsync of every frame.
#   At 500 x 500 the step is 1e-4 s, S6's 1e-3 s being above the CFL estimate of that grid
#   (2.4e-4 s).
# Into benchmarks/results/output-fields-<host>-<date>.md.
#   benchmarks/run_output_fields.sh [COSSERAT]   (default build/release/cosserat)
set -euo pipefail
cd "$(dirname "$0")/.."
CONTEXT_BUILD=0 source benchmarks/context.sh output-fields none none
binary=${1:-build/release/cosserat}

measure() {  # folder place -> markdown rows
  /usr/bin/python3 - "$binary" "$1" "$2" <<'PY'
import os, statistics, subprocess, sys, time
binary, folder, place = sys.argv[1:]
out = os.path.join(folder, "fields.h5")
ALL = '["velocity","area_ratio","curvature","energy_density"]'

def run(sets):
    """(cpu s, wall s, .h5 bytes) of one run."""
    line = [binary, "run", "scenes/s6_compression.toml", "-q", "--threads", "1", "-o", out]
    for s in sets:
        line += ["--set", s]
    start = time.monotonic()
    process = subprocess.Popen(line, env=dict(os.environ, OMP_NUM_THREADS="1"))
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.monotonic() - start
    assert os.waitstatus_to_exitcode(status) == 0, line
    size = os.path.getsize(out)
    for f in os.listdir(folder):
        os.remove(os.path.join(folder, f))
    return usage.ru_utime + usage.ru_stime, wall, size

def median(sets):
    runs = [run(sets) for _ in range(5)]
    return (statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs),
            runs[0][2])

for grid, steps, dt in (("[60,60]", 200, "1e-3"), ("[500,500]", 20, "1e-4")):
    for label, fields in (("none", "[]"), ("all four", ALL)):
        base = [f"grid.nodes={grid}", f"output.fields={fields}", f"time.dt={dt}"]
        zero = median(base + ["time.steps=0"])
        ends = median(base + [f"time.steps={steps}", f"time.output_every={steps}"])
        every = median(base + [f"time.steps={steps}", "time.output_every=1"])
        frame = [(every[i] - ends[i]) / (steps - 1) for i in range(2)]
        step = [(ends[i] - zero[i] - frame[i]) / steps for i in range(2)]
        frame_mb = (every[2] - ends[2]) / (steps - 1) / 1e6
        s6 = ""
        if grid == "[60,60]":
            s6 = f"{run(base + ['time.steps=2000', 'time.output_every=20'])[2] / 1e6:.2f}"
        print(f"| {place} | {grid} | {label} | {1e3 * frame[0]:.1f} | {1e3 * frame[1]:.1f} "
              f"| {1e3 * step[0]:.2f} | {frame_mb:.3f} | {s6} |", flush=True)
PY
}

rows=()
for place in disk shm; do
  parent=/dev/shm
  [ "$place" = disk ] && parent=$PWD/build
  folder=$(mktemp -d -p "$parent")
  while IFS= read -r row; do rows+=("$row"); done < <(measure "$folder" "$place")
  rmdir "$folder"
done

{
  echo "# Output fields: size and frame-writing time, $date"
  echo
  echo "Machine: $cpu; compiler: $compiler; git $revision; 1 rank, 1 thread;"
  echo "\`benchmarks/run_output_fields.sh $binary\`. Fields: none (\`output.fields = []\`) or"
  echo "velocity, area_ratio, curvature and energy_density. A frame's cost: what writing one"
  echo "more frame adds to a run (computing its fields, writing and flushing the .h5, its XDMF"
  echo "element), in CPU and in wall milliseconds; a step's, in CPU milliseconds, for scale;"
  echo "medians of 5 runs. MB per frame: what a frame adds to the .h5. S6 .h5: the file of"
  echo "S6's 101 frames on its 60 x 60 grid."
  echo
  echo "| folder | grid | fields | frame CPU ms | frame wall ms | step CPU ms | MB per frame | S6 .h5 MB |"
  echo "|---|---|---|---|---|---|---|---|"
  printf '%s\n' "${rows[@]}"
} > "$stem.md"
cat "$stem.md"
