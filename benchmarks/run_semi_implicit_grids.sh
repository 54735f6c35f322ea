#!/usr/bin/env bash
# The semi-implicit baseline against grid size: for the S1-like hanging sheet on N x N nodes
# (jobs/make_large_sheet.sh), one rank x one thread, the cost of one semi-implicit step of 5 ms
# (the Jacobian, the preconditioner's set-up, the Krylov iterations) for each Krylov method and
# preconditioner, in Verlet steps of the same grid at its own stable step (0.02 h^2).
# Writes benchmarks/results/semi-implicit-grids-<host>-<date>.md.
#   benchmarks/run_semi_implicit_grids.sh [GRIDS...]   (default: 120 240 480)
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh semi-implicit-grids release cosserat
export OMP_NUM_THREADS=1
grids=("$@")
[ ${#grids[@]} -gt 0 ] || grids=(120 240 480)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
steps=3
# integrator | KSP | PC | rtol | jacobian_every (3: one Jacobian and preconditioner for the run)
solvers=("semi-implicit|gmres|bjacobi|1e-10|1" "semi-implicit|cg|icc|1e-10|1"
         "semi-implicit|cg|hypre|1e-10|1" "semi-implicit|cg|gamg|1e-10|1"
         "semi-implicit|cg|gamg|1e-6|1" "semi-implicit|cg|gamg|1e-10|3"
         "semi-implicit-2|cg|gamg|1e-10|1")
{
  echo "# Semi-implicit step against grid size, $date"
  echo
  echo "Machine: $cpu; compiler: $compiler, release; git $revision; 1 rank x 1 thread."
  echo "\`benchmarks/run_semi_implicit_grids.sh ${grids[*]}\`: the S1-like hanging sheet"
  echo "(jobs/make_large_sheet.sh), $steps semi-implicit steps of 5 ms from rest, seconds per step"
  echo "from the run summary (Jacobian + solve: the set-up of PETSc's objects before the first step"
  echo "is left out); Verlet's step at 0.02 h^2, wall time per step over 400 steps."
  echo "A failed row (status not ok) is a solve that did not converge in 1000 iterations or a"
  echo "step the stability check stopped."
  echo
  echo "| grid | integrator | KSP | PC | rtol | jacobian_every | iterations / step | Jacobian s | PC set-up s | iterations s | step s | in Verlet steps | status |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  for n in "${grids[@]}"; do
    bash jobs/make_large_sheet.sh "$n" 400 "$work/sheet.toml"
    build/release/cosserat run "$work/sheet.toml" -q --overwrite -o "$work/o.h5" \
      --summary "$work/v.json" --set time.output_every=400 >/dev/null 2>&1
    for solver in "${solvers[@]}"; do
      IFS='|' read -r integrator ksp pc rtol every <<<"$solver"
      build/release/cosserat run "$work/sheet.toml" -q --overwrite -o "$work/o.h5" \
        --summary "$work/s.json" --set time.integrator="\"$integrator\"" --set time.dt=0.005 \
        --set time.steps=$steps --set time.output_every=$steps \
        --set time.solver.ksp="\"$ksp\"" --set time.solver.pc="\"$pc\"" \
        --set time.solver.rtol="$rtol" --set time.solver.jacobian_every="$every" \
        >/dev/null 2>&1 || true
      /usr/bin/python3 - "$work/s.json" "$work/v.json" "$n" "$integrator" "$ksp" "$pc" "$rtol" \
        "$every" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); v = json.load(open(sys.argv[2]))
n, integrator, ksp, pc, rtol, every = sys.argv[3:]
l = s["linear_solves"]; k = max(l["solves"], 1)
verlet = v["wall_seconds"] / v["steps"]
jac, solve, setup = l["jacobian_seconds"] / k, l["solve_seconds"] / k, l["setup_seconds"] / k
step = jac + solve
print(f"| {n}² | {integrator} | {ksp} | {pc} | {rtol} | {every} | {l['mean_iterations']:.1f} | {jac:.3f} | "
      f"{setup:.3f} | {solve - setup:.3f} | {step:.3f} | {step / verlet:.0f} (Verlet "
      f"{verlet * 1e3:.2f} ms) | {s['status']} |")
PY
    done
  done
} | tee "$stem.md"
