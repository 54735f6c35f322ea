#!/usr/bin/python3
"""Where the semi-implicit step overtakes Verlet (issue 30, item 5; docs/integrator-study.md,
"Explicit against semi-implicit: the crossover").

The problem: the S1-like 10 m sheet of jobs/make_large_sheet.sh (S1's material, gravity and
damping, held at the two corners of one edge, starting flat) on N x N grids, run to T = 1 s.
On each grid:

  reference  Verlet at --reference-fraction x h^2 (default 0.008 h^2, 1/9 of the largest stable
             step 0.071 h^2 measured on 120^2 and 240^2, docs/integrator-study.md); its own
             error is estimated by Richardson from the run at twice its step (order 2)
  verlet     Verlet at 0.064 h^2 (0.9 of the limit) and halvings of it, down to twice the
             reference's step
  semi       each semi-implicit configuration (--configs: integrator, solver rtol, Jacobian
             kept for k steps; the linear solver is the default one for the grid) at
             dt = T/10, T/20, ... (or --si-steps) until its error is below the smallest
             target, or until the next run would cost more than --cap times the fastest Verlet
             run on this grid (it could then win no target), or would pass --max-steps

Error = RMS over all nodes of the distance to the reference's positions at T, in metres (the
spatial error is the same for every run on a grid: this is the error of the time integration).
For each grid and target (1e-2, 1e-3, 1e-4 m) the table gives the wall time of the fastest
Verlet run and of the fastest semi-implicit run whose error is within the target.

Writes STEM.csv (every run), STEM.md (tables) and STEM.png (wall time against grid for each
target), and STEM.log. Runs --workers single-threaded processes side by side.

  /usr/bin/python3 tools/crossover_study.py --exe COSSERAT --out STEM [--grids 60,120,240]
      [--context JSON] [--report-only]
"""

import argparse
import concurrent.futures
import csv
import json
import math
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from accuracy_study import rms, run_cosserat
from parity_study import LoggedStudy

ROOT = Path(__file__).resolve().parent.parent
TARGETS = [1e-2, 1e-3, 1e-4]
LIMIT = 0.071           # the largest stable Verlet step over h^2 (docs/integrator-study.md)
VERLET_FIRST = 0.064    # 0.9 of it
DEFAULT_CONFIGS = "semi-implicit:1e-6:1,semi-implicit-2:1e-6:1,semi-implicit:1e-6:5," \
                  "semi-implicit-2:1e-6:5"
KEYS = ["grid", "kind", "integrator", "rtol", "jacobian_every", "dt", "steps", "wall_seconds",
        "error", "max_error", "status", "mean_iterations", "jacobians", "jacobian_seconds",
        "solve_seconds", "reference_error"]


