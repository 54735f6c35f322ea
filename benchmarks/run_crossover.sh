#!/usr/bin/env bash
# Where the semi-implicit step overtakes Verlet (issue 30, item 5; docs/integrator-study.md,
# "Explicit against semi-implicit: the crossover"): the S1-like 10 m sheet held at two corners
# on 60², 120² and 240² grids to T = 1 s; the wall time of the fastest Verlet run and of the
# fastest semi-implicit run within 1e-2, 1e-3 and 1e-4 m of the grid's Verlet reference.
# Writes benchmarks/results/crossover-<host>-<date>{.md,.csv,.png,.log}. Two single-threaded
# runs side by side: about 20 min on the 2-core VM (3.5, 4.5 and 11.5 min a grid). The grids'
# settings are those of the published run (each grid's rows replace that grid's rows in the
# CSV). 480² is not a sweep here: its reference alone takes 11 min and one semi-implicit step
# about a minute (docs/integrator-study.md gives what was measured there).
#   benchmarks/run_crossover.sh [--grids 60,120]
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh crossover release cosserat
dirty=$(git status --porcelain --untracked-files=no 2>/dev/null | grep -q . && echo ", modified" || true)
context=$(/usr/bin/python3 -c 'import json, sys; print(json.dumps(dict(zip(
  ["machine", "build", "date", "ranks x threads"], sys.argv[1:]))))' \
  "$cpu, $(nproc) cores, $host" "$compiler, release (-O3); checkout at git $revision$dirty" \
  "$date" "1 x 1 per run, two runs side by side")
grids=60,120,240
if [ "${1:-}" = --grids ]; then grids=$2; fi
start=$(date +%s)
study() {
  /usr/bin/python3 tools/crossover_study.py --exe build/release/cosserat --out "$stem" \
    --context "$context" "$@"
}
for n in ${grids//,/ }; do
  case $n in
    # Every configuration's whole sweep on the small grids, to see each step's error
    # against Δt; on the large ones only the configurations and steps that could win.
    60) study --grids 60 --cap 1000 --max-steps 1280 \
          --configs semi-implicit:1e-6:1,semi-implicit-2:1e-6:1,semi-implicit:1e-6:5,semi-implicit-2:1e-6:5 ;;
    120) study --grids 120 --cap 100 --max-steps 320 \
          --configs semi-implicit:1e-6:5,semi-implicit-2:1e-6:1,semi-implicit-2:1e-6:5 ;;
    # Only the second-order step (the first needs 4 times its steps for 1e-2 m on the grids
    # below) and Jacobians kept 5 and 10 steps; 40 steps cost 11 times Verlet's run already.
    240) study --grids 240 --cap 15 --si-steps 20,40,80 \
          --configs semi-implicit-2:1e-6:5,semi-implicit-2:1e-6:10 ;;
    *) echo "run_crossover.sh: no settings for grid $n (60, 120, 240)" >&2; exit 2 ;;
  esac
done
echo "run_crossover.sh: $(( ($(date +%s) - start) / 60 )) min $(( ($(date +%s) - start) % 60 )) s"
