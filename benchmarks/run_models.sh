#!/usr/bin/env bash
# The two force models side by side (docs/models.md, "Side by side"): S1, S2, S6 and the sphere
# drape, each as shipped (the Cosserat model, the default energy form) and with
# model = { kind = "mass-spring", match = "material" }: the same grid, mass, loads, fixes,
# solids, medium damping and integrator, springs matched to the material's stiffness
# (docs/models.md, "Matched springs"). Per run, one rank and one thread, one run at a time:
#   - node-steps/s and wall time of the scene as shipped (its own duration), the best of three
#     runs writing no fields;
#   - steps, from the run summary of a long run (S1 to 20 s, where its corners are let go, S2 to
#     60 s, the sphere drape to 30 s, S6 its own 20 s, whose loads hold to the end);
#   - the largest stable fixed step over the scene's own duration (`cosserat stable-dt`);
#   - the kinetic energy from the stored velocities and the solver's node masses
#     (tools/rest_report.py): its peak, the time after which it stays below 1e-6 of the peak
#     ("time to rest"), its last value over the peak and the largest move over the last frame;
#   - S6: the largest distance from the sheet's plane, at 10 s (the squeeze's end) and 20 s;
#   - the zig-zag amplitude and share of tools/sheet_quality.py at the scene's own end time.
# Writes benchmarks/results/models-<host>-<date>.md and docs/images/models/<scene>.png (both
# models at the scene's own end time, side by side).
#   benchmarks/run_models.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh models release cosserat
export OMP_NUM_THREADS=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
springs='model={kind="mass-spring", match="material"}'
# label | scene | own end time (s) | long run's end (s) | frames of the long run
cases=("S1 clothesline|scenes/s1_clothesline.toml|10|20|200"
       "S2 cape|scenes/s2_cape.toml|10|60|600"
       "S6 compression|scenes/s6_compression.toml|20|20|200"
       "sphere drape|scenes/contact/sphere_drape.toml|3|30|300")
mkdir -p docs/images/models
start=$(date +%s)
rows=$work/rows.jsonl
: >"$rows"
for case in "${cases[@]}"; do
  IFS='|' read -r label scene own until frames <<<"$case"
  name=$(basename "$scene" .toml)
  for model in cosserat mass-spring; do
    extra=()
    [[ $model == mass-spring ]] && extra=(--set "$springs")
    if grep -q '^dt *=' "$scene"; then
      dt=$(sed -n 's/^dt *= *\([0-9.e-]*\).*/\1/p' "$scene")
      steps=$(/usr/bin/python3 -c "print(round($until / $dt))")
      length=(--set "time.steps=$steps" --set "time.output_every=$((steps / frames))")
    else
      length=(--set "time.duration=$until" --set "time.output_dt=$(
        /usr/bin/python3 -c "print($until / $frames)")")
    fi
    rc=0
    build/release/cosserat run "$scene" -q --threads 1 -o "$work/$name-$model.h5" \
      --summary "$work/$name-$model.json" "${extra[@]}" "${length[@]}" \
      >/dev/null 2>"$work/$name-$model.err" || rc=$?
    for round in 1 2 3; do
      build/release/cosserat run "$scene" -q --threads 1 -o "$work/timed.h5" --overwrite \
        --summary "$work/$name-$model.timed$round.json" --set 'output.fields=[]' "${extra[@]}" \
        >/dev/null 2>>"$work/$name-$model.err" || true
    done
    build/release/cosserat stable-dt "$scene" -q --threads 1 --time "$own" \
      --csv "$work/$name-$model.csv" "${extra[@]}" >/dev/null 2>>"$work/$name-$model.err" || true
    /usr/bin/python3 tools/sheet_quality.py "$work/$name-$model.h5" --json \
      >"$work/$name-$model.q.json" 2>>"$work/$name-$model.err" || true
    /usr/bin/python3 - "$work/$name-$model" "$label" "$model" "$rc" "$own" >>"$rows" <<'PY'
import csv, json, sys, tomllib
import h5py, numpy as np
sys.path.insert(0, "tools")
import rest_report
stem, label, model, rc, own = sys.argv[1:]
own = float(own)
s = json.load(open(stem + ".json"))
timed = [json.load(open(f"{stem}.timed{i}.json")) for i in (1, 2, 3)]
best = max(timed, key=lambda t: t["node_steps_per_second"])
row = {"label": label, "model": model, "exit": int(rc), "steps": s["steps"],
       "sim_time": s["sim_time"], "node_steps_per_second": best["node_steps_per_second"],
       "wall": best["wall_seconds"], "own_steps": best["steps"]}
with h5py.File(stem + ".h5") as f:
    r, t, v = f["positions"][:], f["time"][:], f["fields/velocity"][:]
    scene = tomllib.loads(f.attrs["scene"])
if model == "mass-spring":
    scene.setdefault("model", {})["kind"] = "mass-spring"