class Study(LoggedStudy):
    def __init__(self, args):
        self.exe = args.exe
        self.T = args.time
        self.workers = args.workers
        self.cap = args.cap
        self.max_steps = args.max_steps
        self.si_steps = [int(s) for s in args.si_steps.split(",")] if args.si_steps else None
        self.work = Path(tempfile.mkdtemp(prefix="cosserat-crossover-"))
        super().__init__(args.out)

    def scene(self, n):
        path = self.work / f"hanging-{n}.toml"
        if not path.exists():
            subprocess.run(["bash", str(ROOT / "jobs/make_large_sheet.sh"), str(n), "10",
                            str(path)], check=True)
        return path

    def run(self, n, integrator, dt, steps, rtol=None, every=None):
        """One run to T with frames at 0 and T: (summary, positions at T or None)."""
        overrides = [f'time.integrator="{integrator}"', f"time.dt={dt!r}", f"time.steps={steps}",
                     f"time.output_every={steps}"]
        if rtol is not None:
            overrides += [f"time.solver.rtol={rtol!r}", f"time.solver.jacobian_every={every}"]
        stem = self.work / f"{n}-{integrator}-{steps}-{rtol}-{every}"
        return run_cosserat(self.exe, self.env, stem, self.scene(n), overrides)

    def grid(self, n, reference_fraction, configs):
        h = 10.0 / (n - 1)
        steps_of = lambda fraction: math.ceil(self.T / (fraction * h * h) - 1e-9)
        reference_steps = steps_of(reference_fraction)
        verlet_steps = []
        fraction = VERLET_FIRST
        while fraction >= 2 * reference_fraction - 1e-12:
            verlet_steps.append(steps_of(fraction))
            fraction /= 2
        jobs = [reference_steps] + verlet_steps
        self.say(f"{n}x{n}: reference verlet, {reference_steps} steps; verlet {verlet_steps}")
        with concurrent.futures.ThreadPoolExecutor(self.workers) as pool:
            results = list(pool.map(lambda s: self.run(n, "verlet", self.T / s, s), jobs))
        reference = results[0][1]
        if reference is None:
            raise SystemExit(f"{n}x{n}: the reference run failed: {results[0][0]['status']}")
        rows = []

        def row(kind, integrator, steps, summary, positions, rtol="", every=""):
            distance = (np.linalg.norm(positions - reference, axis=1) if positions is not None
                        else None)
            solves = summary.get("linear_solves") or {}
            r = {"grid": n, "kind": kind, "integrator": integrator, "rtol": rtol,
                 "jacobian_every": every, "dt": self.T / steps, "steps": steps,
                 "wall_seconds": summary.get("wall_seconds"),
                 "error": rms(positions - reference, 1.0) if distance is not None else "",
                 "max_error": float(distance.max()) if distance is not None else "",
                 "status": summary.get("status"),
                 "mean_iterations": solves.get("mean_iterations", ""),
                 "jacobians": solves.get("jacobians", ""),
                 "jacobian_seconds": solves.get("jacobian_seconds", ""),
                 "solve_seconds": solves.get("solve_seconds", "")}
            error = f"{r['error']:.3e}" if r["error"] != "" else "none"
            self.say(f"  {n}x{n} {integrator:16s} rtol {rtol!s:6s} k {every!s:2s} "
                     f"dt {self.T / steps:.4g} error {error} wall {r['wall_seconds']} "
                     f"{r['status']}")
            rows.append(r)
            return r

        for steps, (summary, positions) in zip(jobs, results):
            row("reference" if steps == reference_steps else "verlet", "verlet", steps,
                summary, positions)
        partner = [r for r in rows if r["steps"] == steps_of(2 * reference_fraction)]
        reference_error = partner[0]["error"] / 3.0 if partner and partner[0]["error"] != "" \
            else float("nan")
        self.say(f"{n}x{n}: the reference's own error (Richardson, order 2): "
                 f"{reference_error:.2e} m")
        fastest_verlet = min(r["wall_seconds"] for r in rows
                             if r["kind"] == "verlet" and r["error"] != "")

        def sweep(config):
            integrator, rtol, every = config
            mine, last_wall = [], None
            for steps in self.si_steps or (10 * 2 ** j for j in range(20)):
                if steps > self.max_steps:
                    self.say(f"  {n}x{n} {integrator} k {every}: stop at {steps} steps "
                             f"(--max-steps)")
                    break
                if last_wall is not None and 2 * last_wall > self.cap * fastest_verlet:
                    self.say(f"  {n}x{n} {integrator} k {every}: stop before {steps} steps: "
                             f"about {2 * last_wall:.0f} s, over {self.cap:g} x the fastest "
                             f"Verlet run ({fastest_verlet:.1f} s)")
                    break
                summary, positions = self.run(n, integrator, self.T / steps, steps, rtol, every)
                mine.append((steps, summary, positions))
                last_wall = summary.get("wall_seconds") or last_wall
                if positions is not None and rms(positions - reference, 1.0) < min(TARGETS):
                    break
            return config, mine

        with concurrent.futures.ThreadPoolExecutor(self.workers) as pool:
            for (integrator, rtol, every), mine in pool.map(sweep, configs):
                for steps, summary, positions in mine:
                    row("semi", integrator, steps, summary, positions, rtol, every)
        for r in rows:
            r["reference_error"] = reference_error
        return rows


