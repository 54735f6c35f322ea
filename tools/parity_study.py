#!/usr/bin/python3
"""Parity of the energy form with the flux form (issue 11, item 6 and item 1's throughput).

  stability   largest stable Verlet dt of S1-S6 per discretisation (`cosserat stable-dt`)
  refinement  an S1-like sheet on nested grids of 9 * 2^j + 1 nodes a side, both forms at one
              dt: distance between the forms and each form's self-convergence at the nodes
              of the coarsest grid, with observed orders
  throughput  node-steps/s of both forms on a 1024 x 1024 sheet, 1 and 2 threads

Writes STEM-stability.csv, STEM-refinement.csv, STEM-throughput.csv, STEM-refinement.png,
STEM.md and STEM.log. Used by benchmarks/run_parity.sh, which records the context.

  /usr/bin/python3 tools/parity_study.py --exe COSSERAT --out STEM --context TEXT
"""

import argparse
import concurrent.futures
import csv
import datetime
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

ROOT = Path(__file__).resolve().parent.parent
FORMS = ["flux", "energy"]
SCENES = [("S1", "s1_clothesline.toml"), ("S2", "s2_cape.toml"), ("S3", "s3_bench.toml"),
          ("S4", "s4_flag.toml"), ("S5", "s5_armchair.toml"), ("S6", "s6_compression.toml")]
SIZE = 10.0  # the sheet's side (m): distances are reported relative to it



def s1_like_scene(nodes, dt, steps, every, support):
    """S1's sheet, material and environment on a nodes x nodes grid (nodes = 9 * 2^j + 1),
    held throughout (S1's fix window, 20 001 steps, outlasts its run; here it has no end so
    that no dt releases it) by
      corners   S1's supports: the corner nodes [0, 0] and [0, nodes-1] of the x1 = 0 edge;
      segments  the x1 = 0 edge from each of those corners to the next node of the 10 x 10
                grid (10/9 m at each end), the same support on every grid;
    with "-undamped" appended, without S1's medium damping (the forms' damping differs by
    the area ratio S/S0: the flux form's μ = M/S is the current one, the energy form's μ0
    = M/S0 the rest one)."""
    damping = 0.0 if support.endswith("-undamped") else 0.2
    if support.startswith("corners"):
        fix = f"[[fix]]\nnodes = [[0, 0], [0, {nodes - 1}]]\n"
    else:
        s = (nodes - 1) // 9
        fix = (f"[[fix]]\nregion = {{ rect = [0, 0, 0, {s}] }}\n"
               f"[[fix]]\nregion = {{ rect = [0, {nodes - 1 - s}, 0, {nodes - 1}] }}\n")
    return f"""title = "S1-like sheet {nodes} x {nodes}"
[grid]
nodes = [{nodes}, {nodes}]
size = [{SIZE}, {SIZE}]
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
damping = {damping!r}
[time]
integrator = "verlet"
dt = {dt!r}
steps = {steps}
output_every = {every}
{fix}"""


class LoggedStudy:
    """A study's log, STEM.log, appended to (a study can be run a part at a time); each line
    is printed too. The first line: the time and the command line. Also the environment of its
    single-threaded runs, as root."""

    def __init__(self, stem):
        self.env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1",
                        OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        self.log = open(str(stem) + ".log", "a")
        self.say(f"# {datetime.datetime.now().isoformat(timespec='seconds')}: "
                 + " ".join(sys.argv[1:]))

    def say(self, text):
        print(text, flush=True)
        self.log.write(text + "\n")
        self.log.flush()


