#!/usr/bin/env bash
# Hard cases of issue 11 (items 3 and 5) with the three discretisations of the internal force
# (model.discretisation = "flux", "energy-nodal" and the default "energy", docs/model.md) and with
# the mass-spring model, its springs matched to the case's material (model = { kind =
# "mass-spring", match = "material" }, docs/models.md "Matched springs"):
# every preset on S2 for 10 s, the 1 m squares of
# silk, cotton and denim hung from a corner, S6 with its loads x 5, S6 with xi = 0, S4 with the
# flag preset and the 120 x 120 silk crumple (scenes/hard/). For each run: exit status, the time
# it stopped and the stability monitor's message, wall time, the step, and the sheet's quality
# over its frames (tools/sheet_quality.py: smallest det a/det A, smallest adjacent-normal cosine,
# self-proximity, triangles passing through each other, area ratio). Writes
# benchmarks/results/hard-cases-<host>-<date>.{md,csv} and, in a full run, one picture per
# scenes/hard scene from its energy-form run (…-<scene>.png). Two runs at a time, each under a timeout.
#   benchmarks/run_hard_cases.sh [--quick] [--self-contact]
# --quick: every run 1/10 of its steps (a check of the script, not results; files *-quick.*).
# --self-contact: the energy discretisation only, without and with self-contact
# ([self_contact] with its defaults, docs/contact.md "Self-contact"; material.thickness from the
# preset, else 0.5 mm, the 10 m calibrations'); files hard-cases-self-contact-*.
# COSSERAT=path: the binary to run (default build/release/cosserat, built here);
# HARD_TIMEOUT: seconds per run (default 1200); HARD_JOBS: runs at a time (default 2).
set -euo pipefail
cd "$(dirname "$0")/.."
quick=0
self_contact=0
for arg in "$@"; do
  case $arg in
    --quick) quick=1 ;;
    --self-contact) self_contact=1 ;;
    *) echo "usage: benchmarks/run_hard_cases.sh [--quick] [--self-contact]" >&2; exit 2 ;;
  esac
done
if [[ -z ${COSSERAT:-} ]]; then
  source benchmarks/context.sh hard-cases release cosserat
  COSSERAT=build/release/cosserat
else
  CONTEXT_BUILD=0 source benchmarks/context.sh hard-cases none none
  compiler="$compiler (binary given as COSSERAT=$COSSERAT)"
fi
stem=$stem_base
((self_contact)) && stem=${stem/hard-cases-/hard-cases-self-contact-}
((quick)) && stem=$stem-quick
claim_stem
export COSSERAT OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
export HARD_TIMEOUT=${HARD_TIMEOUT:-1200} QUICK=$quick SELF_CONTACT=$self_contact
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export WORK=$work
start=$(date +%s)

# label|scene|steps (full run)|extra --set (one, may be empty)
cases=()
for p in silk-10m cotton-10m denim-10m canvas-10m satin-10m linen-10m velvet-10m \
  coated-cotton-10m sheer-curtain-10m heavy-curtain-10m shower-curtain-10m flag-10m; do
  cases+=("S2 $p|scenes/s2_cape.toml|10000|material={preset=\"$p\"}")
done
for s in silk_square cotton_square denim_square s6_loads_x5 s6_xi0 s4_flag_preset crumple; do
  steps=$(sed -n 's/^steps *= *\([0-9]*\).*/\1/p' "scenes/hard/$s.toml")
  cases+=("$s|scenes/hard/$s.toml|$steps|")
done

