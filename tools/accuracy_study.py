#!/usr/bin/python3
"""The integrator study of issue 4, run through the `cosserat` executable.

  stability   largest stable dt (`cosserat stable-dt`) of S1-S6 and the hard cases, per scheme
  accuracy    error at time T against a reference run, and wall time, for a dt sweep per scheme
  rest        steps and wall time until the kinetic energy is below 1e-6 of its peak

Writes CSV files, PNG plots and a markdown summary under OUT (a path stem). Runs WORKERS
single-threaded processes side by side. See docs/integrator-study.md for the definitions.

  /usr/bin/python3 tools/accuracy_study.py --exe build/release/cosserat --out STEM
"""

import argparse
import concurrent.futures
import csv
import datetime
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

SCHEMES = ["verlet", "symplectic-euler", "euler", "midpoint", "rk4", "leapfrog",
           "velocity-verlet", "tc-verlet", "verlet-lagged", "semi-implicit",
           "semi-implicit-2"]
SLOW_FIRST = ["euler", "semi-implicit", "semi-implicit-2", "midpoint", "rk4"]
STABILITY_KEYS = ["scene", "integrator", "duration", "stable_dt", "unstable_dt", "cfl_dt",
                  "stable_over_cfl", "trials", "wall_seconds", "cause", "case", "exit_status"]
ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "scenes"


def scene_path(name):
    return str(SCENES / name)