class Study(LoggedStudy):
    def __init__(self, args):
        self.exe = args.exe
        self.stem = args.out
        self.workers = args.workers
        self.work = Path(tempfile.mkdtemp(prefix="cosserat-parity-"))
        super().__init__(self.stem)

    def form(self, name):
        return f'model.discretisation="{name}"'

    # ------------------------------------------------------------------------------------------
    def stable_dt(self, job):
        label, scene, form, duration = job
        path = self.work / f"stable-{label}-{form}.csv"
        command = [self.exe, "stable-dt", str(ROOT / "scenes" / scene), "--integrator", "verlet",
                   "--time", repr(duration), "--set", self.form(form), "--csv", str(path), "-q"]
        done = subprocess.run(command, env=self.env, capture_output=True, text=True)
        row = {"case": label, "form": form, "duration": duration, "exit_status": done.returncode}
        if path.exists():
            with open(path) as f:
                found = list(csv.DictReader(f))
            if found:
                row.update(found[0])
        row["form"] = form
        self.say(f"stable-dt {label} {form}: exit {done.returncode}, "
                 f"{row.get('stable_dt')} s ({row.get('trials')} trials, "
                 f"{row.get('wall_seconds')} s wall) {done.stderr.strip()[-300:]}")
        return row

    def stability(self, duration):
        jobs = [(label, scene, form, duration) for label, scene in SCENES for form in FORMS]
        with concurrent.futures.ThreadPoolExecutor(self.workers) as pool:
            return list(pool.map(self.stable_dt, jobs))

    # ------------------------------------------------------------------------------------------
    def sheet(self, nodes, dt, steps, every, support):
        """The S1-like scene (s1_like_scene) written to a file of the work folder."""
        path = self.work / f"sheet-{support}-{nodes}-{dt!r}.toml"
        path.write_text(s1_like_scene(nodes, dt, steps, every, support))
        return str(path)

    def run(self, job):
        """One run of the sheet: (job, summary, {time: positions [m, n, 3]})."""
        support, nodes, form, dt, duration, samples = job
        steps = round(duration / dt)
        every = round(duration / samples / dt)
        scene = self.sheet(nodes, dt, steps, every, support)
        stem = self.work / f"run-{support}-{nodes}-{form}-{dt!r}"
        command = [self.exe, "run", scene, "--set", self.form(form), "-o", f"{stem}.h5",
                   "--summary", f"{stem}.json", "-q"]
        done = subprocess.run(command, env=self.env, capture_output=True, text=True)
        summary = json.loads(Path(f"{stem}.json").read_text()) if Path(f"{stem}.json").exists() \
            else {"status": "no summary"}
        summary["exit_status"] = done.returncode
        frames = {}
        if done.returncode == 0:
            with h5py.File(f"{stem}.h5", "r") as f:
                for t, r in zip(f["time"][:], f["positions"][:]):
                    frames[round(float(t), 9)] = np.array(r)
        for suffix in (".h5", ".xmf", ".json"):
            Path(f"{stem}{suffix}").unlink(missing_ok=True)
        self.say(f"run {support} {nodes}x{nodes} {form} dt {dt:g} T {duration:g}: exit {done.returncode} "
                 f"{summary.get('status')} wall {summary.get('wall_seconds')} s "
                 f"{done.stderr.strip()[-300:]}")
        return job, summary, frames

    def refinement(self, levels, dt, duration, samples, supports):
        grids = [9 * 2 ** j + 1 for j in range(levels)]
        check = grids[min(2, levels - 1)]
        jobs = []
        for support in supports:  # the largest runs first, so that the two workers end together
            jobs += [(support, n, form, dt, duration, samples) for n in reversed(grids)
                     for form in FORMS]
            # The time-error check: the middle grid again at dt / 2.
            jobs += [(support, check, form, dt / 2, duration, samples) for form in FORMS]
        jobs.sort(key=lambda job: -job[1] ** 2 / job[3])
        with concurrent.futures.ThreadPoolExecutor(self.workers) as pool:
            results = list(pool.map(self.run, jobs))
        rows = []
        for support in supports:
            rows += self.compare(support, grids, check, dt, duration,
                                 [r for r in results if r[0][0] == support])
        walls = [{"support": job[0], "nodes": job[1], "form": job[2], "dt": job[3],
                  "wall_seconds": s.get("wall_seconds"), "status": s.get("status"),
                  "area_ratio": s.get("area_ratio")} for job, s, _ in results]
        return rows, walls

    def compare(self, support, grids, check, dt, duration, results):
        runs = {(job[1], job[2], job[3]): (summary, frames) for job, summary, frames in results}
        for key, (summary, frames) in runs.items():
            if not frames:
                raise SystemExit(f"refinement run {key} failed: {summary}")

        def common(n, frames, t):
            stride = (n - 1) // (grids[0] - 1)
            return frames[t][::stride, ::stride, :].reshape(-1, 3)

        def distance(a, b):
            d = np.linalg.norm(a - b, axis=1) / SIZE
            return float(np.sqrt(np.mean(d ** 2))), float(d.max())

        times = sorted(runs[(grids[0], "flux", dt)][1])[1:]
        rows = []
        for t in times:
            for n in grids:
                h = SIZE / (n - 1)
                pos = {form: common(n, runs[(n, form, dt)][1], t) for form in FORMS}
                rms_, max_ = distance(pos["energy"], pos["flux"])
                rows.append({"time": t, "quantity": "energy-flux", "nodes": n, "h": h,
                             "rms": rms_, "max": max_})
                if n != grids[0]:
                    coarser = (n - 1) // 2 + 1
                    # Richardson with order 1 (each form's observed order): 2 r_h - r_2h.
                    extra = {form: 2 * pos[form] - common(coarser, runs[(coarser, form, dt)][1], t)
                             for form in FORMS}
                    rms_, max_ = distance(extra["energy"], extra["flux"])
                    rows.append({"time": t, "quantity": "extrapolated energy-flux", "nodes": n,
                                 "h": h, "rms": rms_, "max": max_})
                    for form in FORMS:
                        rms_, max_ = distance(pos[form],
                                              common(coarser, runs[(coarser, form, dt)][1], t))
                        rows.append({"time": t, "quantity": f"{form} {coarser}->{n}",
                                     "nodes": n, "h": h, "rms": rms_, "max": max_})
                if n == check:
                    for form in FORMS:
                        rms_, max_ = distance(pos[form],
                                              common(n, runs[(n, form, dt / 2)][1], t))
                        rows.append({"time": t, "quantity": f"{form} dt/2", "nodes": n,
                                     "h": h, "rms": rms_, "max": max_})
        for r in rows:
            r.update(support=support, dt=dt, duration=duration)
        return rows

    # ------------------------------------------------------------------------------------------
    def throughput(self, nodes, steps, dt, repetitions, threads):
        rows = []
        for thread_count in threads:
            env = dict(self.env, OMP_NUM_THREADS=str(thread_count), OMP_PROC_BIND="close")
            for rep in range(repetitions):
                for form in FORMS:  # interleaved, so that a change of load hits both forms
                    stem = self.work / f"tp-{form}-{thread_count}-{rep}"
                    command = [self.exe, "run", str(ROOT / "scenes/s1_clothesline.toml"),
                               "--set", self.form(form),
                               "--set", f"grid.nodes=[{nodes},{nodes}]",
                               "--set", f"time.steps={steps}", "--set", f"time.dt={dt!r}",
                               "--set", f"time.output_every={steps}",
                               "-o", f"{stem}.h5", "--summary", f"{stem}.json", "-q"]
                    done = subprocess.run(command, env=env, capture_output=True, text=True)
                    s = json.loads(Path(f"{stem}.json").read_text())
                    for suffix in (".h5", ".xmf", ".json"):
                        Path(f"{stem}{suffix}").unlink(missing_ok=True)
                    rows.append({"form": form, "threads": s["threads"], "ranks": s["ranks"],
                                 "repetition": rep, "nodes": nodes, "steps": s["steps"],
                                 "wall_seconds": s["wall_seconds"],
                                 "node_steps_per_second": s["node_steps_per_second"],
                                 "status": s["status"], "exit_status": done.returncode,
                                 "loadavg": Path("/proc/loadavg").read_text().split()[0]})
                    self.say(f"throughput {form} {thread_count} thread(s) #{rep}: "
                             f"{s['node_steps_per_second']:.4g} node-steps/s, "
                             f"{s['wall_seconds']:.3f} s, load {rows[-1]['loadavg']}")
        return rows


