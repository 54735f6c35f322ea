#!/usr/bin/env bash
# Largest stable Δt of a scene and integrator over a fixed simulated time, by bisection on the
# run's exit status (3 = the stability monitor stopped it; SCENES.md: never by eye).
#   benchmarks/stable_dt.sh SCENE [INTEGRATOR] [SIM_TIME] [TOLERANCE]
# Prints the bracket [stable, unstable]; the answer is the stable end.
set -euo pipefail
scene=$1
integrator=${2:-verlet}
sim_time=${3:-10}
tolerance=${4:-0.005}
exe=${COSSERAT:-build/release/cosserat}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

stable() {  # exit status 0 of a whole run at Δt = $1
  local steps
  steps=$(/usr/bin/python3 -c "import math; print(math.ceil($sim_time / $1))")
  "$exe" run "$scene" -q --set time.integrator="\"$integrator\"" --set time.dt="$1" \
    --set time.steps="$steps" --set time.output_every="$steps" -o "$out/run.h5" 2>/dev/null
}

low=0.0005
high=0.1
stable "$low" || { echo "unstable even at dt = $low" >&2; exit 1; }
while /usr/bin/python3 -c "import sys; sys.exit(0 if ($high - $low) / $low > $tolerance else 1)"; do
  mid=$(/usr/bin/python3 -c "print(f'{($low + $high) / 2:.6g}')")
  if stable "$mid"; then low=$mid; else high=$mid; fi
done
echo "$scene $integrator T=$sim_time s: largest stable dt in [$low, $high]"
