#!/usr/bin/env bash
# The contact experiments of docs/contact.md ("Scenes") with the mass-spring model
# (docs/models.md, "The source's experiments"): the cube thrown into the net at 25 N and 500 N
# with the source's springs (15 g particles; the presets source-net, every family ke = 100 N/m,
# kd = 20 N s/m, and source-stiff-net, 250 and 50), rupture at 2 rest lengths and, for the
# 500 N throw, at 1.3; the sheet pressed onto the plane (10 g particles, source-pressed-sheet,
# ke = 1000 N/m, kd = 200 N s/m). Per run: the longest unbroken structural spring, the springs
# broken, the cube's lowest point and rebound, and how far the cloth came to the plane. Writes
# benchmarks/results/spring-contact-<host>-<date>.md.
#   benchmarks/run_spring_contact.sh
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh spring-contact release cosserat
export OMP_NUM_THREADS=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
springs() {  # preset [rupture length]
  echo "model={kind=\"mass-spring\", preset=\"$1\"${2:+, rupture_length=$2}}"
}
# label | scene | particle mass | springs
cases=("net, 25 N, ke 100|contact/cube_net_25|0.015|$(springs source-net 2.0)"
       "net, 25 N, ke 250|contact/cube_net_25|0.015|$(springs source-stiff-net 2.0)"
       "net, 500 N, ke 100|contact/cube_net_500|0.015|$(springs source-net 2.0)"
       "net, 500 N, ke 250|contact/cube_net_500|0.015|$(springs source-stiff-net 2.0)"
       "net, 500 N, ke 100, rupture 1.3|contact/cube_net_500|0.015|$(springs source-net 1.3)"
       "pressed sheet, 10 N to 10^4 N|contact/pressed_sheet|0.01|$(springs source-pressed-sheet)")
{
  echo "# The contact experiments with the mass-spring model, $date"
  echo
  echo "Machine: $cpu; compiler: $compiler, release; git $revision; 1 rank x 1 thread."
  echo "\`benchmarks/run_spring_contact.sh\`: the scenes of scenes/contact with"
  echo "\`--set material={particle_mass=...}\` and \`--set model={kind=\"mass-spring\", ...}\`, every"
  echo "spring family alike. Stretch: the longest unbroken structural spring over the run, in rest"
  echo "lengths. The cube's rebound: its highest point after its lowest, and how far it is then"
  echo "from the vertical line through the impact point."
  echo
  echo -n "| run | status | wall (s) | longest spring | springs broken | cube lowest y (m) | "
  echo "rebound top y (m) | off the line at the top (m) | lowest cloth y (m) |"
  echo "|---|---|---|---|---|---|---|---|---|"
  for case in "${cases[@]}"; do
    IFS='|' read -r label scene mass model <<<"$case"
    build/release/cosserat run "scenes/$scene.toml" -q --overwrite -o "$work/o.h5" \
      --summary "$work/s.json" --set "material={particle_mass=$mass}" --set "$model" \
      >/dev/null 2>&1 || true
    /usr/bin/python3 - "$work/o.h5" "$work/s.json" "$label" <<'PY'
import json, sys
import h5py, numpy as np
path, summary, label = sys.argv[1:]
s = json.load(open(summary))
with h5py.File(path) as f:
    p = f["positions"][:]
    bits = np.zeros(p.shape[:3], np.int64)
    if "fields/broken_springs" in f:
        bits = f["fields/broken_springs"][:].astype(np.int64)
    h1 = np.linalg.norm(p[0, 1, 0] - p[0, 0, 0]); h2 = np.linalg.norm(p[0, 0, 1] - p[0, 0, 0])
    longest = 0.0
    for frame, b in zip(p, bits):
        a = np.linalg.norm(frame[1:] - frame[:-1], axis=-1) / h1
        c = np.linalg.norm(frame[:, 1:] - frame[:, :-1], axis=-1) / h2
        a[(b[:-1] & 1) == 1] = 0.0
        c[(b[:, :-1] & 2) == 2] = 0.0
        longest = max(longest, a.max(), c.max())
    broken = sum(bin(int(x)).count("1") for x in bits[-1].ravel())
    cells = ["–"] * 3
    if label.startswith("net"):
        cube = f["solids"][sorted(f["solids"].keys(), key=int)[0]]["world_vertices"][:].mean(axis=1)
        low = int(np.argmin(cube[:, 1])); top = low + int(np.argmax(cube[low:, 1]))
        cells = [f"{cube[low, 1]:.3f}", f"{cube[top, 1]:.3f}",
                 f"{np.hypot(*(cube[top, [0, 2]] - cube[low, [0, 2]])):.1e}"]
print(f"| {label} | {s['status']} | {s['wall_seconds']:.1f} | {longest:.3f} | {broken} | "
      + " | ".join(cells) + f" | {p[..., 1].min():.4f} |")
PY
  done
} | tee "$stem.md"
