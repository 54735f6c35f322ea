#!/usr/bin/env python3
"""Whether a run came to rest (docs/contact.md, "Resting contact").

    /usr/bin/python3 tools/rest_report.py OUT.h5 [--summary OUT.json] [--table] [--from T]

From the frames of OUT.h5 (docs/output.md; the `velocity` and `energy_density` fields): the
kinetic energy from the stored velocities, its peak and its last value over the peak; the same
from the frames' own motion (|r_f - r_f-1| / dt between frames), which a velocity that says more
than the nodes moved cannot match, and which a swing faster than the frames also reads low (the
napkin's crease swung at 7 kHz through micrometres, docs/contact.md "Self-contact": a run
continued from a checkpoint with --set time.output_dt=<its step> tells the two apart); the
largest node move over the last frame; and the total energy, kinetic + gravitational (-sum m
g.r) + elastic (energy_density times the rest dual area), with the frames where it rose. Loads,
moving solids and free bodies do work this total does not count. The node masses are the
discretisation's (docs/model.md, "Energy quadrature"): mu0 h1 h2 times the node's share of the
dual area (1 inside, 1/2 on a border, 1/4 at a corner) in the default energy form, mu0 h1 h2 at
every node in energy-nodal, M / (m n) in flux and in the mass-spring model; mu0 from the scene's
material.mass (or density), or for a preset read back from the run summary's gravitational
energy (--summary).
--table prints about 25 frames. --from T counts the rises only from time T on (after moving fixes,
loads or solids have stopped doing work).
"""

import argparse
import json
import os
import sys
import tomllib

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402
import numpy as np  # noqa: E402


def shares(scene, m, n):
    """Each node's share of the dual area, and the cell count the masses divide M by."""
    model = scene.get("model", {})
    discretisation = model.get("discretisation", "energy")
    if discretisation == "flux" or model.get("kind") == "mass-spring":
        return np.ones((m, n)), m * n
    if discretisation == "energy-nodal":
        return np.ones((m, n)), (m - 1) * (n - 1)
    wk = np.ones(m)
    wk[[0, -1]] = 0.5
    wl = np.ones(n)
    wl[[0, -1]] = 0.5
    return np.outer(wk, wl), (m - 1) * (n - 1)


def node_masses(scene, m, n, last, gravity, summary):
    material = scene.get("material", {})
    size = scene["grid"]["size"]
    share, cells = shares(scene, m, n)
    if "mass" in material:
        return material["mass"] / cells * share
    if "density" in material:
        return material["density"] * size[0] * size[1] / cells * share
    if summary is None:
        raise SystemExit("a preset's mass is not in the output file: give --summary")
    # The summary's −Σ m g·r at the last step, the last frame.
    weighted = (share[..., None] * last).reshape(-1, 3) @ gravity
    return json.load(open(summary))["gravitational_energy"] / -weighted.sum() * share


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("h5")
    ap.add_argument("--summary", help="the run's --summary file (for a preset's mass)")
    ap.add_argument("--table", action="store_true", help="print about 25 frames")
    ap.add_argument("--from", dest="start", type=float, default=0.0,
                    help="count the rises of the total energy from this time on (s)")
    args = ap.parse_args()
    with h5py.File(args.h5, "r") as f:
        r = f["/positions"][:]
        t = f["/time"][:]
        if "/fields/velocity" not in f or "/fields/energy_density" not in f:
            raise SystemExit(f"{args.h5}: needs the velocity and energy_density fields")
        v = f["/fields/velocity"][:]
        density = f["/fields/energy_density"][:]
        scene = tomllib.loads(f.attrs["scene"])
    frames, m, n, _ = r.shape
    g = np.array(scene.get("environment", {}).get("gravity", [0.0, -9.8, 0.0]))
    mass = node_masses(scene, m, n, r[-1], g, args.summary)
    size = scene["grid"]["size"]
    cell = size[0] / (m - 1) * size[1] / (n - 1)
    # energy_density stands for each node's dual area (docs/output.md).
    dual = cell * shares(scene, m, n)[0]
    kinetic = 0.5 * (mass * (v ** 2).sum(axis=-1)).sum(axis=(1, 2))
    total = (kinetic - (mass * (r @ g)).sum(axis=(1, 2)) + (density * dual).sum(axis=(1, 2)))
    move = np.zeros(frames)
    kinetic_moved = np.zeros(frames)
    for i in range(1, frames):
        d = np.linalg.norm(r[i] - r[i - 1], axis=-1)
        move[i] = d.max()
        kinetic_moved[i] = 0.5 * (mass * (d / (t[i] - t[i - 1])) ** 2).sum()
    counted = t[1:] > args.start
    rise = np.where(counted, np.diff(total), -np.inf)
    risen = rise > 1e-12 * np.abs(total).max()
    peak = kinetic.max()
    speed_end = move[-1] / (t[-1] - t[-2]) if frames > 1 else 0.0
    print(f"{args.h5}: {frames} frames to t = {t[-1]:.4g} s, {m} x {n} nodes")
    print(f"  kinetic energy: peak {peak:.3g} J at t = {t[kinetic.argmax()]:.3g} s, at the end "
          f"{kinetic[-1]:.3g} J ({kinetic[-1] / peak:.2e} of the peak); from the frames' motion "
          f"{kinetic_moved[-1]:.3g} J")
    print(f"  at the end: largest stored speed {np.linalg.norm(v[-1], axis=-1).max():.3g} m/s, "
          f"largest move over the last frame {move[-1]:.3g} m ({speed_end:.3g} m/s)")
    since = f" after t = {args.start:.4g} s" if args.start > 0.0 else ""
    when = f" (t = {t[1 + rise.argmax()]:.3g} s)" if counted.any() else ""
    print(f"  total energy rose in {int(risen.sum())} of {int(counted.sum())} frames{since}, at "
          f"most {rise.max():.3g} J{when}")
    if args.table:
        for i in range(0, frames, max(1, frames // 25)):
            print(f"  t = {t[i]:8.3f}  kinetic {kinetic[i]:.3e}  from motion "
                  f"{kinetic_moved[i]:.3e}  total {total[i]:.7e}  largest move {move[i]:.2e}")


if __name__ == "__main__":
    main()
