#!/usr/bin/python3
"""Speed against total error, space and time together (issue 28, item 4), for both energy
quadratures: model.discretisation = "energy" (trapezoidal, second order) and "energy-nodal"
(the previous default, first order).

  hung  a 10 m square sheet of cotton-10m with phi = 0 hung from its whole top edge under
        gravity and damping: its exact rest state is 1-D, 3 zeta lambda (lambda^2 - 1) =
        mu0 g (L - X). Square grids and strips 3 nodes across (checked to give the same state),
        each at 0.9 x its largest stable Verlet step, run to T with a frame every 0.05 s: the
        settle time to each target is the first frame from which the total error (bottom-centre
        node, and the largest over the centre line) stays within it; the cheapest runs are then
        timed again (3 repetitions) stopped at that frame.
  s1    an S1-like sheet (S1's sheet, material, gravity, damping; held by the x1 = 0 edge
        segments of 10/9 m at each end, the "segments" support of tools/parity_study.py) on
        nested grids of 9 * 2^j + 1 nodes a side, each at 0.9 x its largest stable step and
        halvings of it, to T = 2 s; total error = distance at T to the finest trapezoidal grid
        (289 nodes a side), the largest (and RMS) over the run's own nodes.

Writes STEM.csv (every run), STEM.md, STEM-work-precision.png and STEM.log. Used by
benchmarks/run_total_error.sh, which records the context. One cosserat process at a time,
1 thread (--threads 1, OMP_NUM_THREADS=1).

  /usr/bin/python3 tools/total_error_study.py --exe COSSERAT --out STEM [--parts hung,s1]
      [--quick] [--context JSON] [--report-only]
"""

import argparse
import csv
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

from parity_study import LoggedStudy, s1_like_scene, write_csv

DISCS = ["energy", "energy-nodal"]
LABEL = {"energy": "trapezoidal (\"energy\")", "energy-nodal": "nodal (\"energy-nodal\")"}
TARGETS = [1e-2, 1e-3, 1e-4]
# The work-precision plot's targets for the hung sheet: quarter decades, 1e-1 to 1e-5 m.
PLOT_TARGETS = [float(f"{10 ** (-k / 4):.3g}") for k in range(4, 21)]
SAFETY = 0.9  # the runs' step: this fraction of stable-dt's largest stable step

# The hung sheet: cotton-10m (docs/materials.md) with phi = 0, as in
# tests/unit/test_quadrature.cpp's HungSheet{100.0, 0.88, 9.8, 10.0}.
ZETA, XI, MU0, G, L = 100.0, 0.02, 0.88, 9.8, 10.0
HUNG_DAMPING = 7.5  # kg/(m^2 s): the fastest settling of a 21 x 21 scan (docs/integrator-study.md)
FRAME = 0.05        # s between the hung sweep's frames
# S1's sheet.
S1_ZETA, S1_XI, S1_MU0 = 100.0, 0.3, 0.1


def cfl(size_k, size_l, nk, nl, zeta, xi, mu0):
    """The CFL estimate of docs/stability.md: (membrane, bending) in seconds."""
    h1, h2 = size_k / (nk - 1), size_l / (nl - 1)
    c_l, c_s = math.sqrt(6 * zeta / mu0), math.sqrt(zeta / mu0)
    membrane = min(1 / math.sqrt(c_l ** 2 / h1 ** 2 + c_s ** 2 / h2 ** 2),
                   1 / math.sqrt(c_s ** 2 / h1 ** 2 + c_l ** 2 / h2 ** 2))
    bending = min(h1, h2) ** 2 / (2 * math.sqrt(6 * xi / mu0))
    return membrane, bending


def exact_hung(X):
    """Exact downward displacement ∫0^X lambda dX' of the rest state, at each X (metres from
    the top): Gauss-Legendre with 64 points on [0, X] (lambda is analytic on [0, L]), lambda
    from 3 zeta lambda (lambda^2 - 1) = mu0 g (L - X) by Newton's method."""
    x, w = np.polynomial.legendre.leggauss(64)
    X = np.asarray(X, dtype=float)
    s = 0.5 * X[:, None] * (x[None, :] + 1.0)
    tension = MU0 * G * (L - s)
    lam = np.ones_like(s)
    for _ in range(60):
        lam -= (3 * ZETA * lam * (lam ** 2 - 1) - tension) / (3 * ZETA * (3 * lam ** 2 - 1))
    return 0.5 * X * (lam * w[None, :]).sum(axis=1)


