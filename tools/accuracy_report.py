#!/usr/bin/python3
"""Plots and the markdown summary of the integrator study (tools/accuracy_study.py).

Reads STEM-stability.csv, STEM-accuracy.csv and STEM-rest.csv; writes STEM-work-precision.png,
STEM-error-vs-dt.png and STEM.md.

  /usr/bin/python3 tools/accuracy_report.py STEM --machine TEXT --build TEXT --date DATE
"""

import argparse
import csv
import math
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SCHEMES = ["verlet", "symplectic-euler", "euler", "midpoint", "rk4", "leapfrog",
           "velocity-verlet", "tc-verlet", "verlet-lagged", "semi-implicit",
           "semi-implicit-2"]
TARGETS = [1e-2, 1e-4, 1e-6]


def read(path):
    if not Path(path).exists():
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def number(text):
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def curves(accuracy):
    """scene -> scheme -> [(dt, wall, error)] of the runs that finished, by decreasing dt."""
    by = defaultdict(lambda: defaultdict(list))
    for r in accuracy:
        dt, wall, error = number(r["dt"]), number(r["wall_seconds"]), number(r["error"])
        if r["status"] == "ok" and None not in (dt, wall, error) and error > 0:
            by[r["scene"]][r["integrator"]].append((dt, wall, error))
    for scene in by.values():
        for points in scene.values():
            points.sort(reverse=True)
    return by


def slope(points):
    """Least-squares slope of log error against log dt."""
    if len(points) < 2:
        return None
    xs = [math.log(p[0]) for p in points]
    ys = [math.log(p[2]) for p in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else None


def time_at(points, target):
    """Wall time to reach `target` error, interpolated log-log between swept runs; None when
    the sweep does not reach it (no extrapolation)."""
    ordered = sorted(points, key=lambda p: p[2])
    for (_, w0, e0), (_, w1, e1) in zip(ordered, ordered[1:]):
        if e0 <= target <= e1:
            if e1 == e0:
                return min(w0, w1)
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(w0) + f * (math.log(w1) - math.log(w0)))
    if ordered and ordered[0][2] <= target and len(ordered) == 1:
        return ordered[0][1]
    # The coarsest run already beats the target: its time is an upper bound.
    if ordered and ordered[-1][2] <= target:
        return ordered[-1][1]
    return None


def plot(by, stem):
    scenes = list(by)
    for name, x_of, x_label in [("work-precision", lambda p: p[1], "wall time of the run (s)"),
                                ("error-vs-dt", lambda p: p[0], "time step dt (s)")]:
        fig, axes = plt.subplots(1, len(scenes), figsize=(5.5 * len(scenes), 4.5), squeeze=False)
        for ax, scene in zip(axes[0], scenes):
            for scheme in SCHEMES:
                points = by[scene].get(scheme)
                if not points:
                    continue
                style = "--" if scheme.startswith("semi-implicit") else "-"
                ax.loglog([x_of(p) for p in points], [p[2] for p in points], style, marker="o",
                          markersize=3, label=scheme)
            ax.set_title(scene)
            ax.set_xlabel(x_label)
            ax.set_ylabel("RMS error / sheet size")
            ax.grid(True, which="both", alpha=0.3)
        axes[0][-1].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(f"{stem}-{name}.png", dpi=110)
        plt.close(fig)


