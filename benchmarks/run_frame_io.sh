#!/usr/bin/env bash
# Cost of writing frames (issue 12, defect 13): a 32 x 32 sheet (S1) written at every one of
# 3000 steps (3001 frames), on one rank of one thread, in a folder on the repository's disk and
# in /dev/shm (where fsync costs nothing). Wall time of the whole run, and the bytes the process
# wrote (wchar of /proc/PID/io, read before the process is reaped). Each argument is a build of
# cosserat, optionally labelled (LABEL=PATH), e.g. the one before a change and the one after, so
# that both figures come from one machine in one sitting. Into
# benchmarks/results/frame-io-<host>-<date>.md.
#   benchmarks/run_frame_io.sh [LABEL=]COSSERAT...
set -euo pipefail
cd "$(dirname "$0")/.."
CONTEXT_BUILD=0 source benchmarks/context.sh frame-io none none
binaries=("$@")

measure() {  # binary folder -> "wall_s wchar h5_bytes xmf_bytes"
  /usr/bin/python3 - "$1" "$2" <<'PY'
import os, subprocess, sys, time
binary, folder = sys.argv[1:]
out = os.path.join(folder, "frames.h5")
line = [binary, "run", "scenes/s1_clothesline.toml", "-q", "-o", out,
        "--set", "grid.nodes=[32,32]", "--set", "time.steps=3000", "--set", "time.output_every=1"]
start = time.monotonic()
process = subprocess.Popen(line, env=dict(os.environ, OMP_NUM_THREADS="1"))
os.waitid(os.P_PID, process.pid, os.WEXITED | os.WNOWAIT)
io = dict(l.split(": ") for l in open(f"/proc/{process.pid}/io").read().splitlines())
assert process.wait() == 0
wall = time.monotonic() - start
sizes = [os.path.getsize(out), os.path.getsize(out[:-3] + ".xmf")]
for f in os.listdir(folder):
    os.remove(os.path.join(folder, f))
print(f"{wall:.2f} {io['wchar']} {sizes[0]} {sizes[1]}")
PY
}

rows=()
for place in disk shm; do
  parent=/dev/shm
  [ "$place" = disk ] && parent=$PWD/build
  folder=$(mktemp -d -p "$parent")
  for named in "${binaries[@]}"; do
    binary=${named#*=}
    read -r wall wchar h5 xmf < <(measure "$binary" "$folder")
    rows+=("| $place | ${named%%=*} | $wall | $((wchar / 1000000)) | $((h5 / 1000000)) |"
           "$((xmf / 1000)) |")
  done
  rmdir "$folder"
done

{
  echo "# Frame output cost, $date"
  echo
  echo "Machine: $cpu; compiler: $compiler; git $revision."
  echo "S1 on 32 x 32 nodes, 3000 steps, a frame at every step (3001 frames), 1 rank, 1 thread;"
  echo "\`benchmarks/run_frame_io.sh ${binaries[*]}\`. Written: every byte the process wrote"
  echo "(wchar), HDF5 data and metadata included."
  echo
  echo "| folder | binary | wall s | written MB | .h5 MB | .xmf kB |"
  echo "|---|---|---|---|---|---|"
  printf '%s %s\n' "${rows[@]}"
} > "$stem.md"
cat "$stem.md"
