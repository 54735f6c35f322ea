#!/usr/bin/env bash
# The semi-implicit baseline's linear solver: Krylov iterations per step and where a step's time
# goes (finite-difference Jacobian against solve) for Krylov methods and preconditioners, on S1
# at three times the CFL estimate and on a 60 x 60 hanging sheet at twice it; Verlet's time
# per step beside. Writes benchmarks/results/semi-implicit-<host>-<date>.md.
#   benchmarks/run_semi_implicit.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh semi-implicit release cosserat
export OMP_NUM_THREADS=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bash jobs/make_large_sheet.sh 60 100 "$work/hanging60.toml"

# scene label, scene file, dt, steps
cases=("S1|scenes/s1_clothesline.toml|0.04|100" "hanging 60x60|$work/hanging60.toml|0.004|50")
solvers=("gmres bjacobi" "gmres jacobi" "gmres sor" "gmres none" "gmres gamg" "bcgs bjacobi" "cg jacobi")
{
  echo "# Semi-implicit baseline: linear solver choices, $date"
  echo
  echo "Machine: $cpu; compiler: $compiler, release; git $revision; 1 rank x 1 thread."
  echo "\`benchmarks/run_semi_implicit.sh\`; rtol 1e-10, initial guess d = r^n - r^(n-1)."
  echo
  echo "| scene | dt (s) | KSP | PC | iterations / step (most) | Jacobian s / step | solve s / step | status |"
  echo "|---|---|---|---|---|---|---|---|"
  for case in "${cases[@]}"; do
    IFS='|' read -r label scene dt steps <<<"$case"
    for solver in "${solvers[@]}"; do
      read -r ksp pc <<<"$solver"
      build/release/cosserat run "$scene" -q --overwrite -o "$work/o.h5" --summary "$work/s.json" \
        --set time.integrator='"semi-implicit"' --set time.dt="$dt" --set time.steps="$steps" \
        --set time.output_every="$steps" --set time.solver.ksp="\"$ksp\"" \
        --set time.solver.pc="\"$pc\"" >/dev/null 2>&1 || true
      /usr/bin/python3 - "$work/s.json" "$label" "$dt" "$ksp" "$pc" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); label, dt, ksp, pc = sys.argv[2:]
l = s["linear_solves"]; n = max(l["solves"], 1)
print(f"| {label} | {dt} | {ksp} | {pc} | {l['mean_iterations']:.2f} ({l['most_iterations']}) | "
      f"{l['jacobian_seconds'] / n:.2e} | {(l['solve_seconds']) / n:.2e} | {s['status']} |")
PY
    done
    build/release/cosserat run "$scene" -q --overwrite -o "$work/o.h5" --summary "$work/s.json" \
      --set time.dt=0.001 --set time.steps=2000 --set time.output_every=2000 >/dev/null 2>&1
    /usr/bin/python3 -c "
import json; s = json.load(open('$work/s.json'))
print(f'| $label | 0.001 | verlet (explicit) | — | — | — | {s[\"wall_seconds\"] / s[\"steps\"]:.2e} (whole step) | {s[\"status\"]} |')"
  done
} | tee "$stem.md"