frames, m, n, _ = r.shape
g = np.array(scene.get("environment", {}).get("gravity", [0.0, -9.8, 0.0]))
mass = rest_report.node_masses(scene, m, n, r[-1], g, stem + ".json")
kinetic = 0.5 * (mass * (v ** 2).sum(axis=-1)).sum(axis=(1, 2))
peak = kinetic.max()
above = np.nonzero(kinetic >= 1e-6 * peak)[0]
row.update(peak_kinetic=peak, peak_time=float(t[kinetic.argmax()]),
           rest_time=float(t[above[-1] + 1]) if above[-1] + 1 < frames else None,
           end_over_peak=kinetic[-1] / peak,
           last_move=float(np.linalg.norm(r[-1] - r[-2], axis=-1).max()))
for at in (10.0, 20.0):
    i = int(np.abs(t - at).argmin())
    if abs(t[i] - at) < 1e-9 and scene.get("environment", {}).get("gravity") == [0.0, 0.0, 0.0]:
        row[f"off_plane_{int(at)}"] = float(np.abs(r[i, :, :, 1]).max())
with open(stem + ".csv") as f:
    stable = list(csv.DictReader(f))
if stable:
    row.update(stable_dt=float(stable[0]["stable_dt"]), cfl_dt=float(stable[0]["cfl_dt"]))
try:
    q = json.load(open(stem + ".q.json"))
    own_frame = min(q["frames"], key=lambda fr: abs(fr["time"] - own))
    row["zigzag_share"] = own_frame.get("zigzag_fraction")
    row["zigzag_amplitude"] = own_frame.get("zigzag_amplitude")
except (OSError, ValueError, KeyError):
    pass
print(json.dumps(row))
PY
    /usr/bin/python3 tools/render.py "$work/$name-$model.h5" --time "$own" \
      --output "$work/$name-$model.png" >/dev/null 2>>"$work/$name-$model.err" ||
      echo "render of $name $model failed" >&2
    echo "$(date +%T) $label $model: exit $rc" >&2
  done
  /usr/bin/python3 - "$work/$name" "docs/images/models/$name.png" <<'PY'
import sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
stem, out = sys.argv[1:]
fig, axes = plt.subplots(1, 2, figsize=(12, 5.2))
for ax, model in zip(axes, ("cosserat", "mass-spring")):
    ax.imshow(plt.imread(f"{stem}-{model}.png"))
    ax.set_title({"cosserat": "Cosserat (energy form)",
                  "mass-spring": "mass-spring, matched springs"}[model])
    ax.axis("off")
fig.tight_layout()
fig.savefig(out, dpi=90)
PY
done
total=$(($(date +%s) - start))
/usr/bin/python3 - "$rows" "$stem.md" "$date" "$cpu" "$compiler" "$revision" "$total" <<'PY'
import json, sys
rows_path, out, date, cpu, compiler, revision, total = sys.argv[1:]
rows = [json.loads(l) for l in open(rows_path)]
def f(x, spec):
    return "—" if x is None else format(x, spec)
with open(out, "w") as o:
    o.write(f"# The two force models side by side, {date}\n\n")
    o.write(f"Machine: {cpu}; compiler: {compiler}, release; git {revision}; 1 rank x 1 thread, one "
            f"run at a time; {int(total) // 60} min {int(total) % 60} s in all.\n")
    o.write("`benchmarks/run_models.sh`: each scene as shipped and with `model = { kind = "
            "\"mass-spring\", match = \"material\" }` (docs/models.md, \"Matched springs\"). "
            "Node-steps/s and wall time: the scene as shipped, best of three runs writing no "
            "fields (frames of positions included); steps: the long run's; "
            "stable dt: `cosserat stable-dt` over the scene's own duration, fixed steps; kinetic "
            "energy from the stored velocities and the solver's node masses; rest: the time "
            "after which it stays below 1e-6 of its peak; zig-zag: tools/sheet_quality.py's "
            "amplitude (m) and share at the scene's own end time.\n\n")
    o.write("| scene | model | exit | node-steps/s | wall as shipped (s) | run to (s) | steps | "
            "stable dt (s) | "
            "CFL estimate (s) | peak kinetic (J) | rest at (s) | kinetic at the end / peak | "
            "last frame's largest move (m) | off the plane at 10 s / 20 s (m) | zig-zag (m, share) |\n")
    o.write("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        plane = "—"
        if "off_plane_10" in r:
            plane = f"{r['off_plane_10']:.3g} / {r.get('off_plane_20', float('nan')):.3g}"
        o.write(f"| {r['label']} | {r['model']} | {r['exit']} | "
                f"{r['node_steps_per_second']:.3g} | {r['wall']:.3g} | {r['sim_time']:.4g} | "
                f"{r['steps']} | {f(r.get('stable_dt'), '.4g')} | "
                f"{f(r.get('cfl_dt'), '.4g')} | {r['peak_kinetic']:.3g} | "
                f"{f(r['rest_time'], '.3g')} | {r['end_over_peak']:.2e} | {r['last_move']:.2e} | "
                f"{plane} | {f(r.get('zigzag_amplitude'), '.2g')}, "
                f"{f(r.get('zigzag_share'), '.2f')} |\n")
print(open(out).read())
PY
