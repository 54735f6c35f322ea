#!/usr/bin/env bash
# Run the gallery (docs/gallery.md): every scenes/gallery/*.toml to its end, one after another,
# a picture and an animation of each with tools/render.py, and a markdown table of wall times.
#
#   scenes/gallery/run_gallery.sh [-o DIR] [--overwrite] [--no-render] [SCENE ...]
#
#   -o DIR        where everything goes (default gallery-out/ in the working directory):
#                 NAME.h5 (+ .xdmf), NAME.json (the run summary), NAME.log, NAME.png, NAME.mp4,
#                 and gallery-table.md
#   --overwrite   replace the files of an earlier run; without it a scene whose output exists
#                 is refused (cosserat exits 2) and a picture or animation that exists is kept
#   --no-render   run only, no pictures
#   SCENE ...     scene names (crumple_silk) or paths; default every scenes/gallery/*.toml
#
# Environment: THREADS (OpenMP threads per run, default 1), COSSERAT (the binary, default
# build/release/cosserat under the repository), PYTHON (default /usr/bin/python3, which has
# h5py, numpy and matplotlib), WAIT_FOR (a file: while it exists, wait before each run and each
# rendering, e.g. a lock another user holds while taking timings).
#
# A scene file may hold one line "# render: OPTIONS": extra tools/render.py options for its
# picture and animation (camera, field, frame). The table is built from every NAME.json in DIR
# at the end, so scenes run in several calls land in one table. Exit status: 0 when every scene
# ran to its end (status ok) and every picture was written, 1 otherwise.
set -u

here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=gallery-out
overwrite=0
render=1
scenes=()
while [ $# -gt 0 ]; do
  case "$1" in
    -o) out=$2; shift 2 ;;
    --overwrite) overwrite=1; shift ;;
    --no-render) render=0; shift ;;
    -h|--help) sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "run_gallery.sh: unknown option $1" >&2; exit 2 ;;
    *) scenes+=("$1"); shift ;;
  esac
done
THREADS=${THREADS:-1}
COSSERAT=${COSSERAT:-$root/build/release/cosserat}
PYTHON=${PYTHON:-/usr/bin/python3}
if [ ! -x "$COSSERAT" ]; then
  echo "run_gallery.sh: no cosserat binary at $COSSERAT (build it: cmake --preset release &&" \
       "cmake --build --preset release --target cosserat), or set COSSERAT" >&2
  exit 2
fi
if [ ${#scenes[@]} -eq 0 ]; then
  for f in "$here"/*.toml; do scenes+=("$f"); done
fi
mkdir -p "$out"

wait_quiet() {
  if [ -n "${WAIT_FOR:-}" ]; then
    while [ -e "$WAIT_FOR" ]; do sleep 10; done
  fi
}

failed=0
for s in "${scenes[@]}"; do
  case "$s" in
    *.toml) scene=$s ;;
    *) scene=$here/$s.toml ;;
  esac
  name=$(basename "$scene" .toml)
  if [ ! -f "$scene" ]; then
    echo "run_gallery.sh: no scene $scene" >&2; failed=1; continue
  fi
  flags=()
  [ $overwrite -eq 1 ] && flags+=(--overwrite)
  wait_quiet
  echo "== $name: running ($THREADS thread(s))"
  "$COSSERAT" run "$scene" --threads "$THREADS" -q -o "$out/$name.h5" \
      --summary "$out/$name.json" "${flags[@]}" > "$out/$name.log" 2>&1
  rc=$?
  if [ $rc -ne 0 ]; then
    echo "   exit status $rc:"; sed 's/^/   /' "$out/$name.log"
    failed=1
    [ $rc -ne 3 ] && continue   # 3: unstable, its frames so far are kept and drawn
  fi
  [ $render -eq 1 ] || continue
  if [ $overwrite -eq 0 ] && { [ -e "$out/$name.png" ] || [ -e "$out/$name.mp4" ]; }; then
    echo "   $out/$name.png or .mp4 exists; kept (--overwrite to replace)"
    continue
  fi
  opts=$(sed -n 's/^# render: //p' "$scene" | head -n 1)
  wait_quiet
  start=$(date +%s.%N)
  # shellcheck disable=SC2086  # the render options are words
  if "$PYTHON" "$root/tools/render.py" "$out/$name.h5" --output "$out/$name.png" \
      --animate "$out/$name.mp4" $opts >> "$out/$name.log" 2>&1; then
    awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "   drawn in %.1f s\n", b - a }'
  else
    echo "   render failed:"; tail -n 3 "$out/$name.log" | sed 's/^/   /'; failed=1
  fi
done

# The table, from every summary in the folder.
"$PYTHON" - "$out" "$root" "$THREADS" "$COSSERAT" <<'EOF'
import glob, json, os, platform, subprocess, sys, datetime
out, root, threads, binary = sys.argv[1:5]
def sh(cmd):
    try:
        return subprocess.run(cmd, shell=True, capture_output=True, text=True, cwd=root).stdout.strip()
    except Exception:
        return ""
cpu = ""
try:
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip(); break
except OSError:
    pass
cache = os.path.join(os.path.dirname(binary), "CMakeCache.txt")
compiler = ""
if os.path.exists(cache):
    for line in open(cache):
        if line.startswith("CMAKE_CXX_COMPILER:"):
            cxx = line.split("=", 1)[1].strip()
            compiler = sh(f"{cxx} --version | head -n 1") or cxx
rows = []
for path in sorted(glob.glob(os.path.join(out, "*.json"))):
    try:
        d = json.load(open(path))
    except (OSError, ValueError):
        continue
    if "wall_seconds" not in d:
        continue
    name = os.path.splitext(os.path.basename(path))[0]
    dt = d.get("dt")
    rows.append("| {} | {} × {} | {} | {} | {:.4g} | {:.1f} | {:.3g} | {:.4f} | {} |".format(
        name, d["grid"][0], d["grid"][1], "adaptive" if dt is None else f"{dt:g}", d["steps"],
        d["sim_time"], d["wall_seconds"], d["node_steps_per_second"], d["area_ratio"],
        d["status"]))
text = f"""# Gallery wall times

- machine: {platform.node()}, {cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}
- compiler: {compiler or "unknown"}; binary: {os.path.relpath(binary, root)}
- date: {datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")}
- git revision: {sh("git describe --always --dirty") or "unknown"}
- one rank, {threads} thread(s) per run; wall time of the run alone (from its `--summary`), not
  of writing the pictures

| scene | grid | dt (s) | steps | simulated (s) | wall (s) | node-steps/s | final area ratio | status |
|---|---|---|---|---|---|---|---|---|
""" + "\n".join(rows) + "\n"
with open(os.path.join(out, "gallery-table.md"), "w") as f:
    f.write(text)
print(text)
EOF
exit $failed
