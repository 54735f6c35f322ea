#!/usr/bin/env bash
# The mass-spring source's return-to-equilibrium sheets (scenes/springs/equilibrium_4..7.toml,
# docs/models.md "The source's experiments"): the largest coordinate difference and distance
# from rest and the standard deviation of the distances at steps 5000 and 20 000, and sheet 4
# again without its dead zone. Writes
# benchmarks/results/equilibrium-<host>-<date>.md.
#   benchmarks/run_equilibrium.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh equilibrium release equilibrium_sheets
export OMP_NUM_THREADS=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Sheet 4 without its dead zone: how much of the shortfall the zone makes.
sed -e '/^preset = "source-sheet"/a dead_zone = 0.0' scenes/springs/equilibrium_4.toml \
  >"$work/equilibrium_4_without_dead_zone.toml"
{
  echo "# Return to equilibrium of the mass-spring sheets, $date"
  echo
  echo "Machine: $cpu; compiler: $compiler, release; git $revision; 1 rank x 1 thread."
  echo "\`benchmarks/run_equilibrium.sh\`: scenes/springs/equilibrium_4..7.toml (tc-verlet, random"
  echo "steps in [1/110, 1/60] s, each scene its own seed)."
  echo
  build/release/benchmarks/equilibrium_sheets scenes/springs/equilibrium_{4,5,6,7}.toml \
    "$work/equilibrium_4_without_dead_zone.toml"
} | tee "$stem.md"