def read_rows(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        r["grid"] = int(r["grid"])
        for key in ("dt", "wall_seconds", "error", "reference_error"):
            r[key] = float(r[key]) if r[key] not in ("", "None") else None
    return rows


def write_rows(path, rows):
    """Rows of grids not in rows are kept from the file already there: one grid at a time."""
    if Path(path).exists():
        grids = {r["grid"] for r in rows}
        rows = [r for r in read_rows(path) if r["grid"] not in grids] + rows
    rows.sort(key=lambda r: (r["grid"], r["kind"] != "reference", r["kind"], r["integrator"],
                             str(r["jacobian_every"]), r["dt"] * -1))
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=KEYS, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    return rows


def fastest(rows, grid, kind, target):
    good = [r for r in rows if r["grid"] == grid and r["kind"] == kind
            and r["error"] is not None and r["error"] <= target and r["wall_seconds"]]
    return min(good, key=lambda r: r["wall_seconds"]) if good else None


def report(stem, rows, context):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    grids = sorted({r["grid"] for r in rows})
    lines = ["# Explicit against semi-implicit: the crossover", ""]
    if context:
        lines += [f"- {k}: {v}" for k, v in json.loads(context).items()] + [""]
    lines += ["Written by tools/crossover_study.py (docs/integrator-study.md, \"Explicit "
              "against semi-implicit: the crossover\"): the S1-like 10 m sheet held at two "
              "corners, T = 1 s, error = RMS distance to the grid's Verlet reference at T, "
              "in metres.", "",
              "## The fastest run within each target", "",
              "| grid | target (m) | Verlet: wall s (Δt) | semi-implicit: wall s (step, k, Δt) "
              "| semi-implicit / Verlet |", "|---|---|---|---|---|"]
    for g in grids:
        for t in TARGETS:
            v, s = fastest(rows, g, "verlet", t), fastest(rows, g, "semi", t)
            vs = f"{v['wall_seconds']:.3g} ({v['dt']:.3g})" if v else "none ran"
            ss = (f"{s['wall_seconds']:.3g} ({s['integrator']}, {s['jacobian_every']}, "
                  f"{s['dt']:.3g})" if s else "none within the runs' cap")
            ratio = f"{s['wall_seconds'] / v['wall_seconds']:.2f}" if v and s else "—"
            lines.append(f"| {g}² | {t:g} | {vs} | {ss} | {ratio} |")
    lines += ["", "## Every run", "",
              "| grid | kind | integrator | rtol | k | Δt (s) | steps | wall (s) | RMS error (m) "
              "| largest (m) | iterations/step | Jacobians | status |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        err = f"{r['error']:.3g}" if r["error"] is not None else "—"
        mx = f"{float(r['max_error']):.3g}" if r["max_error"] not in ("", None) else "—"
        it = f"{float(r['mean_iterations']):.1f}" if r["mean_iterations"] not in ("", None) \
            else ""
        wall = f"{r['wall_seconds']:.3g}" if r["wall_seconds"] else "—"
        lines.append(f"| {r['grid']}² | {r['kind']} | {r['integrator']} | {r['rtol']} | "
                     f"{r['jacobian_every']} | {r['dt']:.4g} | {r['steps']} | {wall} | {err} | "
                     f"{mx} | {it} | {r['jacobians']} | {r['status']} |")
    lines += ["", "The reference's own error (Richardson against its run at twice the step): "
              + ", ".join(f"{g}²: {next(r['reference_error'] for r in rows if r['grid'] == g):.2g}"
                          f" m" for g in grids)]
    Path(stem + ".md").write_text("\n".join(lines) + "\n")

    fig, axes = plt.subplots(1, len(TARGETS), figsize=(4.2 * len(TARGETS), 3.8), sharey=True)
    for ax, t in zip(axes, TARGETS):
        for kind, label, style in (("verlet", "Verlet", "o-"), ("semi", "semi-implicit", "s--")):
            points = [(g, fastest(rows, g, kind, t)) for g in grids]
            points = [(g * g, r["wall_seconds"]) for g, r in points if r]
            if points:
                ax.loglog(*zip(*points), style, label=label)
        ax.set_title(f"RMS error ≤ {t:g} m at T = 1 s")
        ax.set_xlabel("nodes")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("wall time of the fastest run (s, 1 thread)")
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(stem + ".png", dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--exe", help="the cosserat executable")
    parser.add_argument("--out", required=True, help="stem of the result files")
    parser.add_argument("--grids", default="60,120,240")
    parser.add_argument("--time", type=float, default=1.0, help="T, simulated seconds")
    parser.add_argument("--reference-fraction", default="0.008",
                        help="the reference's step over h^2, one value or GRID:VALUE,...")
    parser.add_argument("--configs", default=DEFAULT_CONFIGS,
                        help="semi-implicit configurations INTEGRATOR:RTOL:JACOBIAN_EVERY,...")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cap", type=float, default=4.0,
                        help="a semi-implicit sweep stops before a run that would cost more "
                        "than this times the grid's fastest Verlet run")
    parser.add_argument("--max-steps", type=int, default=2560)
    parser.add_argument("--si-steps", help="the semi-implicit runs' step counts, STEPS,... "
                        "(default 10, 20, 40, ...; the same stopping rules apply)")
    parser.add_argument("--context", default="", help="JSON of the run's context")
    parser.add_argument("--report-only", action="store_true")
    args = parser.parse_args()
    stem = str(args.out)
    if not args.report_only:
        if not args.exe:
            parser.error("--exe is needed unless --report-only")
        fractions = {}
        for item in args.reference_fraction.split(","):
            grid, _, value = item.rpartition(":")
            fractions[int(grid) if grid else None] = float(value)
        configs = []
        for item in args.configs.split(","):
            integrator, rtol, every = item.split(":")
            configs.append((integrator, float(rtol), int(every)))
        study = Study(args)
        try:
            for n in (int(g) for g in args.grids.split(",")):
                fraction = fractions.get(n, fractions.get(None, 0.008))
                write_rows(stem + ".csv", study.grid(n, fraction, configs))
        finally:
            shutil.rmtree(study.work, ignore_errors=True)
    if not Path(stem + ".csv").exists():
        parser.error(f"no runs to report: {stem}.csv does not exist")
    report(stem, read_rows(stem + ".csv"), args.context)


if __name__ == "__main__":
    sys.exit(main())