class Study:
    def __init__(self, args):
        self.exe = args.exe
        self.out = Path(args.out)
        self.workers = args.workers
        self.work = Path(tempfile.mkdtemp(prefix="cosserat-study-"))
        self.env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1",
                        OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        self.quick = args.quick
        self.timeout = args.timeout
        self.max_node_steps = args.max_node_steps
        self.log = None

    def start(self):
        """Opens the log, appended to: the study can be run a piece at a time (--parts, --cases,
        --schemes)."""
        self.log = open(str(self.out) + ".log", "a")
        self.say(f"# {datetime.datetime.now().isoformat(timespec='seconds')}: "
                 + " ".join(sys.argv[1:]))

    def say(self, text):
        print(text, flush=True)
        if self.log is None:
            self.start()
        self.log.write(text + "\n")
        self.log.flush()

    def scene_file(self, label, text):
        path = self.work / f"{file_name(label)}.toml"
        path.write_text(text)
        return str(path)

    def at_step(self, label, scene, dt):
        """The scene with its fix and load windows, given in steps of the scene's own dt, moved
        to the same times at step dt (S1's corners are released at step 20001, S3's and S5's
        supports switch on at set steps)."""
        text = Path(scene).read_text()
        base_dt = float(re.search(r"^dt\s*=\s*([0-9.eE+-]+)", text, re.M).group(1))
        scaled = re.sub(r"^(start|end)(\s*=\s*)(\d+)",
                        lambda m: f"{m.group(1)}{m.group(2)}{round(int(m.group(3)) * base_dt / dt)}",
                        text, flags=re.M)
        return self.scene_file(label, scaled)

    # ------------------------------------------------------------------------------------------
    # Stability

    def stable_dt(self, job):
        """One `cosserat stable-dt` call for one scheme: job = (label, scene, overrides, T,
        scheme). A call that runs past the timeout leaves a row that says so."""
        label, scene, overrides, duration, scheme = job
        csv_path = self.work / f"stable-{file_name(label)}-{scheme}.csv"
        command = [self.exe, "stable-dt", scene, "--time", str(duration), "-q",
                   "--csv", str(csv_path), "--integrator", scheme]
        for o in overrides:
            command += ["--set", o]
        try:
            done = subprocess.run(command, env=self.env, capture_output=True, text=True,
                                  timeout=self.timeout)
        except subprocess.TimeoutExpired:
            row = dict.fromkeys(STABILITY_KEYS, "")
            row.update(integrator=scheme, duration=duration, case=label, exit_status="timeout",
                       cause=f"timed out after {self.timeout:g} s")
            return label, scheme, "timeout", "", [row]
        rows = []
        if csv_path.exists():
            with open(csv_path) as f:
                for row in csv.DictReader(f):
                    row["case"] = label
                    row["exit_status"] = done.returncode
                    rows.append(row)
        return label, scheme, done.returncode, done.stdout + done.stderr, rows

    def stability(self, cases):
        # One process per case and scheme, the slow schemes first so that the two workers end
        # together.
        jobs = [(label, scene, overrides, duration, scheme)
                for label, scene, overrides, duration, schemes in cases for scheme in schemes]
        jobs.sort(key=lambda job: SLOW_FIRST.index(job[4]) if job[4] in SLOW_FIRST else 99)
        rows = []
        with concurrent.futures.ThreadPoolExecutor(self.workers) as pool:
            for label, scheme, status, text, job_rows in pool.map(self.stable_dt, jobs):
                self.say(f"stable-dt {label} {scheme}: exit {status}\n{text.strip()}")
                if status != 0:
                    self.say(f"  !! stable-dt {label} {scheme} did not finish cleanly "
                             f"(exit {status})")
                rows += job_rows
        order = {(c[0], s): i for i, (c, s) in enumerate((c, s) for c in cases for s in c[4])}
        return sorted(rows, key=lambda r: order[(r["case"], r["integrator"])])

    # ------------------------------------------------------------------------------------------
    # Runs

    def run(self, label, scene, overrides, until_rest=None, timeout=None):
        """One `cosserat run` without frames but the first and last: (summary, final positions)."""
        return run_cosserat(self.exe, self.env, self.work / file_name(label), scene, overrides,
                            until_rest, timeout)

    # ------------------------------------------------------------------------------------------
    # Accuracy

    def accuracy(self, label, scene, duration, limits, levels, size, nodes):
        """Sweep each scheme from its stable limit down by halves; error against RK4. A run of
        more than max_node_steps (steps x nodes) is left out and listed as such."""
        jobs, skipped = [], []
        for scheme in SCHEMES:
            limit = limits.get(scheme, 0.0)
            if not limit > 0.0:
                continue
            for j in range(levels):
                steps = math.ceil(duration / (limit / 2 ** j) - 1e-9)
                (jobs if steps * nodes <= self.max_node_steps else skipped).append((scheme, steps))
        smallest = duration / max(steps for _, steps in jobs)
        # The reference: RK4 at 1/8 of the smallest swept step, but no finer than 1/256 of its
        # own limit, where its error is at round-off (the Richardson estimate below says so):
        # euler's tiny limits would otherwise ask for hours (docs/integrator-study.md).
        reference_steps = min(8 * max(steps for _, steps in jobs),
                              math.ceil(256 * duration / limits["rk4"]))
        self.say(f"{label}: reference rk4 with {reference_steps} steps "
                 f"(dt = {duration / reference_steps:.3g} s; smallest swept {smallest:.3g} s)")

        def one(job):
            scheme, steps = job
            name = f"{label}-{scheme}-{steps}"
            summary, positions = self.run(
                name, self.at_step(name, scene, duration / steps),
                [f'time.integrator="{scheme}"', f"time.dt={duration / steps!r}",
                 f"time.steps={steps}", f"time.output_every={steps}"])
            return scheme, steps, summary, positions

        with concurrent.futures.ThreadPoolExecutor(self.workers) as pool:
            reference_jobs = list(pool.map(one, [("rk4", reference_steps),
                                                 ("rk4", reference_steps // 2)]))
            results = list(pool.map(one, jobs))
        reference = reference_jobs[0][3]
        reference_error = rms(reference_jobs[1][3] - reference, size) / 15.0
        self.say(f"{label}: reference's own error (Richardson, order 4): {reference_error:.2e}")
        rows = [{"scene": label, "integrator": scheme, "dt": duration / steps, "steps": steps,
                 "wall_seconds": None, "error": None,
                 "status": f"not run: {steps * nodes:.3g} node-steps > --max-node-steps",
                 "reference_error": reference_error} for scheme, steps in skipped]
        for scheme, steps, summary, positions in results:
            error = rms(positions - reference, size) if positions is not None else float("nan")
            rows.append({"scene": label, "integrator": scheme, "dt": duration / steps,
                         "steps": steps, "wall_seconds": summary.get("wall_seconds"),
                         "error": error, "status": summary.get("status"),
                         "reference_error": reference_error})
            self.say(f"  {label} {scheme:17s} dt {duration / steps:.4g} error {error:.3e} "
                     f"wall {summary.get('wall_seconds')} {summary.get('status')}")
        return rows

    # ------------------------------------------------------------------------------------------
    # Time to rest

    def rest(self, label, scene, limits, longest, timeout):
        def attempt(scheme, dt):
            path = self.at_step(f"rest-{label}-{scheme}", scene, dt)
            steps = math.ceil(longest / dt)
            return self.run(f"rest-{label}-{scheme}", path,
                            [f'time.integrator="{scheme}"', f"time.dt={dt!r}",
                             f"time.steps={steps}", f"time.output_every={steps}"],
                            until_rest=1e-6, timeout=timeout)

        def one(scheme):
            # 90 % of the limit over the stability study's T; a run that goes unstable later, on
            # its way to rest, is repeated at half the step, twice at most.
            dt = 0.9 * limits[scheme]
            summary, _ = attempt(scheme, dt)
            for _ in range(2):
                if summary.get("status") != "unstable":
                    break
                dt *= 0.5
                summary, _ = attempt(scheme, dt)
            rest = summary.get("rest") or {}
            row = {"scene": label, "integrator": scheme, "dt": dt,
                   "dt_over_limit": dt / limits[scheme],
                   "rest_step": rest.get("step"),
                   "rest_time": rest["step"] * dt if rest.get("step") else None,
                   "wall_seconds": summary.get("wall_seconds"),
                   "status": summary.get("status")}
            self.say(f"  rest {label} {scheme:17s} dt {dt:.4g}: step {row['rest_step']} "
                     f"wall {row['wall_seconds']} {row['status']}")
            return row

        schemes = [s for s in SCHEMES if limits.get(s, 0.0) > 0.0]
        with concurrent.futures.ThreadPoolExecutor(self.workers) as pool:
            return list(pool.map(one, schemes))


def run_cosserat(exe, env, stem, scene, overrides, until_rest=None, timeout=None):
    """One `cosserat run` of scene with the --set overrides, writing STEM.h5 and STEM.json and
    removing them after: (summary, final positions, or None if the run did not end cleanly).
    The summary's status says why a run failed."""
    command = [exe, "run", str(scene), "-q", "-o", f"{stem}.h5", "--summary", f"{stem}.json"]
    for o in overrides:
        command += ["--set", o]
    if until_rest:
        command += ["--until-rest", str(until_rest)]
    try:
        done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"status": "timed out", "exit_status": None}, None
    summary = {"status": "no summary"}
    if Path(f"{stem}.json").exists():
        summary = json.loads(Path(f"{stem}.json").read_text())
    summary["exit_status"] = done.returncode
    if done.returncode not in (0, 3):
        summary["status"] = f"exit {done.returncode}: {done.stderr.strip()[-200:]}"
    positions = None
    if Path(f"{stem}.h5").exists() and done.returncode == 0:
        with h5py.File(f"{stem}.h5", "r") as f:
            positions = f["positions"][-1].reshape(-1, 3)
    for suffix in (".h5", ".xmf", ".json"):
        Path(f"{stem}{suffix}").unlink(missing_ok=True)
    return summary, positions


def file_name(label):
    return re.sub(r"[^A-Za-z0-9_.-]", "_", label)


def rms(difference, size):
    return float(np.sqrt(np.mean(np.sum(difference ** 2, axis=1)))) / size


def write_csv(path, rows, key=()):
    """Writes rows to path; with key (column names), rows already there whose key is not among
    the new rows' are kept, so that the study can be run a part, a case or a scheme at a time."""
    if key and Path(path).exists():
        with open(path) as f:
            new = {tuple(r[k] for k in key) for r in rows}
            rows = [r for r in csv.DictReader(f) if tuple(r[k] for k in key) not in new] + rows
    if not rows:
        return
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)


def nodes_of(scene):
    n = re.search(r"^nodes\s*=\s*\[\s*(\d+)\s*,\s*(\d+)\s*\]", Path(scene).read_text(), re.M)
    return int(n.group(1)) * int(n.group(2))


def limits_of(rows, case):
    return {r["integrator"]: float(r["stable_dt"]) for r in rows
            if r["case"] == case and r["stable_dt"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--exe", required=True, help="the cosserat executable")
    parser.add_argument("--out", required=True, help="stem of the result files")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--quick", action="store_true",
                        help="small sizes and times: a check that the study runs, not results")
    parser.add_argument("--parts", default="stability,accuracy,rest")
    parser.add_argument("--accuracy-scenes", default="S1,S2,hanging",
                        help="scenes of the speed-against-error sweep")
    parser.add_argument("--rest-scenes", default="S1,S2,S3,S5")
    parser.add_argument("--cases", help="stability cases to run, by label (default: all); the "
                        "rows of other cases already in the CSV are kept")
    parser.add_argument("--schemes", help="schemes of the stability cases to run (default: all)")
    parser.add_argument("--timeout", type=float, default=1800.0,
                        help="wall seconds one stable-dt search of one scheme may take")
    parser.add_argument("--max-node-steps", type=float, default=2e9,
                        help="largest run of the accuracy sweep, in steps x nodes")
    args = parser.parse_args()
    study = Study(args)
    parts = args.parts.split(",")
    quick = args.quick

    # The hanging sheet of the accuracy study and S1 at 240 x 240: S1's supports at the two
    # corners of one edge, at any resolution (jobs/make_large_sheet.sh).
    def hanging(nodes):
        path = study.work / f"hanging-{nodes}.toml"
        subprocess.run(["bash", str(ROOT / "jobs/make_large_sheet.sh"), str(nodes), "100",
                        str(path)], check=True)
        return str(path)

    s6_text = Path(scene_path("s6_compression.toml")).read_text()
    s6_loads_x5 = study.scene_file("s6-loads-x5", re.sub(
        r"^(force\s*=\s*)\[([^\]]*)\]",
        lambda m: m.group(1) + "[" + ", ".join(repr(5 * float(v)) for v in m.group(2).split(","))
        + "]", s6_text, flags=re.M))

    T = 0.2 if quick else 2.0  # simulated time each stability trial must survive
    T_fine = 0.05 if quick else 0.2
    hanging_nodes = 24 if quick else 120
    big_nodes = 30 if quick else 240
    scenes = {"S1": "s1_clothesline.toml", "S2": "s2_cape.toml", "S3": "s3_bench.toml",
              "S4": "s4_flag.toml", "S5": "s5_armchair.toml", "S6": "s6_compression.toml"}
    hanging_scene = hanging(hanging_nodes)
    cases = [(k, scene_path(v), [], T, SCHEMES) for k, v in scenes.items()]
    cases += [
        ("S1 zeta=500", scene_path(scenes["S1"]), ["material.zeta=500.0"], T, SCHEMES),
        ("S1 mass/10", scene_path(scenes["S1"]), ["material.mass=1.0"], T, SCHEMES),
        ("S1 mass*13", scene_path(scenes["S1"]), ["material.mass=130.0"], T, SCHEMES),
        ("S1 phi=1", scene_path(scenes["S1"]), ["material.phi=1.0"], T, SCHEMES),
        ("S1 xi=0", scene_path(scenes["S1"]), ["material.xi=0.0"], T, SCHEMES),
        ("S6 phi=1", scene_path(scenes["S6"]), ["material.phi=1.0"], T, SCHEMES),
        ("S6 xi=0", scene_path(scenes["S6"]), ["material.xi=0.0"], T, SCHEMES),
        ("S6 loads*5", s6_loads_x5, [], T, SCHEMES),
        (f"hanging {hanging_nodes}", hanging_scene, [], T_fine, SCHEMES),
        # Without the semi-implicit steps: a search starts at the scene's step, some 2900
        # steps over T at about 1.3 s each (0.32 s at 120 x 120): docs/integrator-study.md.
        (f"S1 {big_nodes}x{big_nodes}", hanging(big_nodes), [], T_fine / 2,
         [s for s in SCHEMES if not s.startswith("semi-implicit")]),
    ]
    def refuse(message):  # before any run and before the log is touched
        shutil.rmtree(study.work, ignore_errors=True)
        parser.error(message)

    if args.cases:
        chosen = args.cases.split(",")
        unknown = set(chosen) - {c[0] for c in cases}
        if unknown:
            refuse(f"unknown cases {sorted(unknown)}; known: {[c[0] for c in cases]}")
        cases = [c for c in cases if c[0] in chosen]
    if args.schemes:
        chosen = args.schemes.split(",")
        unknown = set(chosen) - set(SCHEMES)
        if unknown:
            refuse(f"unknown schemes {sorted(unknown)}; known: {SCHEMES}")
        cases = [c[:4] + ([s for s in c[4] if s in chosen],) for c in cases]
    if not any(c[4] for c in cases):
        refuse("--cases and --schemes leave no stable-dt search to run")
    stem = str(study.out)
    study.start()
    if "stability" in parts:
        write_csv(stem + "-stability.csv", study.stability(cases), key=("case", "integrator"))
    with open(stem + "-stability.csv") as f:
        stability_rows = list(csv.DictReader(f))

    if "accuracy" in parts:
        accuracy_rows = []
        chosen = args.accuracy_scenes.split(",")
        for label, scene, duration in [("S1", scene_path(scenes["S1"]), T),
                                       ("S2", scene_path(scenes["S2"]), T),
                                       (f"hanging {hanging_nodes}", hanging_scene, T_fine)]:
            if label.split()[0] not in chosen:
                continue
            levels = 4 if label.startswith("hanging") else 6
            accuracy_rows += study.accuracy(label, scene, duration,
                                            limits_of(stability_rows, label), levels, 10.0,
                                            nodes_of(scene))
            write_csv(stem + "-accuracy.csv", accuracy_rows, key=("scene",))

    if "rest" in parts:
        rest_rows = []
        for label in args.rest_scenes.split(","):
            rest_rows += study.rest(label, scene_path(scenes[label]),
                                    limits_of(stability_rows, label),
                                    longest=10.0 if quick else 30.0,
                                    timeout=60 if quick else 120)
            write_csv(stem + "-rest.csv", rest_rows, key=("scene",))
    shutil.rmtree(study.work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
