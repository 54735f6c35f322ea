#!/usr/bin/env bash
# What self-contact costs (docs/contact.md, "Self-contact"): node-steps per second of
# `cosserat run` on the hanging S1-like sheets of jobs/make_large_sheet.sh (no contacts: a
# hanging sheet does not touch itself) at 120², 240², 512² and 1024², on 1 and 2 threads, with
# self-contact off and on (material.thickness 0.5 mm); and on scenes with contacts, one thread:
# S6 with its loads x 5 (scenes/hard/s6_loads_x5.toml, 60², thickness 0.5 mm; and at 240², 1
# and 2 threads) and the napkin
# fold (scenes/contact/napkin_fold.toml, its first 0.5 s, where the fold comes over). Figures from
# each run's summary; and the 1024² sheet's cost a step once the candidate lists are built.
# Writes benchmarks/results/self-contact-<host>-<date>.md.
#   benchmarks/run_self_contact.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh self-contact release cosserat
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
on=(--set 'self_contact={}' --set material.thickness=0.0005)
none=()

rate() {  # threads scene [args...]: node-steps per second from the run's summary
  local threads=$1 scene=$2
  shift 2
  OMP_PROC_BIND=close build/release/cosserat run "$scene" -q --threads "$threads" \
    -o "$work/run.h5" --overwrite --summary "$work/run.json" "$@" >/dev/null
  /usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); \
print(f\"{d['node_steps_per_second']:.3e} {(d['self_contact'] or {}).get('max_pairs', '—')}\")" \
    "$work/run.json"
}

# label threads steps off-scene on-scene on-flags [args...]: a table row, self-contact off and
# on; on-flags names the array of flags the run with self-contact adds ("on" or "none").
row() {
  local label=$1 threads=$2 steps=$3 off_scene=$4 on_scene=$5 off with pairs ratio
  local -n on_flags=$6
  shift 6
  read -r off _ < <(rate "$threads" "$off_scene" "$@")
  read -r with pairs < <(rate "$threads" "$on_scene" "$@" "${on_flags[@]}")
  ratio=$(/usr/bin/python3 -c "print(f'{$with / $off:.3f}')")
  echo "| $label | $threads | $steps | $off | $with | $ratio | $pairs |"
}

best() {  # repeats threads steps [args...]: the least wall time of the 1024² sheet's runs
  local repeats=$1 threads=$2 steps=$3
  shift 3
  for ((i = 0; i < repeats; ++i)); do
    OMP_PROC_BIND=close build/release/cosserat run "$work/sheet.toml" -q --threads "$threads" \
      -o "$work/run.h5" --overwrite --summary "$work/run.json" --set time.steps="$steps" \
      --set time.output_every="$steps" "$@" >/dev/null
    /usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['wall_seconds'])" \
      "$work/run.json"
  done | sort -g | head -1
}

{
  echo "# Self-contact's cost, $date"
  echo
  echo "Machine: $cpu; compiler: $compiler, release preset; git $revision; 1 rank,"
  echo "OMP_PROC_BIND=close. \`benchmarks/run_self_contact.sh\`: node-steps/s of \`cosserat run\` from"
  echo "its summary (output included, every tenth step a frame of the large sheets)."
  echo
  echo "| scene | threads | steps | off (node-steps/s) | on | on / off | most pairs in a step |"
  echo "|---|---|---|---|---|---|---|"
  for spec in 120:200 240:100 512:40 1024:20; do
    nodes=${spec%%:*}
    steps=${spec##*:}
    jobs/make_large_sheet.sh "$nodes" "$steps" "$work/sheet.toml"
    for threads in 1 2; do
      row "hanging sheet ${nodes}²" "$threads" "$steps" "$work/sheet.toml" "$work/sheet.toml" on
    done
  done
  echo
  echo "The 1024² sheet's step after the first, which builds the candidate lists: from runs of 60"
  echo "and 120 steps with one frame each, (wall(120) − wall(60)) / 60, the best of three of each."
  echo
  echo "| threads | off (ms a step) | on (ms a step) | on / off − 1 | the build, s |"
  echo "|---|---|---|---|---|"
  jobs/make_large_sheet.sh 1024 60 "$work/sheet.toml"
  for threads in 1 2; do
    off60=$(best 3 "$threads" 60) off120=$(best 3 "$threads" 120)
    on60=$(best 3 "$threads" 60 "${on[@]}") on120=$(best 3 "$threads" 120 "${on[@]}")
    /usr/bin/python3 -c "
off, on = ($off120 - $off60) / 60, ($on120 - $on60) / 60
build = ($on60 - $off60) - 60 * (on - off)
print(f'| $threads | {1e3 * off:.1f} | {1e3 * on:.1f} | {on / off - 1:+.0%} | {build:.2f} |')"
  done
  echo
  echo "| scene | threads | steps | off (node-steps/s) | on | on / off | most pairs in a step |"
  echo "|---|---|---|---|---|---|---|"
  row "s6_loads_x5 (60², 20 000 steps)" 1 20000 scenes/hard/s6_loads_x5.toml \
    scenes/hard/s6_loads_x5.toml on
  # S6 x 5 at 240² (issue 31): each load of a node [k, l] of the 60² grid spread over the 4 x 4
  # nodes around [4k, 4l], at the same force per area (100 h1 h2 and 25 h1 h2 a component on
  # each; on the one node [4k, 4l] the sheet hardly folds), its first 6 s in adaptive steps
  # with the load windows in seconds (with a fixed 4e-4 s, within the rest sheet's CFL
  # estimate of 5e-4 s, it folds sharper than the grid resolves and stops at 2.48 s).
  /usr/bin/python3 - scenes/hard/s6_loads_x5.toml "$work/s6_240.toml" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
scale = (59 / 239) ** 2
text = text.replace("nodes = [60, 60]", "nodes = [240, 240]")
text = re.sub(r"nodes = \[\[(\d+), (\d+)\]\]",
              lambda m: f"region = {{ rect = [{4 * int(m[1]) - 1}, {4 * int(m[2]) - 1}, "
                        f"{4 * int(m[1]) + 2}, {4 * int(m[2]) + 2}] }}", text)
text = re.sub(r"force = \[([-0-9.e]+), 0.0, ([-0-9.e]+)\]",
              lambda m: f"force = [{float(m[1]) * scale!r}, 0.0, {float(m[2]) * scale!r}]", text)
for old, new in (("dt = 0.001\n", ""), ("steps = 20000", "duration = 6.0"),
                 ("start = 0\n", "start_time = 0.0\n"), ("end = 10000", "end_time = 10.0"),
                 ("start = 10001", "start_time = 10.001"), ("end = 20000", "end_time = 20.0")):
    text = re.sub(f"^{old}", new, text, flags=re.M)
text = re.sub(r"^output_every = .*$", "output_dt = 0.06", text, flags=re.M)
open(sys.argv[2], "w").write(text)
PY
  for threads in 1 2; do
    row "S6 x 5 at 240² (6 s, adaptive steps)" "$threads" — "$work/s6_240.toml" \
      "$work/s6_240.toml" on
  done
  sed '/^\[self_contact\]/,/^$/d' scenes/contact/napkin_fold.toml >"$work/napkin_off.toml"
  row "napkin_fold (26 × 51, 0.5 s)" 1 50000 "$work/napkin_off.toml" \
    scenes/contact/napkin_fold.toml none --set time.duration=0.5
} | tee "$stem.md"