def fmt(value, spec=".3g"):
    return "—" if value is None else format(value, spec)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("stem")
    parser.add_argument("--machine", default="unknown")
    parser.add_argument("--build", default="unknown")
    parser.add_argument("--date", default="unknown")
    args = parser.parse_args()
    stem = args.stem
    stability = read(stem + "-stability.csv")
    accuracy = read(stem + "-accuracy.csv")
    rest = read(stem + "-rest.csv")
    by = curves(accuracy)
    if by:
        plot(by, stem)
    name = Path(stem).name
    out = [f"# Integrator study, {args.date}", "",
           f"Machine: {args.machine}. Build: {args.build}. Ranks × threads: 1 × 1 per run, "
           "two runs side by side on the two cores. Regenerate with "
           "`benchmarks/run_accuracy.sh`; definitions in docs/integrator-study.md.", ""]

    # Stability
    cases = list(dict.fromkeys(r["case"] for r in stability))
    out += ["## Largest stable Δt (s), and its ratio to the CFL estimate", "",
            "Bisection to 2 % on the stability monitor (`cosserat stable-dt --time T`). "
            "`≥` : stable up to Δt = T, the search's ceiling. Exit status of every "
            "`stable-dt` call: " + ", ".join(sorted({r["exit_status"] for r in stability}))
            + " (0: finished; every blow-up was stopped by the monitor; timeout: the search "
            "ran past the study's `--timeout` and was stopped, its cell says so).", "",
            "| case | T (s) | CFL est. | " + " | ".join(SCHEMES) + " |",
            "|---|---|---|" + "---|" * len(SCHEMES)]
    for case in cases:
        rows = {r["integrator"]: r for r in stability if r["case"] == case}
        first = next((r for r in rows.values() if r["cfl_dt"]), next(iter(rows.values())))
        cells = []
        for s in SCHEMES:
            r = rows.get(s)
            if r is None:
                cells.append("not run")
                continue
            if r["exit_status"] == "timeout":
                cells.append(r["cause"])
                continue
            dt, ratio = number(r["stable_dt"]), number(r["stable_over_cfl"])
            bound = "≥ " if number(r["unstable_dt"]) == 0 else ""
            cells.append(f"{bound}{fmt(dt, '.3g')} ({fmt(ratio, '.2f')})")
        out.append(f"| {case} | {first['duration']} | {fmt(number(first['cfl_dt']), '.3g')} | "
                   + " | ".join(cells) + " |")
    out += [""]

    # Accuracy
    if by:
        out += ["## Speed against error", "",
                f"![work-precision]({name}-work-precision.png)", "",
                f"![error against dt]({name}-error-vs-dt.png)", "",
                "Reference: RK4 (see docs/integrator-study.md); its own error estimate "
                "(Richardson) per scene: "
                + ", ".join(f"{sc} {fmt(number(next(r for r in accuracy if r['scene'] == sc)['reference_error']), '.1e')}"
                            for sc in by) + ".", "",
                "### Observed order (slope of log error against log Δt)", "",
                "| scheme | " + " | ".join(f"{sc}: all / finest 3" for sc in by) + " |",
                "|---|" + "---|" * len(by)]
        for s in SCHEMES:
            cells = []
            for sc in by:
                points = by[sc].get(s, [])
                cells.append(f"{fmt(slope(points), '.2f')} / {fmt(slope(points[-3:]), '.2f')}")
            out.append(f"| {s} | " + " | ".join(cells) + " |")
        out += ["", "### Fastest scheme to a relative error", "",
                "Wall time interpolated log-log along each scheme's sweep (no extrapolation; "
                "'—': the sweep does not reach that error).", "",
                "| scene | error | winner | its time (s) | runner-up | ratio | semi-implicit (s) | verlet (s) |",
                "|---|---|---|---|---|---|---|---|"]
        for sc in by:
            for target in TARGETS:
                times = {s: time_at(p, target) for s, p in by[sc].items()}
                ranked = sorted((t, s) for s, t in times.items() if t is not None)
                if not ranked:
                    out.append(f"| {sc} | {target:g} | — | — | — | — | — | — |")
                    continue
                winner = ranked[0]
                runner = ranked[1] if len(ranked) > 1 else (None, "—")
                ratio = runner[0] / winner[0] if runner[0] else None
                out.append(f"| {sc} | {target:g} | {winner[1]} | {fmt(winner[0])} | {runner[1]} | "
                           f"{fmt(ratio, '.2f')} | {fmt(times.get('semi-implicit'))} | "
                           f"{fmt(times.get('verlet'))} |")
        out += ["", "### Cost per step (wall s / step, median over the sweep)", "",
                "| scene | " + " | ".join(SCHEMES) + " |", "|---|" + "---|" * len(SCHEMES)]
        for sc in by:
            cells = []
            for s in SCHEMES:
                rows = [r for r in accuracy if r["scene"] == sc and r["integrator"] == s
                        and number(r["wall_seconds"])]
                per = sorted(number(r["wall_seconds"]) / int(r["steps"]) for r in rows)
                cells.append(fmt(per[len(per) // 2], ".2e") if per else "—")
            out.append(f"| {sc} | " + " | ".join(cells) + " |")
        out += [""]

    # Rest
    if rest:
        out += ["## Time to rest (kinetic energy below 1e-6 of its peak)", "",
                "At 90 % of the largest stable Δt over the stability study's T; `dt/limit` below "
                "0.9 means the run went unstable on its way to rest and was repeated at half "
                "the step (at most twice). Fix and load windows are scaled to keep their times.",
                "", "| scene | scheme | Δt (s) | dt/limit | steps | simulated s | wall s | status |",
                "|---|---|---|---|---|---|---|---|"]
        for r in rest:
            out.append(f"| {r['scene']} | {r['integrator']} | {fmt(number(r['dt']))} | "
                       f"{fmt(number(r.get('dt_over_limit')), '.2f')} | {r['rest_step'] or '—'} | "
                       f"{fmt(number(r['rest_time']))} | {fmt(number(r['wall_seconds']))} | "
                       f"{r['status']} |")
        out += [""]
    Path(stem + ".md").write_text("\n".join(out))
    print("\n".join(out))


if __name__ == "__main__":
    main()
