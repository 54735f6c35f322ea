#!/usr/bin/env bash
# What keeping every edge from passing through another costs and gives (docs/contact.md,
# "Self-contact", item 1): wall time and node-steps per second of `cosserat run` without
# self-contact, with `self_contact.edges = "border"` (the border's edges alone) and with
# `edges = "all"` (the default), one rank, one thread; and the most pairs of the sheet's
# triangles that pass through each other in a frame (tools/sheet_quality.py's exact test) with
# the cells they lie in. Scenes: S2 with the silk-10m preset (scenes/s2_cape.toml, 10 s),
# S6 with its loads x 5 (scenes/hard/s6_loads_x5.toml, 20 000 steps), the napkin fold's first
# 0.5 s (scenes/contact/napkin_fold.toml) and the 512² hanging sheet of jobs/make_large_sheet.sh
# (40 steps), thickness 0.5 mm where the scene gives none.
# Writes benchmarks/results/self-contact-edges-<host>-<date>.md.
#   benchmarks/run_self_contact_edges.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh self-contact-edges release cosserat
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1

# label scene thickness-or-empty crossings(0/1) [args...]: three table rows.
rows() {
  local label=$1 scene=$2 thickness=$3 crossings=$4
  shift 4
  local base=("$@")
  [[ -n $thickness ]] && base+=(--set "material.thickness=$thickness")
  # A scene with its own [self_contact] keeps it (its friction), and runs without it from a copy
  # that leaves the table out.
  local own=0
  grep -q '^\[self_contact\]' "$scene" && own=1
  sed '/^\[self_contact\]/,/^$/d' "$scene" >"$work/off.toml"
  local mode
  for mode in off border all; do
    local args=("${base[@]}") file=$scene
    if [[ $mode == off ]]; then
      file=$work/off.toml
    else
      ((own)) || args+=(--set 'self_contact={}')
      args+=(--set "self_contact.edges=\"$mode\"")
    fi
    OMP_PROC_BIND=close build/release/cosserat run "$file" -q --threads 1 -o "$work/run.h5" \
      --overwrite --summary "$work/run.json" "${args[@]}" >/dev/null
    local crossed="—"
    if ((crossings)); then
      crossed=$(/usr/bin/python3 tools/sheet_quality.py "$work/run.h5" --json | /usr/bin/python3 -c "
import json, sys
frames = json.load(sys.stdin)['frames']
worst = max(frames, key=lambda f: f['crossing_pairs'])
print(f\"{worst['crossing_pairs']} ({worst['crossing_cells']})\")")
    fi
    /usr/bin/python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
pairs = (d['self_contact'] or {}).get('max_pairs', '—')
print(f\"| $label | $mode | {d['wall_seconds']:.2f} | {d['node_steps_per_second']:.3e} | {pairs} | $crossed |\")" \
      "$work/run.json"
  done
}

{
  echo "# Self-contact: every edge or the border's, $date"
  echo
  echo "Machine: $cpu; compiler: $compiler, release preset; git $revision; 1 rank x 1 thread,"
  echo "OMP_PROC_BIND=close. \`benchmarks/run_self_contact_edges.sh\`: wall time and node-steps/s"
  echo "from each run's summary (output included); the most crossing triangle pairs in a frame"
  echo "(cells) from \`tools/sheet_quality.py\` over the frames written."
  echo
  echo "| scene | self-contact | wall (s) | node-steps/s | most pairs in a step | most crossing triangle pairs (cells) |"
  echo "|---|---|---|---|---|---|"
  rows "S2 silk-10m (20², 10 000 steps)" scenes/s2_cape.toml "" 1 \
    --set 'material={preset="silk-10m"}' --set time.output_every=100
  rows "S6 x 5 (60², 20 000 steps)" scenes/hard/s6_loads_x5.toml 0.0005 1 \
    --set time.output_every=200
  rows "napkin_fold (26 × 51, 0.5 s)" scenes/contact/napkin_fold.toml "" 0 \
    --set time.duration=0.5
  jobs/make_large_sheet.sh 512 40 "$work/sheet.toml" >/dev/null
  rows "hanging sheet 512² (40 steps)" "$work/sheet.toml" 0.0005 0
} | tee "$stem.md"