class Study(LoggedStudy):
    def __init__(self, args):
        self.exe = args.exe
        self.stem = args.out
        self.quick = args.quick
        self.keep = args.keep
        self.work = Path(tempfile.mkdtemp(prefix="cosserat-total-error-"))
        self.count = 0
        self.kept = {}  # S1 runs' final positions by (discretisation, nodes, dt)
        super().__init__(self.stem)

    def scene(self, text):
        self.count += 1
        path = self.work / f"scene-{self.count}.toml"
        path.write_text(text)
        return str(path)

    # ------------------------------------------------------------------------------------------
    def stable_dt(self, scene, disc, duration):
        path = self.work / f"stable-{self.count}.csv"
        command = [self.exe, "stable-dt", scene, "--integrator", "verlet", "--time",
                   repr(duration), "--set", f'model.discretisation="{disc}"', "--threads", "1",
                   "--csv", str(path), "-q"]
        done = subprocess.run(command, env=self.env, capture_output=True, text=True)
        row = {}
        if path.exists():
            with open(path) as f:
                found = list(csv.DictReader(f))
            row = found[0] if found else {}
            path.unlink()
        if done.returncode != 0 or not row.get("stable_dt"):
            raise SystemExit(f"stable-dt failed (exit {done.returncode}): {done.stderr[-500:]}")
        return row

    def run(self, scene, disc, frames=True):
        """One `cosserat run`: (summary, times, steps, positions [frames, m, n, 3] or the last
        frame only)."""
        stem = self.work / f"run-{self.count}"
        command = [self.exe, "run", scene, "--set", f'model.discretisation="{disc}"',
                   "--threads", "1", "-o", f"{stem}.h5", "--summary", f"{stem}.json", "-q",
                   "--overwrite"]
        done = subprocess.run(command, env=self.env, capture_output=True, text=True)
        summary = json.loads(Path(f"{stem}.json").read_text()) \
            if Path(f"{stem}.json").exists() else {"status": "no summary"}
        summary["exit_status"] = done.returncode
        times = steps = positions = None
        if done.returncode == 0:
            with h5py.File(f"{stem}.h5", "r") as f:
                times, steps = f["time"][:], f["step"][:]
                positions = np.array(f["positions"][:] if frames else f["positions"][-1])
        else:
            summary["status"] = f"exit {done.returncode}: {done.stderr.strip()[-300:]}"
        for suffix in (".h5", ".xmf", ".json"):
            Path(f"{stem}{suffix}").unlink(missing_ok=True)
        return summary, times, steps, positions

    def step_for(self, family, disc, nk, nl, duration, measured, make, term, cap):
        """0.9 x the largest stable step: stable-dt when a trial costs at most `cap`
        node-steps, else the ratio stable/term of the finest grid measured in `family` for this
        discretisation times `term` of this grid. Returns (dt, stable, source)."""
        estimate = term(nk, nl)
        trial = nk * nl * duration / (SAFETY * estimate)
        if trial <= cap:
            start = time.time()
            row = self.stable_dt(make(SAFETY * estimate), disc, duration)
            stable = float(row["stable_dt"])
            measured.setdefault((family, disc), []).append((nk * nl, stable / estimate))
            source = f"stable-dt over {duration:g} s ({stable / estimate:.3f} of the term)"
            self.say(f"stable-dt {family} {nk}x{nl} {disc}: {stable:.5g} s "
                     f"({row.get('trials')} trials, {time.time() - start:.1f} s wall)")
        else:
            known = measured.get((family, disc))
            if not known:
                raise SystemExit(f"no measured stable step to scale for {family} {disc}")
            ratio = max(known)[1]
            stable = ratio * estimate
            source = f"scaled: {ratio:.3f} x the term (finest measured grid)"
            self.say(f"stable dt {family} {nk}x{nl} {disc}: {stable:.5g} s, {source}")
        return SAFETY * stable, stable, source

    # ------------------------------------------------------------------------------------------
    # The hung sheet
    def hung_scene(self, n, across, dt, steps, every):
        """k runs up the sheet (grid.u = +y; node [k, l] starts at y = k h), l across it
        (grid.v = +x, 10 m wide): the top row k = n - 1 is held. The long index along k runs
        twice as fast on a strip 3 nodes wide as along l; on the square both orientations give
        the same positions to 1e-13 m for both quadratures (checked 2026-12-02)."""
        return self.scene(f"""title = "edge-hung sheet {n} x {across}"
[grid]
nodes = [{n}, {across}]
size = [{L}, {L}]
origin = [0.0, 0.0, 0.0]
u = [0.0, 1.0, 0.0]
v = [1.0, 0.0, 0.0]
[material]
preset = "cotton-10m"
phi = 0.0
[environment]
gravity = [0.0, {-G}, 0.0]
damping = {HUNG_DAMPING!r}
[time]
integrator = "verlet"
dt = {dt!r}
steps = {steps}
output_every = {every}
[output]
fields = []
[[fix]]
region = {{ column = {n - 1} }}
""")

    @staticmethod
    def hung_errors(positions, n, across):
        """Per frame: (|bottom-centre - exact|, max over the centre line of |r - exact|), the
        centre line l = (across - 1)/2 at x = 5 m."""
        c = (across - 1) // 2
        y0 = np.arange(n) * (L / (n - 1))
        exact = np.zeros((n, 3))
        exact[:, 0] = c * L / (across - 1)
        exact[:, 1] = L - exact_hung(L - y0)
        line = positions[..., :, c, :] if positions.ndim == 4 else positions[:, c, :]
        d = np.linalg.norm(line - exact, axis=-1)
        return d[..., 0], d.max(axis=-1)

    def hung(self, args):
        duration = args.hung_time
        squares = [int(x) for x in args.hung_squares.split(",")]
        strips = {disc: [int(x) for x in getattr(args, f"hung_strips_{disc.replace('-', '_')}")
                         .split(",")] for disc in DISCS}
        membrane = lambda nk, nl: cfl(L, L, nk, nl, ZETA, XI, MU0)[0]
        measured, rows, lines = {}, [], {}
        jobs = [(disc, "square", n, n) for disc in DISCS for n in squares]
        jobs += [(disc, "strip", n, 3) for disc in DISCS for n in strips[disc]]
        for disc, shape, n, across in jobs:
            dt, stable, source = self.step_for(
                f"hung-{shape}", disc, n, across, duration, measured,
                lambda d: self.hung_scene(n, across, d, 1, 1), membrane, args.hung_trial_cap)
            row, line = self.hung_sweep(disc, shape, n, across, dt, duration)
            row.update(stable_dt=stable, dt_source=source)
            rows.append(row)
            lines[(disc, shape, n)] = (row["dt"], line)
        # The strips' check: the strip at the square's step, the centre lines compared frame by
        # frame.
        for n in [int(x) for x in args.hung_check.split(",") if x]:
            for disc in DISCS:
                if (disc, "square", n) not in lines:
                    continue
                dt, square = lines[(disc, "square", n)]
                row, strip = self.hung_sweep(disc, "strip-check", n, 3, dt, duration)
                k = min(len(square), len(strip))
                diff = float(np.abs(strip[:k] - square[:k]).max())
                sq = next(r for r in rows if r["disc"] == disc and r["shape"] == "square"
                          and r["nodes"] == n)
                row.update(check_max_difference=diff,
                           check_bottom_relative=abs(row["error_bottom"] - sq["error_bottom"])
                           / sq["error_bottom"],
                           check_line_relative=abs(row["error_line"] - sq["error_line"])
                           / sq["error_line"], dt_source="the square's step")
                self.say(f"  strip check {n} {disc}: centre lines differ by at most {diff:.2e} m; "
                         f"final errors relative {row['check_bottom_relative']:.1e} (bottom), "
                         f"{row['check_line_relative']:.1e} (line)")
                rows.append(row)
        # The cheapest runs to each target, timed again stopped at their settle frame.
        for disc in DISCS:
            for metric in ("bottom", "line"):
                for target in TARGETS:
                    key = f"wall_estimate_{metric}_{target:g}"
                    cands = sorted((r for r in rows if r["disc"] == disc and r.get(key)
                                    and r["shape"] in ("square", "strip")),
                                   key=lambda r: r[key])[:args.candidates]
                    for r in cands:
                        rows.append(self.hung_confirm(r, metric, target, args.repetitions))
        return rows

    def hung_sweep(self, disc, shape, n, across, dt, duration):
        for attempt in range(3):  # a run the monitor stops is repeated at dt/2, twice at most
            steps = math.ceil(duration / dt - 1e-9)
            every = max(1, round(FRAME / dt))
            summary, times, step_index, positions = self.run(
                self.hung_scene(n, across, dt, steps, every), disc)
            if summary["exit_status"] != 3 or shape == "strip-check":
                break
            self.say(f"hung {shape} {n}x{across} {disc} dt {dt:.4g}: unstable, again at dt/2")
            dt /= 2
        row = {"problem": "hung", "kind": "sweep" if shape != "strip-check" else "check",
               "shape": shape, "disc": disc, "nodes": n, "across": across, "dt": dt,
               "halved": attempt, "steps": steps, "sim_time": summary.get("sim_time"),
               "wall_seconds": summary.get("wall_seconds"),
               "node_steps_per_second": summary.get("node_steps_per_second"),
               "status": summary.get("status")}
        if positions is None:
            self.say(f"hung {shape} {n}x{across} {disc} dt {dt:.4g}: {row['status']}")
            return row, None
        bottom, line = self.hung_errors(positions, n, across)
        row.update(error_bottom=float(bottom[-1]), error_line=float(line[-1]))
        for metric, e in (("bottom", bottom), ("line", line)):
            for target in PLOT_TARGETS:
                bad = np.nonzero(e > target)[0]
                if len(bad) == len(e) or (len(bad) and bad[-1] == len(e) - 1):
                    continue  # not within the target at T
                i = bad[-1] + 1 if len(bad) else 0
                row[f"settle_step_{metric}_{target:g}"] = int(step_index[i])
                row[f"settle_time_{metric}_{target:g}"] = float(times[i])
                row[f"wall_estimate_{metric}_{target:g}"] = \
                    row["wall_seconds"] * step_index[i] / step_index[-1]
        c = (across - 1) // 2
        self.say(f"hung {shape} {n}x{across} {disc} dt {dt:.4g}: bottom {bottom[-1]:.4e} "
                 f"line {line[-1]:.4e} m, wall {row['wall_seconds']:.3f} s "
                 f"({row['node_steps_per_second']:.3g} node-steps/s)")
        return row, positions[:, :, c, :]

    def hung_confirm(self, sweep, metric, target, repetitions):
        steps = sweep[f"settle_step_{metric}_{target:g}"]
        walls, errors = [], None
        for _ in range(repetitions):
            summary, _, _, positions = self.run(
                self.hung_scene(sweep["nodes"], sweep["across"], sweep["dt"], max(steps, 1),
                                max(steps, 1)), sweep["disc"], frames=False)
            walls.append(summary.get("wall_seconds"))
            errors = self.hung_errors(positions, sweep["nodes"], sweep["across"])
        row = {k: sweep[k] for k in ("problem", "shape", "disc", "nodes", "across", "dt",
                                     "stable_dt", "dt_source")}
        row.update(kind="confirm", metric=metric, target=target, steps=steps,
                   sim_time=steps * sweep["dt"], wall_seconds=statistics.median(walls),
                   walls=" ".join(f"{w:.4g}" for w in walls),
                   error_bottom=float(errors[0]), error_line=float(errors[1]), status="ok")
        self.say(f"  confirm {metric} {target:g} {sweep['disc']} {sweep['shape']} "
                 f"{sweep['nodes']}: {steps} steps, wall {row['walls']} s, error bottom "
                 f"{row['error_bottom']:.3e} line {row['error_line']:.3e}")
        return row

    # ------------------------------------------------------------------------------------------
    # S1-like sheet
    def s1_scene(self, n, dt, steps):
        """tools/parity_study.py's S1-like sheet on its segment supports, the last frame only,
        no fields."""
        return self.scene(s1_like_scene(n, dt, steps, steps, "segments")
                          + "[output]\nfields = []\n")

    def s1(self, args):
        duration = args.s1_time
        grids = [9 * 2 ** j + 1 for j in range(args.s1_levels)]
        reference_n = 9 * 2 ** args.s1_levels + 1
        term = lambda nk, nl: min(cfl(10.0, 10.0, nk, nl, S1_ZETA, S1_XI, S1_MU0))
        measured, runs = {}, []
        for disc in DISCS:
            for n in grids:
                dt0, stable, source = self.step_for(
                    "s1", disc, n, n, duration, measured, lambda d: self.s1_scene(n, d, 1),
                    term, args.s1_trial_cap)
                for j in range(args.s1_halvings + 1):
                    dt = dt0 / 2 ** j
                    steps = math.ceil(duration / dt - 1e-9)
                    if j and steps * n * n > args.s1_run_cap:
                        break
                    runs.append(self.s1_run(disc, n, duration / steps, steps, stable, source))
        # The reference: the next grid, trapezoidal, at 0.9 x its step scaled from the finest
        # measured grid (bending sets the step there and on the finest measured grid alike).
        dt0, stable, source = self.step_for("s1", "energy", reference_n, reference_n, duration,
                                            measured, None, term, 0)
        steps = math.ceil(duration / dt0 - 1e-9)
        reference = self.s1_run("energy", reference_n, duration / steps, steps, stable, source,
                                kind="reference")
        ref = reference.pop("positions")
        if ref is None:
            raise SystemExit(f"the reference run failed: {reference['status']}")
        if self.keep:
            np.savez_compressed(self.keep, reference=ref, **{
                f"{d}-{n}-{dt!r}": p for (d, n, dt), p in self.kept.items()})
        rows = [reference]
        for r in runs:
            p = r.pop("positions")
            if p is None:
                rows.append(r)
                continue
            n = r["nodes"]
            stride = (reference_n - 1) // (n - 1)
            d = np.linalg.norm(p - ref[::stride, ::stride], axis=-1)
            r.update(error_max=float(d.max()), error_rms=float(np.sqrt(np.mean(d ** 2))))
            rows.append(r)
            self.say(f"  s1 {n} {r['disc']} dt {r['dt']:.4g}: error max {r['error_max']:.3e} "
                     f"rms {r['error_rms']:.3e} m, wall {r['wall_seconds']:.3f} s")
        # Each grid's own differences (for the reference's Richardson estimate and the time
        # errors): kept as rows of kind "difference".
        finest = {}
        for r in runs:
            key = (r["disc"], r["nodes"])
            finest.setdefault(key, []).append(r)
        positions = dict(self.kept)
        positions[("energy", reference_n, reference["dt"])] = ref
        for disc in DISCS:
            chain = [n for n in grids if (disc, n) in finest]
            if disc == "energy":
                chain.append(reference_n)
            for a, b in zip(chain, chain[1:]):
                pa = positions[self.smallest(disc, a, reference, runs)]
                pb = positions[self.smallest(disc, b, reference, runs)]
                stride = (b - 1) // (a - 1)
                d = np.linalg.norm(pa - pb[::stride, ::stride], axis=-1)
                rows.append({"problem": "s1", "kind": "difference", "disc": disc, "nodes": b,
                             "coarser": a, "error_max": float(d.max()),
                             "error_rms": float(np.sqrt(np.mean(d ** 2)))})
            for n in chain[:-1] if disc == "energy" else chain:
                dts = sorted(r["dt"] for r in finest.get((disc, n), []))
                if len(dts) >= 2:
                    d = np.linalg.norm(positions[(disc, n, dts[0])]
                                       - positions[(disc, n, dts[1])], axis=-1)
                    rows.append({"problem": "s1", "kind": "dt-difference", "disc": disc,
                                 "nodes": n, "dt": dts[0], "dt_coarser": dts[1],
                                 "error_max": float(d.max()),
                                 "error_rms": float(np.sqrt(np.mean(d ** 2)))})
        # The cheapest runs, timed twice more.
        for disc in DISCS:
            for target in TARGETS:
                cands = sorted((r for r in rows if r.get("kind") == "sweep"
                                and r["disc"] == disc and r.get("error_max") is not None
                                and r["error_max"] <= target), key=lambda r: r["wall_seconds"])
                for r in cands[:args.candidates]:
                    if r.get("walls"):
                        continue
                    walls = [r["wall_seconds"]]
                    for _ in range(args.repetitions - 1):
                        summary, _, _, _ = self.run(self.s1_scene(r["nodes"], r["dt"],
                                                                  r["steps"]), disc,
                                                    frames=False)
                        walls.append(summary.get("wall_seconds"))
                    r["walls"] = " ".join(f"{w:.4g}" for w in walls)
                    r["wall_seconds"] = statistics.median(walls)
                    self.say(f"  retimed s1 {r['nodes']} {disc} dt {r['dt']:.4g}: {r['walls']}")
        return rows

    def smallest(self, disc, n, reference, runs):
        if disc == "energy" and n == reference["nodes"]:
            return ("energy", n, reference["dt"])
        return (disc, n, min(r["dt"] for r in runs if r["disc"] == disc and r["nodes"] == n))

    def s1_run(self, disc, n, dt, steps, stable, source, kind="sweep"):
        """One run to T; one stopped by the stability monitor (exit 3) is repeated at half the
        step, twice at most (the row says so)."""
        for attempt in range(3):
            summary, _, _, positions = self.run(self.s1_scene(n, dt, steps), disc, frames=False)
            if summary["exit_status"] != 3:
                break
            self.say(f"s1 {kind} {n}x{n} {disc} dt {dt:.5g}: unstable, again at dt/2")
            dt, steps, source = dt / 2, steps * 2, source + "; halved after an unstable run"
        row = {"problem": "s1", "kind": kind, "shape": "square", "disc": disc, "nodes": n,
               "across": n, "dt": dt, "halved": attempt, "steps": steps, "stable_dt": stable, "dt_source": source,
               "sim_time": summary.get("sim_time"), "wall_seconds": summary.get("wall_seconds"),
               "node_steps_per_second": summary.get("node_steps_per_second"),
               "status": summary.get("status"), "positions": positions}
        if positions is not None:
            self.kept[(disc, n, dt)] = positions
        self.say(f"s1 {kind} {n}x{n} {disc} dt {dt:.5g} ({steps} steps): {row['status']}, "
                 f"wall {row['wall_seconds']} s ({row['node_steps_per_second']} node-steps/s)")
        return row


