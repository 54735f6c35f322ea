#!/usr/bin/env bash
# The semi-implicit step on the contact scenes users run (issue 30, item 7;
# docs/integrator-study.md, "Explicit against semi-implicit: real fabrics on solids"): the
# gallery's linen tablecloth on a round table (scenes/gallery/tablecloth_round.toml) and a 1 m
# cotton sheet dropped on a sphere of radius 0.3 m, each on 51² and 101² nodes, 1 s simulated,
# Verlet at the gallery's step (half the CFL estimate) and at 0.9 of the estimate against
# semi-implicit-2 at 0.25, 1 and 2.5 ms (rtol 1e-6, a Jacobian every 5 steps). Writes
# benchmarks/results/si-scenes-<host>-<date>.md (wall time, status, RMS and largest distance
# at 1 s to the Verlet run at half the CFL step, deepest penetration, kinetic energy at 1 s)
# and -pictures.png (every run's frame at 1 s). One run
# at a time, one thread: about 20 min on the 2-core VM.
#   benchmarks/run_semi_implicit_scenes.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh si-scenes release cosserat
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1
sphere=$work/sphere_cotton.toml
cat > "$sphere" <<'TOML'
title = "1 m cotton sheet dropped on a sphere"

[grid]
nodes = [51, 51]
size = [1.0, 1.0]
origin = [-0.5, 0.35, -0.5]
u = [1.0, 0.0, 0.0]
v = [0.0, 0.0, 1.0]

[material]
preset = "cotton"

[environment]
gravity = [0.0, -9.81, 0.0]
damping = 0.25

[time]
integrator = "verlet"
dt = 3e-5
duration = 1.0
output_dt = 0.25

[[solid]]
name = "sphere"
shape = "sphere"
center = [0.0, 0.0, 0.0]
radius = 0.3
friction = 0.5
thickness = 0.003
TOML
runs=()
for scene in scenes/gallery/tablecloth_round.toml "$sphere"; do
  label=$(basename "$scene" .toml)
  for nodes in 51 101; do
    # Half the CFL estimate (the gallery's choice) and 0.9 of it, which the Verlet family
    # reaches without contact (docs/integrator-study.md); h halves from 51² to 101².
    case $label-$nodes in
      tablecloth_round-51) half=6e-5 near=1.08e-4 ;;
      tablecloth_round-101) half=3e-5 near=5.4e-5 ;;
      sphere_cotton-51) half=3e-5 near=5.4e-5 ;;
      sphere_cotton-101) half=1.5e-5 near=2.7e-5 ;;
    esac
    for case in "verlet $half" "verlet $near" "semi-implicit-2 2.5e-4" "semi-implicit-2 1e-3" \
      "semi-implicit-2 2.5e-3"; do
      set -- $case
      run=$work/$label-$nodes-$1-$2
      solver=()
      [ "$1" = verlet ] || solver=(--set time.solver.rtol=1e-6 --set time.solver.jacobian_every=5)
      status=0
      build/release/cosserat run "$scene" -q -o "$run.h5" --summary "$run.json" \
        --set "grid.nodes=[$nodes, $nodes]" --set "time.integrator=\"$1\"" --set "time.dt=$2" \
        --set time.duration=1.0 --set time.output_dt=0.25 "${solver[@]}" || status=$?
      echo "$label $nodes² $1 Δt $2: exit $status"
      /usr/bin/python3 tools/render.py "$run.h5" --output "$run.png" --frame -1 \
        --title "$label $nodes² $1 Δt $2 s, last frame" >/dev/null 2>&1 || true
      runs+=("$label,$nodes,$1,$2,$run")
    done
  done
done
/usr/bin/python3 - "$stem" "$cpu, $(nproc --all) cores, $host" "$compiler" "$revision" "$date" "${runs[@]}" <<'PY'
import json, sys
from pathlib import Path
import h5py, numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
stem, machine, compiler, revision, date, *runs = sys.argv[1:]
lines = ["# The semi-implicit step on real fabrics on solids", "",
         f"- machine: {machine}", f"- build: {compiler}, release (-O3), git {revision}",
         f"- date: {date}", "- ranks x threads: 1 x 1, one run at a time",
         "- written by benchmarks/run_semi_implicit_scenes.sh", "",
         "| scene | grid | integrator | Δt (s) | wall (s) | status | reached t (s) | RMS / largest distance to Verlet at 1 s (m) | deepest penetration (m) | kinetic energy at the end (J) | iterations/step |",
         "|---|---|---|---|---|---|---|---|---|---|---|"]
verlet = {}
for run in runs:
    label, nodes, integrator, dt, path = run.split(",")
    summary = json.loads(Path(path + ".json").read_text()) if Path(path + ".json").exists() else {}
    last = None
    if Path(path + ".h5").exists() and summary.get("sim_time", 0) >= 1.0 - 1e-9:
        with h5py.File(path + ".h5") as f:
            last = np.array(f["positions"][-1]).reshape(-1, 3)
    if integrator == "verlet" and (label, nodes) not in verlet:
        verlet[(label, nodes)] = last
    ref = verlet.get((label, nodes))
    distance = "—"
    if last is not None and ref is not None and integrator != "verlet":
        d = np.linalg.norm(last - ref, axis=1)
        distance = f"{np.sqrt(np.mean(d ** 2)):.3g} / {d.max():.3g}"
    solves = summary.get("linear_solves") or {}
    iterations = f"{solves['mean_iterations']:.1f}" if solves else ""
    lines.append(f"| {label} | {nodes}² | {integrator} | {dt} | {summary.get('wall_seconds', float('nan')):.3g} | "
                 f"{summary.get('status')} | {summary.get('sim_time', float('nan')):.3g} | {distance} | {summary.get('max_penetration')} | "
                 f"{summary.get('kinetic_energy', float('nan')):.3g} | {iterations} |")
Path(stem + ".md").write_text("\n".join(lines) + "\n")
print("\n".join(lines))
pictures = [run.split(",")[4] + ".png" for run in runs]
fig, axes = plt.subplots(len(pictures) // 4, 4, figsize=(20, 4.2 * (len(pictures) // 4)))
for ax, picture in zip(axes.flat, pictures):
    ax.axis("off")
    if Path(picture).exists():
        ax.imshow(plt.imread(picture))
fig.tight_layout()
fig.savefig(stem + "-pictures.png", dpi=80)
PY
