#!/usr/bin/env bash
# Writes an S1-like scene (docs/scenes.md S1: the 10 m x 10 m, 10 kg reference sheet hung from the
# two corners of one edge, gravity, damping 0.2, Verlet) on a NODES x NODES grid to FILE.
# S1's own file names its corners by index for its 10 x 10 grid; here they follow NODES. The
# step is 0.02 h²: on fine grids bending sets the largest stable Verlet step, which shrinks
# with h² (docs/stability.md): measured 0.071 h² on 120 x 120 and 240 x 240
# (`cosserat stable-dt`, docs/integrator-study.md), so 0.02 h² keeps a margin of 3.5.
#   jobs/make_large_sheet.sh NODES STEPS FILE
set -euo pipefail
nodes=$1
steps=$2
file=$3
dt=$(/usr/bin/python3 -c "print(f'{0.02 * (10.0 / ($nodes - 1)) ** 2:.6g}')")
last=$((nodes - 1))
every=$(( steps / 10 > 0 ? steps / 10 : 1 ))
cat > "$file" <<TOML
# S1-like large sheet, written by jobs/make_large_sheet.sh $nodes $steps
title = "S1-like sheet $nodes x $nodes"

[grid]
nodes = [$nodes, $nodes]
size = [10.0, 10.0]
origin = [0.0, 0.0, 0.0]
u = [1.0, 0.0, 0.0]
v = [0.0, 0.0, 1.0]

[material]
mass = 10.0
zeta = 100.0
xi = 0.3
phi = 0.001

[environment]
gravity = [0.0, -9.8, 0.0]
damping = 0.2

[time]
integrator = "verlet"
dt = $dt
steps = $steps
output_every = $every

[[fix]]
nodes = [[0, 0], [0, $last]]
TOML