def write_csv(path, rows):
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def order(a, b):
    """Observed order between two successive values on grids h and h/2."""
    a, b = float(a), float(b)
    return math.log2(a / b) if a > 0 and b > 0 else float("nan")


def report(stem, context, notes):
    """STEM.md and STEM-refinement.png from the three CSV files."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lines = [f"# Parity of the energy form with the flux form, {context['date']}", "",
             f"Machine: {context['machine']}. Build: "
             + ("; ".join(f"{b} (parts run: {parts})" for parts, b in notes["builds"].items())
                if notes.get("builds") else context["build"]) + ". "
             f"Ranks × threads: {context['layout']}. Date: {context['date']}.",
             f"Regenerate with `benchmarks/run_parity.sh` (binary: {context['binary']}); "
             f"the log of every run: `{Path(stem).name}.log`.", ""]

    if Path(stem + "-stability.csv").exists():
        rows = read_csv(stem + "-stability.csv")
        by = {(r["case"], r["form"]): r for r in rows}
        lines += ["## Largest stable Verlet Δt (s)", "",
                  f"`cosserat stable-dt SCENE --integrator verlet --time {rows[0]['duration']}` "
                  "with `--set model.discretisation=\"flux\"` or `\"energy\"`, bisection to 2 %; "
                  "each search one process, 1 rank × 1 thread, two side by side. "
                  "CFL: the estimate of docs/stability.md (the same for both forms).", "",
                  "| scene | CFL est. | flux | energy | energy / flux | flux / CFL | energy / CFL "
                  "| what stopped energy's first unstable trial |",
                  "|---|---|---|---|---|---|---|---|"]
        for label, _ in SCENES:
            f, e = by.get((label, "flux"), {}), by.get((label, "energy"), {})
            try:
                fs, es, cfl = float(f["stable_dt"]), float(e["stable_dt"]), float(f["cfl_dt"])
                lines.append(f"| {label} | {cfl:.3g} | {fs:.4g} | {es:.4g} | {es / fs:.3f} | "
                             f"{fs / cfl:.2f} | {es / cfl:.2f} | {e.get('cause', '')} |")
            except (KeyError, ValueError, TypeError):
                lines.append(f"| {label} | | {f.get('stable_dt', 'failed')} | "
                             f"{e.get('stable_dt', 'failed')} | | | | |")
        lines.append("")

    if Path(stem + "-refinement.csv").exists():
        all_rows = read_csv(stem + "-refinement.csv")
        for r in all_rows:
            r.setdefault("support", "corners")
        supports = list(dict.fromkeys(r["support"] for r in all_rows))
        dt, duration = float(all_rows[0]["dt"]), float(all_rows[0]["duration"])
        times = sorted({float(r["time"]) for r in all_rows})
        grids = sorted({int(r["nodes"]) for r in all_rows})
        lines += ["## Refinement: an S1-like sheet on nested grids", "",
                  f"S1's sheet, material, gravity and damping on n × n nodes, n = "
                  f"{', '.join(map(str, grids))} (9·2^j + 1: each grid's nodes include every "
                  f"node of the coarser ones, h = 10/(n−1) m halves exactly), held throughout "
                  "by one of two supports:", "",
                  "- **corners**: S1's own, the corner nodes [0, 0] and [0, n−1] of the x1 = 0 "
                  "edge. A point support of a membrane is singular (the continuum sheet's "
                  "stretch near it grows without bound, logarithmically, as the support "
                  "shrinks), so on finer grids the sheet hangs lower near the corners and "
                  "neither form need converge there;",
                  "- **segments**: the x1 = 0 edge from each of those corners to the 10² grid's "
                  "next node (10/9 m at each end; nodes [0, 0…(n−1)/9] and [0, n−1−(n−1)/9…n−1]) "
                  "— the same physical support on every grid;",
                  "- **segments-undamped**: the same without the medium damping, the one "
                  "term the forms define differently on purpose: the flux form's damping is "
                  "ϱ_D/μ with μ = M/S at the current area S, the energy form's uses the rest "
                  "density μ0 = M/S0 (constant nodal mass, §2.5); the hanging sheet stretches "
                  "by S/S0 ≈ 1.011, so the flux form damps about 1 % harder, a difference no "
                  "refinement removes.", "",
                  "\"Extrapolated\": the distance between the forms' Richardson extrapolations "
                  "2 r_h − r_2h (order 1, each form's observed order), an estimate of how far "
                  "apart their limits h → 0 are.", "",
                  f"Both forms, Verlet, Δt = {dt:g} s at every grid, to T = {duration:g} s. "
                  f"Distances are measured at the {grids[0]}² nodes of the coarsest grid (every "
                  f"2^j-th node of the finer ones), as |Δr| / 10 m, RMS and max over those "
                  f"{grids[0] ** 2} points. Order: log2 of the ratio of successive values "
                  "(h halves).", ""]
        for support in supports:
            rows = [r for r in all_rows if r["support"] == support]
            for t in times:
                at = [r for r in rows if float(r["time"]) == t]
                lines += [f"### {support}, t = {t:g} s", "",
                          "| n | h (m) | energy − flux RMS | order | energy − flux max | order "
                          "| extrapolated: RMS | max |",
                          "|---|---|---|---|---|---|---|---|"]
                prev = None
                for n in grids:
                    r = next(r for r in at if r["quantity"] == "energy-flux"
                             and int(r["nodes"]) == n)
                    o = (f"{order(prev['rms'], r['rms']):.2f}",
                         f"{order(prev['max'], r['max']):.2f}") if prev else ("", "")
                    x = next((r for r in at if r["quantity"] == "extrapolated energy-flux"
                              and int(r["nodes"]) == n), None)
                    xs = f"{float(x['rms']):.3e} | {float(x['max']):.3e}" if x else " | "
                    lines.append(f"| {n} | {float(r['h']):.4f} | {float(r['rms']):.3e} | {o[0]} "
                                 f"| {float(r['max']):.3e} | {o[1]} | {xs} |")
                    prev = r
                lines += ["", "Self-convergence: each form against itself on the next coarser "
                          "grid.", "", "| grids | h of the finer (m) | flux RMS | order "
                          "| flux max | order | energy RMS | order | energy max | order |",
                          "|---|---|---|---|---|---|---|---|---|---|"]
                prev = {}
                for n in grids[1:]:
                    cells = []
                    for form in FORMS:
                        r = next(r for r in at if int(r["nodes"]) == n
                                 and r["quantity"].startswith(form + " ")
                                 and "->" in r["quantity"])
                        p = prev.get(form)
                        cells += [f"{float(r['rms']):.3e}",
                                  f"{order(p['rms'], r['rms']):.2f}" if p else "",
                                  f"{float(r['max']):.3e}",
                                  f"{order(p['max'], r['max']):.2f}" if p else ""]
                        prev[form] = r
                    lines.append(f"| {(n - 1) // 2 + 1} → {n} | {SIZE / (n - 1):.4f} | "
                                 + " | ".join(cells) + " |")
                checks = [r for r in at if r["quantity"].endswith("dt/2")]
                if checks:
                    lines += ["", "Time error: the same grid at Δt and Δt/2 (Verlet, second "
                              "order: the error of the Δt run is about 4/3 of this difference), "
                              "against the space differences above:", ""]
                    for r in checks:
                        lines.append(f"- {r['quantity'].split()[0]}, {r['nodes']}²: RMS "
                                     f"{float(r['rms']):.2e}, max {float(r['max']):.2e}")
                lines.append("")

        fig, axes = plt.subplots(len(supports), len(times),
                                 figsize=(6 * len(times), 4.8 * len(supports)), squeeze=False)
        for row_axes, support in zip(axes, supports):
            rows = [r for r in all_rows if r["support"] == support]
            for ax, t in zip(row_axes, times):
                at = [r for r in rows if float(r["time"]) == t]
                for q, style, label in [("energy-flux", "k", "energy − flux")] + \
                        [(form, c, f"{form}: n vs its coarser grid")
                         for form, c in zip(FORMS, ["tab:blue", "tab:red"])]:
                    sel = [r for r in at if r["quantity"] == q
                           or (q in FORMS and r["quantity"].startswith(q + " ")
                               and "->" in r["quantity"])]
                    sel.sort(key=lambda r: -float(r["h"]))
                    hs = [float(r["h"]) for r in sel]
                    ax.loglog(hs, [float(r["rms"]) for r in sel], "o-", color=style,
                              label=f"{label}, RMS")
                    ax.loglog(hs, [float(r["max"]) for r in sel], "s--", color=style,
                              label=f"{label}, max", alpha=0.6)
                h = np.array(sorted({float(r["h"]) for r in at}))
                ref = max(float(r["rms"]) for r in at if "->" in r["quantity"])
                ax.loglog(h, ref * (h / h.max()), ":", color="gray", label="O(h)")
                ax.loglog(h, ref * (h / h.max()) ** 2, "-.", color="gray", label="O(h²)")
                ax.set_xlabel("h of the (finer) grid (m)")
                ax.set_ylabel("|Δr| / 10 m at the coarsest grid's nodes")
                ax.set_title(f"{support} supports, t = {t:g} s, Δt = {dt:g} s")
                ax.grid(True, which="both", alpha=0.3)
                ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(stem + "-refinement.png", dpi=100)
        lines += [f"![refinement]({Path(stem).name}-refinement.png)", ""]
        if Path(stem + "-refinement-runs.csv").exists():
            runs = read_csv(stem + "-refinement-runs.csv")
            for r in runs:
                r.setdefault("support", "corners")
            lines += ["Wall time of each refinement run (s, 1 rank × 1 thread, two runs side by "
                      "side):", "", "| support | n | Δt | flux | energy |", "|---|---|---|---|---|"]
            seen = sorted({(r["support"], int(r["nodes"]), float(r["dt"])) for r in runs})
            for sup, n, d in seen:
                w = {r["form"]: float(r["wall_seconds"]) for r in runs if r["support"] == sup
                     and int(r["nodes"]) == n and float(r["dt"]) == d}
                lines.append(f"| {sup} | {n} | {d:g} | {w.get('flux', float('nan')):.2f} | "
                             f"{w.get('energy', float('nan')):.2f} |")
            lines.append("")

    if Path(stem + "-throughput.csv").exists():
        rows = read_csv(stem + "-throughput.csv")
        n, steps = rows[0]["nodes"], rows[0]["steps"]
        lines += ["## Throughput", "",
                  f"S1 on {n} × {n} nodes, {steps} Verlet steps (`node_steps_per_second` of "
                  "the run summary: the step loop and its last frame), 1 rank, OMP_PROC_BIND="
                  "close, median of the repetitions (the forms interleaved, one run at a time).",
                  "", "| threads | flux node-steps/s | energy node-steps/s | energy / flux "
                  "| flux runs | energy runs |", "|---|---|---|---|---|---|"]
        for th in sorted({int(r["threads"]) for r in rows}):
            med, every = {}, {}
            for form in FORMS:
                v = [float(r["node_steps_per_second"]) for r in rows
                     if r["form"] == form and int(r["threads"]) == th]
                med[form] = statistics.median(v)
                every[form] = ", ".join(f"{x:.3g}" for x in v)
            lines.append(f"| {th} | {med['flux']:.3e} | {med['energy']:.3e} | "
                         f"{med['energy'] / med['flux']:.2f} | {every['flux']} | "
                         f"{every['energy']} |")
        lines += ["", f"Load (1-min average, `uptime`): {notes.get('load', 'not recorded')}.", ""]

    if notes.get("walls"):
        lines += ["Wall time of `tools/parity_study.py`: " + "; ".join(
            f"{wall} ({parts})" for parts, wall in notes["walls"].items()) + ".", ""]
    Path(stem + ".md").write_text("\n".join(lines))
    print("\n".join(lines))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--exe", required=True)
    parser.add_argument("--out", required=True, help="stem of the result files")
    parser.add_argument("--parts", default="stability,refinement,throughput")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--stability-time", type=float, default=2.0)
    parser.add_argument("--levels", type=int, default=5, help="grids 9*2^j+1, j < LEVELS")
    parser.add_argument("--dt", type=float, default=1e-4)
    parser.add_argument("--time", type=float, default=2.0, help="refinement runs' T")
    parser.add_argument("--supports", default="corners,segments,segments-undamped",
                        help="refinement sheets: corners (S1's supports), segments, and either "
                        "with -undamped")
    parser.add_argument("--samples", type=int, default=2, help="compared times in (0, T]")
    parser.add_argument("--tp-nodes", type=int, default=1024)
    parser.add_argument("--tp-steps", type=int, default=40)
    parser.add_argument("--tp-dt", type=float, default=1e-6)
    parser.add_argument("--tp-repetitions", type=int, default=3)
    parser.add_argument("--tp-threads", default="1,2")
    parser.add_argument("--context", default="{}", help="JSON: machine, build, layout, date, "
                        "binary")
    parser.add_argument("--report-only", action="store_true")
    args = parser.parse_args()
    context = json.loads(args.context)
    stem = args.out
    notes_path = Path(stem + "-notes.json")
    notes = json.loads(notes_path.read_text()) if notes_path.exists() else {}
    if not args.report_only:
        study = Study(args)
        started = time.time()
        parts = args.parts.split(",")
        try:
            if "stability" in parts:
                write_csv(stem + "-stability.csv", study.stability(args.stability_time))
            if "refinement" in parts:
                rows, walls = study.refinement(args.levels, args.dt, args.time, args.samples,
                                               args.supports.split(","))
                write_csv(stem + "-refinement.csv", rows)
                write_csv(stem + "-refinement-runs.csv", walls)
            if "throughput" in parts:
                before = Path("/proc/loadavg").read_text().split()[:3]
                rows = study.throughput(args.tp_nodes, args.tp_steps, args.tp_dt,
                                        args.tp_repetitions,
                                        [int(t) for t in args.tp_threads.split(",")])
                after = Path("/proc/loadavg").read_text().split()[:3]
                write_csv(stem + "-throughput.csv", rows)
                notes["load"] = (f"{' / '.join(before)} (1/5/15 min) before, "
                                 f"{' / '.join(after)} after; the machine has "
                                 f"{os.cpu_count()} cores")
            notes.setdefault("builds", {})[args.parts] = context.get("build", "")
            notes.setdefault("walls", {})[args.parts] = f"{(time.time() - started) / 60:.1f} min"
            notes_path.write_text(json.dumps(notes))
        finally:
            shutil.rmtree(study.work, ignore_errors=True)
    report(stem, context, notes)


if __name__ == "__main__":
    sys.exit(main())