# ----------------------------------------------------------------------------------------------
def read_csv(path):
    if not Path(path).exists():
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def num(text):
    try:
        v = float(text)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def order(a, b):
    return math.log2(a / b) if a and b and a > 0 and b > 0 else float("nan")


def fmt_wall(w):
    return f"{w * 1e3:.3g} ms" if w < 1 else f"{w:.3g} s"


def report(stem, context, notes):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = read_csv(stem + ".csv")
    hung = [r for r in rows if r["problem"] == "hung"]
    s1 = [r for r in rows if r["problem"] == "s1"]
    lines = [f"# Total error, space and time: the two energy quadratures, {context.get('date', '')}",
             "",
             f"Machine: {context.get('machine', '')}. Build: {context.get('build', '')}. "
             f"Ranks × threads: 1 × 1 (`--threads 1`, OMP_NUM_THREADS=1), one process at a time. "
             f"Binary: {context.get('binary', '')}.",
             f"Regenerate with `benchmarks/run_total_error.sh`; the log of every run: "
             f"`{Path(stem).name}.log`. Wall time of the study: "
             + "; ".join(f"{w} ({p})" for p, w in notes.get("walls", {}).items()) + ".", "",
             "Wall time = the run summary's `wall_seconds` (the step loop and its frames; not "
             "the process start or the scene's set-up). Every run is Verlet.", ""]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    colours = {"energy": "tab:blue", "energy-nodal": "tab:red"}

    if hung:
        sweep = [r for r in hung if r["kind"] == "sweep"]
        T = max(num(r["sim_time"]) or 0 for r in sweep)
        lines += ["## (a) Edge-hung sheet: settled state against the exact 1-D rest state", "",
                  "A 10 m × 10 m sheet of `cotton-10m` with φ = 0 (ζ = 100 N/m, ξ = 0.02 N·m, "
                  "μ₀ = 0.88 kg/m²), in the xy plane, held by its whole top row, gravity 9.8 "
                  f"m/s², damping ϱ_D = {HUNG_DAMPING} kg/(m²·s) (rate {HUNG_DAMPING / MU0:.1f}/s, "
                  "near the critical damping of the slowest mode: the fastest settling of a "
                  "21 × 21 scan of 3–16). It starts flat and unstretched and falls into its rest "
                  "state, which is 1-D: 3ζλ(λ² − 1) = μ₀g(L − X), λ the stretch, X the rest "
                  "distance from the top, L = 10 m (its exact positions by Gauss–Legendre "
                  "quadrature of λ; 12 % stretch at the top, the bottom 0.637 m below its rest "
                  "height). Two total errors: |bottom-centre node − exact| (as "
                  "`Quadrature.HungSheetConvergesAtSecondOrderInSpace`) and the largest "
                  "|r − exact| over the centre line's nodes.", "",
                  f"Grids: squares n × n, and strips n × 3 (3 nodes across the same 10 m); k runs "
                  f"up the sheet. Step: {SAFETY} × `cosserat stable-dt --time {T:g}` (Verlet, "
                  "to 2 %), or, where one trial would cost more than the cap, the finest "
                  "measured grid's ratio to the membrane CFL term times this grid's term (the "
                  "sheet stays exactly plane, so bending never limits it). Each grid runs to "
                  f"T = {T:g} s with a frame every {FRAME} s; its **settle time** for a target "
                  "is the first frame from which the error stays within it up to T (so chosen "
                  "knowing the answer: a lower bound on what a user who stops at a fixed T "
                  "pays). The cheapest runs by that estimate (wall × settle step / steps) are "
                  "run again stopped at that frame, three times, and the median wall time is "
                  "the one reported.", ""]
        checks = [r for r in hung if r["kind"] == "check"]
        if checks:
            lines += ["**Strips.** Each check runs a strip n × 3 at the square's step and "
                      "compares its centre line with the square's, frame by frame:", "",
                      "| n | quadrature | largest difference of the centre lines, all frames (m) "
                      "| final bottom error, relative difference | final line error, relative "
                      "difference |", "|---|---|---|---|---|"]
            for r in checks:
                lines.append(f"| {r['nodes']} | {r['disc']} | {float(r['check_max_difference']):.2e} "
                             f"| {float(r['check_bottom_relative']):.1e} "
                             f"| {float(r['check_line_relative']):.1e} |")
            lines.append("")
        lines += ["**Settled error** at T (the spatial error: a damped Verlet run comes to rest "
                  "at the discrete equilibrium whatever its step), the step, and the order "
                  "against the next coarser grid of the same shape:", "",
                  "| shape | n | quadrature | Δt (s) | Δt from | bottom error (m) | order "
                  "| line error (m) | order | wall to T (s) | node-steps/s |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for shape in ("square", "strip"):
            for disc in DISCS:
                prev = None
                for r in sorted((r for r in sweep if r["shape"] == shape and r["disc"] == disc),
                                key=lambda r: int(r["nodes"])):
                    eb, el = num(r.get("error_bottom")), num(r.get("error_line"))
                    ob = ol = ""
                    if prev and eb is not None:
                        ratio = math.log2((int(r["nodes"]) - 1) / (int(prev["nodes"]) - 1))
                        ob = f"{order(num(prev['error_bottom']), eb) / ratio:.2f}"
                        ol = f"{order(num(prev['error_line']), el) / ratio:.2f}"
                    src = "stable-dt" if r["dt_source"].startswith("stable-dt") else "scaled"
                    if int(r.get("halved") or 0):
                        src += f", halved {r['halved']}× (unstable)"
                    lines.append(f"| {shape} | {r['nodes']} | {disc} | {float(r['dt']):.4g} | {src} "
                                 f"| {eb:.3e} | {ob} | {el:.3e} | {ol} "
                                 f"| {float(r['wall_seconds']):.3g} "
                                 f"| {float(r['node_steps_per_second']):.3g} |"
                                 if eb is not None else
                                 f"| {shape} | {r['nodes']} | {disc} | {float(r['dt']):.4g} | {src} "
                                 f"| {r['status']} | | | | | |")
                    prev = r
        lines.append("")
        confirms = [r for r in hung if r["kind"] == "confirm"]
        for metric, title in (("line", "largest error over the centre line"),
                              ("bottom", "bottom-centre node's error")):
            lines += [f"**Cheapest run to each target, {title}** (grid, Δt, stopped at t, "
                      "median wall time of 3; its error):", "",
                      "| target (m) | " + " | ".join(LABEL[d] for d in DISCS) + " | nodal / "
                      "trapezoidal |", "|---|---|---|---|"]
            for target in TARGETS:
                cells, walls = [], []
                for disc in DISCS:
                    c = [r for r in confirms if r["disc"] == disc and r["metric"] == metric
                         and float(r["target"]) == target
                         and float(r[f"error_{metric}"]) <= target]
                    if c:
                        b = min(c, key=lambda r: float(r["wall_seconds"]))
                        walls.append(float(b["wall_seconds"]))
                        cells.append(f"{b['shape']} {b['nodes']} × {b['across']}, Δt "
                                     f"{float(b['dt']):.3g} s, t = {float(b['sim_time']):.2f} s: "
                                     f"**{fmt_wall(float(b['wall_seconds']))}** "
                                     f"(error {float(b[f'error_{metric}']):.2e})")
                    else:
                        fin = [r for r in sweep if r["disc"] == disc and r.get(f"error_{metric}")]
                        big = max(fin, key=lambda r: int(r["nodes"]))
                        walls.append(None)
                        cells.append(f"not reached up to {big['shape']} n = {big['nodes']} "
                                     f"(error {float(big[f'error_{metric}']):.2e})")
                ratio = f"{walls[1] / walls[0]:.3g}×" if None not in walls else "–"
                lines.append(f"| {target:g} | " + " | ".join(cells) + f" | {ratio} |")
            lines.append("")
        # Work-precision: for each target, the cheapest estimated wall over the sweeps.
        ax = axes[0]
        for disc in DISCS:
            for metric, style in (("line", "o-"), ("bottom", "x:")):
                xs, ys = [], []
                for tau in PLOT_TARGETS:
                    w = [num(r.get(f"wall_estimate_{metric}_{tau:g}")) for r in sweep
                         if r["disc"] == disc]
                    w = [x for x in w if x is not None]
                    if w:
                        xs.append(tau)
                        ys.append(min(w))
                ax.loglog(xs, ys, style, color=colours[disc], ms=4,
                          label=f"{disc}: {'centre-line max' if metric == 'line' else 'bottom-centre'}")
            c = [r for r in confirms if r["disc"] == disc and r["metric"] == "line"]
            ax.loglog([float(r["target"]) for r in c], [float(r["wall_seconds"]) for r in c],
                      "s", color=colours[disc], mfc="none", ms=9)
        ax.set_xlabel("total error target (m)")
        ax.set_ylabel("wall time to settle within it (s)")
        ax.set_title("(a) edge-hung sheet: cheapest settle (estimated from the sweeps; "
                     "squares: runs re-timed, line max)", fontsize=9)
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)

    if s1:
        sweep = [r for r in s1 if r["kind"] == "sweep"]
        ref = next(r for r in s1 if r["kind"] == "reference")
        diffs = [r for r in s1 if r["kind"] == "difference"]
        tdiffs = [r for r in s1 if r["kind"] == "dt-difference"]
        T = float(ref["sim_time"])
        grids = sorted({int(r["nodes"]) for r in sweep})
        lines += ["## (b) S1-like sheet at T = 2 s against a grid-converged reference", "",
                  "S1's sheet, material, gravity and damping (scenes/s1_clothesline.toml) on "
                  f"n × n nodes, n = {', '.join(map(str, grids))} (9·2^j + 1: nested), held "
                  "throughout by the x1 = 0 edge segments of 10/9 m at each end (nodes [0, 0…"
                  "(n−1)/9] and [0, n−1−(n−1)/9…n−1]: the \"segments\" support of "
                  "tools/parity_study.py and docs/model.md \"Parity with the flux form\"; S1's "
                  "own two corner nodes are point supports, whose continuum solution is "
                  "singular). Each grid at Δt₀ = "
                  f"{SAFETY} × `cosserat stable-dt --time {T:g}` and halvings of it (fewer on "
                  "the finest grids). Reference: the trapezoidal form on "
                  f"{ref['nodes']} × {ref['nodes']} nodes at Δt = {float(ref['dt']):.4g} s "
                  f"({ref['dt_source']}), wall {float(ref['wall_seconds']):.1f} s. Total error "
                  "= |r − r_ref| at T over the run's own nodes (every node of a coarse grid is a "
                  "node of the reference), the largest (max) and the RMS, in metres.", ""]
        lines += ["**Grid differences** (each grid at its smallest step against the next finer "
                  "one, at the coarser grid's nodes):", "",
                  "| quadrature | grids | max (m) | order | RMS (m) | order |",
                  "|---|---|---|---|---|---|"]
        est = None
        for disc in DISCS:
            prev = None
            for r in sorted((r for r in diffs if r["disc"] == disc), key=lambda r: int(r["nodes"])):
                om = orr = ""
                if prev:
                    om = f"{order(float(prev['error_max']), float(r['error_max'])):.2f}"
                    orr = f"{order(float(prev['error_rms']), float(r['error_rms'])):.2f}"
                lines.append(f"| {disc} | {r['coarser']} → {r['nodes']} | {float(r['error_max']):.3e} "
                             f"| {om} | {float(r['error_rms']):.3e} | {orr} |")
                if disc == "energy" and int(r["nodes"]) == int(ref["nodes"]) and prev:
                    p = order(float(prev["error_max"]), float(r["error_max"]))
                    pr = order(float(prev["error_rms"]), float(r["error_rms"]))
                    est = (float(r["error_max"]) / (2 ** p - 1) if p > 0 else float("nan"),
                           p, float(r["error_rms"]) / (2 ** pr - 1) if pr > 0 else float("nan"))
                prev = r
        lines.append("")
        if est:
            lines += [f"The reference's own spatial error, by Richardson from the last two "
                      f"differences (observed order {est[1]:.2f}, max): about {est[0]:.1e} m "
                      f"(max), {est[2]:.1e} m (RMS) — so errors below about that are not "
                      "resolved by this reference.", ""]
        if tdiffs:
            lines += ["**Time differences** (each grid at its two smallest steps; Verlet is "
                      "second order, so the smaller step's time error is about a third of "
                      "this):", "", "| quadrature | n | Δt and 2Δt (s) | max (m) | RMS (m) |",
                      "|---|---|---|---|---|"]
            for r in tdiffs:
                lines.append(f"| {r['disc']} | {r['nodes']} | {float(r['dt']):.4g}, "
                             f"{float(r['dt_coarser']):.4g} | {float(r['error_max']):.2e} "
                             f"| {float(r['error_rms']):.2e} |")
            lines.append("")
        lines += ["**Every run** (wall: one run, or the median of three for the cheapest ones):",
                  "", "| quadrature | n | Δt (s) | steps | total error max (m) | RMS (m) "
                  "| wall (s) | node-steps/s |", "|---|---|---|---|---|---|---|---|"]
        for disc in DISCS:
            for r in sorted((r for r in sweep if r["disc"] == disc),
                            key=lambda r: (int(r["nodes"]), -float(r["dt"]))):
                if num(r.get("error_max")) is None:
                    lines.append(f"| {disc} | {r['nodes']} | {float(r['dt']):.4g} | {r['steps']} "
                                 f"| {r['status']} | | | |")
                    continue
                lines.append(f"| {disc} | {r['nodes']} | {float(r['dt']):.4g} | {r['steps']} "
                             f"| {float(r['error_max']):.3e} | {float(r['error_rms']):.3e} "
                             f"| {float(r['wall_seconds']):.4g} "
                             f"| {float(r['node_steps_per_second']):.3g} |")
        lines.append("")
        for metric in ("max", "rms"):
            lines += [f"**Cheapest run to each target, total error {metric.upper() if metric == 'rms' else 'max'}:**", "",
                      "| target (m) | " + " | ".join(LABEL[d] for d in DISCS) + " | nodal / "
                      "trapezoidal |", "|---|---|---|---|"]
            for target in TARGETS:
                cells, walls = [], []
                for disc in DISCS:
                    c = [r for r in sweep if r["disc"] == disc and num(r.get(f"error_{metric}"))
                         is not None and float(r[f"error_{metric}"]) <= target]
                    if c:
                        b = min(c, key=lambda r: float(r["wall_seconds"]))
                        walls.append(float(b["wall_seconds"]))
                        cells.append(f"{b['nodes']} × {b['nodes']}, Δt {float(b['dt']):.3g} s: "
                                     f"**{fmt_wall(float(b['wall_seconds']))}** (error "
                                     f"{float(b[f'error_{metric}']):.2e})")
                    else:
                        fin = [r for r in sweep if r["disc"] == disc
                               and num(r.get(f"error_{metric}")) is not None]
                        best = min(fin, key=lambda r: float(r[f"error_{metric}"]))
                        walls.append(None)
                        cells.append(f"not reached up to n = {max(int(r['nodes']) for r in fin)} "
                                     f"(smallest error {float(best[f'error_{metric}']):.2e}, "
                                     f"{best['nodes']} × {best['nodes']}, Δt "
                                     f"{float(best['dt']):.3g} s)")
                ratio = f"{walls[1] / walls[0]:.3g}×" if None not in walls else "–"
                lines.append(f"| {target:g} | " + " | ".join(cells) + f" | {ratio} |")
            lines.append("")
        ax = axes[1]
        markers = ["o", "s", "^", "D", "v", "P", "X"]
        for disc in DISCS:
            pts = sorted(((float(r["error_max"]), float(r["wall_seconds"]), int(r["nodes"]))
                          for r in sweep if r["disc"] == disc and num(r.get("error_max"))),
                         key=lambda p: -p[0])
            for i, n in enumerate(grids):
                sel = [p for p in pts if p[2] == n]
                ax.loglog([p[0] for p in sel], [p[1] for p in sel], markers[i % len(markers)],
                          color=colours[disc], alpha=0.45, mfc="none",
                          label=f"{disc} {n}²" if disc == "energy" else None)
            # the cheapest wall reaching each error: staircase of the minimum over runs with
            # error at most that
            taus = np.logspace(math.log10(min(p[0] for p in pts)), -0.5, 60)
            ys = [min((p[1] for p in pts if p[0] <= t), default=None) for t in taus]
            ax.loglog([t for t, y in zip(taus, ys) if y], [y for y in ys if y], "-",
                      color=colours[disc], drawstyle="steps-post", label=f"{disc}: cheapest")
        if est:
            ax.axvline(est[0], color="gray", ls=":", label="reference's own error (est.)")
        ax.set_xlabel("total error at T, max over the nodes (m)")
        ax.set_ylabel("wall time (s)")
        ax.set_title(f"(b) S1-like sheet, segment supports, T = {T:g} s", fontsize=9)
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(stem + "-work-precision.png", dpi=100)
    lines += [f"![work-precision]({Path(stem).name}-work-precision.png)", ""]
    if notes.get("load"):
        lines += [f"Load (1-min average): {notes['load']}.", ""]
    Path(stem + ".md").write_text("\n".join(lines))
    print("\n".join(lines))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--exe", required=True)
    parser.add_argument("--out", required=True, help="stem of the result files")
    parser.add_argument("--parts", default="hung,s1")
    parser.add_argument("--quick", action="store_true", help="small grids: checks the pipeline")
    parser.add_argument("--hung-time", type=float, default=6.0)
    parser.add_argument("--hung-squares", default="3,5,7,9,11,21,41,81,161")
    parser.add_argument("--hung-strips-energy", default="5,7,9,11,21,41,81,161,321,641")
    parser.add_argument("--hung-strips-energy-nodal",
                        default="5,7,9,11,21,41,81,161,321,641,1281,2561")
    parser.add_argument("--hung-check", default="41,81", help="grids whose strip is checked")
    parser.add_argument("--hung-trial-cap", type=float, default=3e7,
                        help="largest stable-dt trial (node-steps); above it the step is scaled")
    parser.add_argument("--s1-time", type=float, default=2.0)
    parser.add_argument("--s1-levels", type=int, default=5, help="grids 9*2^j+1, j < LEVELS; "
                        "the reference is j = LEVELS")
    parser.add_argument("--s1-halvings", type=int, default=4)
    parser.add_argument("--s1-run-cap", type=float, default=6e8,
                        help="largest halved run (node-steps)")
    parser.add_argument("--s1-trial-cap", type=float, default=1.5e8)
    parser.add_argument("--candidates", type=int, default=2)
    parser.add_argument("--repetitions", type=int, default=3)
    parser.add_argument("--keep", help="also save the S1 runs' final positions to this .npz")
    parser.add_argument("--context", default="{}")
    parser.add_argument("--report-only", action="store_true")
    args = parser.parse_args()
    if args.quick:
        args.hung_time, args.hung_squares, args.hung_check = 3.0, "3,5,11,21", "21"
        args.hung_strips_energy = args.hung_strips_energy_nodal = "5,11,21,41"
        args.s1_levels, args.s1_halvings, args.s1_time = 3, 2, 0.5
    context = json.loads(args.context)
    stem = args.out
    notes_path = Path(stem + "-notes.json")
    notes = json.loads(notes_path.read_text()) if notes_path.exists() else {}
    if not args.report_only:
        study = Study(args)
        started = time.time()
        before = Path("/proc/loadavg").read_text().split()[:3]
        parts = args.parts.split(",")
        old = [r for r in read_csv(stem + ".csv") if r["problem"] not in parts]
        rows = []
        try:
            if "hung" in parts:
                rows += study.hung(args)
                write_csv(stem + ".csv", old + rows)
            if "s1" in parts:
                rows += study.s1(args)
                write_csv(stem + ".csv", old + rows)
        finally:
            shutil.rmtree(study.work, ignore_errors=True)
        after = Path("/proc/loadavg").read_text().split()[:3]
        notes.setdefault("walls", {})[args.parts] = f"{(time.time() - started) / 60:.1f} min"
        notes["load"] = (f"{' / '.join(before)} (1/5/15 min) before, {' / '.join(after)} after; "
                         f"{os.cpu_count()} cores, another job on the machine")
        notes_path.write_text(json.dumps(notes))
    report(stem, context, notes)


if __name__ == "__main__":
    sys.exit(main())