run_one() {  # index label scene steps extra discretisation
  local i=$1 label=$2 scene=$3 steps=$4 extra=$5 disc=$6
  ((QUICK)) && steps=$((steps / 10))
  local every=$((steps / 100 > 0 ? steps / 100 : 1))
  local out=$WORK/$i-$disc
  local model=(--set model.discretisation="\"$disc\"")
  [[ $disc == mass-spring ]] && model=(--set 'model={kind="mass-spring", match="material"}')
  local with=(--set 'self_contact={}')
  grep -q '^preset *=' "$scene" || [[ $extra == *preset* ]] ||
    with+=(--set material.thickness=0.0005)
  [[ $disc == self-contact ]] && model=("${with[@]}")
  local args=(run "$scene" -q -o "$out.h5" --summary "$out.json" "${model[@]}"
    --set time.steps="$steps" --set time.output_every="$every")
  [[ -n $extra ]] && args+=(--set "$extra")
  local t0 rc=0
  t0=$(date +%s.%N)
  timeout "$HARD_TIMEOUT" "$COSSERAT" "${args[@]}" >/dev/null 2>"$out.err" || rc=$?
  local wall
  wall=$(echo "$(date +%s.%N) - $t0" | bc)
  # With --self-contact, the pairs closer than half the cloth's thickness too, in the runs with
  # and without it: the thickness self-contact takes, from the run's summary, or for a run
  # without it from that of a one-step run with it.
  local thickness="" summary=$out.json
  if ((SELF_CONTACT)); then
    if [[ $disc != self-contact ]]; then
      summary=$out.probe.json
      local probe=(run "$scene" -q -o "$out.probe.h5" --summary "$summary" "${with[@]}"
        --set time.steps=1 --set time.output_every=1)
      [[ -n $extra ]] && probe+=(--set "$extra")
      "$COSSERAT" "${probe[@]}" >/dev/null 2>&1 || true
    fi
    thickness=$(/usr/bin/python3 -c "import json,sys
try: print((json.load(open(sys.argv[1])).get('self_contact') or {}).get('thickness') or '')
except Exception: print('')" "$summary")
  fi
  /usr/bin/python3 tools/sheet_quality.py "$out.h5" --json ${thickness:+--thickness "$thickness"} \
    >"$out.q.json" 2>>"$out.err" || true
  /usr/bin/python3 - "$out" "$i" "$label" "$disc" "$rc" "$wall" "$steps" <<'PY'
import json, os, sys
out, i, label, disc, rc, wall, steps = sys.argv[1:]
row = {"index": int(i), "case": label, "discretisation": disc, "exit": int(rc),
       "wall_s": float(wall), "steps_asked": int(steps)}
try:
    s = json.load(open(out + ".json"))
    row.update(dt=s["dt"], steps=s["steps"], sim_time=s["sim_time"], summary_area_ratio=s["area_ratio"],
               run_wall_s=s["wall_seconds"])
except Exception:
    pass
try:
    q = json.load(open(out + ".q.json"))["overall"]
    row.update(quality=q)
    if "sim_time" not in row:
        row["sim_time"] = json.load(open(out + ".q.json"))["frames"][-1]["time"]
except Exception:
    pass
msg = [l.strip().split("; stopped")[0].removeprefix("error: ")
       for l in open(out + ".err") if l.startswith("error:")]
row["message"] = msg[-1] if msg else ("killed by the timeout" if int(rc) == 124 else "")
json.dump(row, open(out + ".row.json", "w"))
PY
  echo "$(date +%T) $label $disc: exit $rc, ${wall%.*} s" >&2
}
export -f run_one

jobs=$work/jobs
: >"$jobs"
for idx in "${!cases[@]}"; do
  IFS='|' read -r label scene steps extra <<<"${cases[$idx]}"
  discretisations=(flux energy-nodal energy mass-spring)
  ((self_contact)) && discretisations=(energy self-contact)
  for disc in "${discretisations[@]}"; do
    printf '%s\0%s\0%s\0%s\0%s\0%s\0' "$idx" "$label" "$scene" "$steps" "$extra" "$disc" >>"$jobs"
  done
done
# the long runs first, so that two long ones do not end up last together
xargs -0 -n 6 -P "${HARD_JOBS:-2}" bash -c 'run_one "$@"' _ < <(
  /usr/bin/python3 -c "
import sys
f = open(sys.argv[1], 'rb').read().split(b'\0')[:-1]
jobs = [f[i:i + 6] for i in range(0, len(f), 6)]
jobs.sort(key=lambda j: (-int(j[3]) * (14400 if b'crumple' in j[2] else 1600 if b'hard' in j[2] else 400)))
sys.stdout.buffer.write(b''.join(x + b'\0' for j in jobs for x in j))" "$jobs")
total=$(($(date +%s) - start))

if ((!quick)); then
  for s in silk_square cotton_square denim_square s6_loads_x5 s6_xi0 s4_flag_preset crumple; do
    for idx in "${!cases[@]}"; do
      [[ ${cases[$idx]%%|*} == "$s" ]] || continue
      pictured=energy
      ((self_contact)) && pictured=self-contact
      /usr/bin/python3 tools/render.py "$work/$idx-$pictured.h5" --frame -1 --output "$stem-$s.png" \
        >/dev/null 2>&1 ||
        echo "render of $s failed" >&2
    done
  done
fi

/usr/bin/python3 - "$work" "$stem" "$date" "$cpu" "$compiler" "$revision" "$OMP_NUM_THREADS" \
  "$total" "$quick" "$HARD_TIMEOUT" "$("$COSSERAT" --version 2>/dev/null | head -1)" <<'PY'
import csv, glob, json, sys
work, stem, date, cpu, compiler, revision, threads, total, quick, timeout, version = sys.argv[1:]
rows = sorted((json.load(open(p)) for p in glob.glob(work + "/*.row.json")),
              key=lambda r: (r["index"],
                             ["flux", "energy-nodal", "energy", "mass-spring",
                              "self-contact"].index(
                                 r["discretisation"])))
def g(r, k, fmt):
    q = r.get("quality") or {}
    v = q.get(k, r.get(k))
    return "—" if v is None else format(v, fmt)
cols = ["case", "discretisation or model", "exit", "finished", "stopped at t (s)", "dt (s)", "steps",
        "wall (s)", "min det a/A", "min signed det a/A", "most inverted cells", "min normal cos",
        "most pairs < h/2", "most pairs < t/2", "min far distance / h",
        "most crossing triangle pairs (cells)",
        "area ratio (summary, end)",
        "area ratio min..max (frames)", "message"]
table = []
for r in rows:
    q = r.get("quality") or {}
    table.append([r["case"], r["discretisation"], str(r["exit"]), "yes" if r["exit"] == 0 else "no",
                  g(r, "sim_time", ".3f"), g(r, "dt", ".3g"), str(r.get("steps", "—")),
                  format(r["wall_s"], ".1f"), g(r, "min_det_ratio", ".3g"),
                  g(r, "min_signed_det_ratio", ".3g"), g(r, "inverted_cells", "d"),
                  g(r, "min_normal_cos", ".3f"), g(r, "close_pairs", "d"),
                  g(r, "pairs_below_half_thickness", "d"), g(r, "min_far_distance_over_h", ".3f"),
                  f"{g(r, 'crossing_pairs', 'd')} ({g(r, 'crossing_cells', 'd')})",
                  g(r, "summary_area_ratio", ".4f"),
                  (f"{q['area_ratio']:.3f}..{q['max_area_ratio']:.3f}" if q else "—"),
                  r["message"].replace("|", "/")])
with open(stem + ".csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(cols)
    w.writerows(table)
title = ("the energy discretisation without and with self-contact" if "self-contact" in stem
         else "the flux, nodal energy and energy discretisations and matched springs")
lines = [f"# Hard cases: {title}, {date}" + (" (QUICK: 1/10 of every run)" if quick == "1" else ""), "",
         f"Machine: {cpu}; compiler: {compiler}, release; git {revision}; binary `{version}`; "
         f"1 rank x {threads} thread(s), two runs at a time; per-run timeout {timeout} s.",
         f"`benchmarks/run_hard_cases.sh{' --quick' if quick == '1' else ''}{' --self-contact' if 'self-contact' in stem else ''}`; whole suite {int(total) // 60} min {int(total) % 60} s of wall time. "
         "Quality measures are over the frames written (100 a run, plus the last good state of a "
         "run stopped by the monitor): tools/sheet_quality.py. \"min far distance / h\": "
         "the smallest distance of two nodes more than 3 indices apart, where one is within h; "
         "\"most pairs < h/2\": the most such pairs closer than h/2 in one frame; "
         "\"most pairs < t/2\": the same closer than half the cloth's thickness t (with "
         "--self-contact, in the runs with and without it; t the thickness self-contact takes: "
         "the preset's, else 0.5 mm); "
         "\"most crossing triangle pairs\": the most pairs of the sheet's triangles that pass "
         "through each other in one frame (an exact test), with the cells they lie in. Exit 3: the "
         "stability monitor stopped the run (message). Wall time includes writing frames.", "",
         "| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
lines += ["| " + " | ".join(t) + " |" for t in table]
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
