#!/usr/bin/python3
"""Strong and weak scaling efficiency from scaling logs (jobs/log_scaling.py).

    jobs/plot_scaling.py [--strong LOG.csv] [--weak LOG.csv] [--cores N] [--title T] --output STEM

Writes STEM.md (a table a study) and STEM.png (efficiency against ranks x threads).
With p = ranks x threads and r(p) the node-steps a second of a run:
- strong (one grid on every layout): speed-up r(p)/r(1), efficiency r(p)/(p r(1));
- weak (p times the one-core nodes on p): efficiency r(p)/(p r(1)), which is T(1)/T(p)
  for the same steps.
r(1) is the 1 x 1 run of the same study; where a layout ran more than once the last run counts.
Layouts with p above --cores (this machine's, by default) shared cores and are marked so.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    rows = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            rows[(int(row["ranks"]), int(row["threads"]), row["grid"])] = row
    return list(rows.values())


def study(rows, kind):
    ones = [r for r in rows if int(r["ranks"]) * int(r["threads"]) == 1]
    if not ones:
        raise SystemExit(f"plot_scaling.py: the {kind} log has no 1 x 1 run to compare with")
    base = float(ones[-1]["node_steps_per_second"])
    if kind == "strong":
        grids = {r["grid"] for r in rows}
        if len(grids) != 1:
            raise SystemExit(f"plot_scaling.py: the strong log has several grids: {sorted(grids)}")
    out = []
    for r in sorted(rows, key=lambda r: (int(r["ranks"]) * int(r["threads"]), int(r["ranks"]))):
        p = int(r["ranks"]) * int(r["threads"])
        rate = float(r["node_steps_per_second"])
        wall = float(r["wall_seconds"])
        halo = float(r["halo_seconds"] or 0.0)
        out.append(dict(row=r, p=p, rate=rate, speedup=rate / base, efficiency=rate / (p * base),
                        halo_share=halo / wall if wall > 0 else 0.0))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strong")
    parser.add_argument("--weak")
    parser.add_argument("--cores", type=int, default=os.cpu_count())
    parser.add_argument("--output", required=True)
    parser.add_argument("--title", default="Scaling efficiency, S1-like sheet (jobs/scaling_study.sh)")
    args = parser.parse_args()
    studies = [(k, p) for k, p in (("strong", args.strong), ("weak", args.weak)) if p]
    if not studies:
        parser.error("give --strong, --weak or both")
    lines = []
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for kind, path in studies:
        points = study(load(path), kind)
        first = points[0]["row"]
        lines += [f"## {kind.capitalize()} scaling", "",
                  f"Machine {first['machine']} ({first['cpu']}), {args.cores} cores; launcher "
                  f"{first['launcher']}; log `{path}`.", "",
                  "| ranks x threads | grid | split | node-steps/s | speed-up | efficiency | "
                  "halo share | revision | date |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for q in points:
            r = q["row"]
            shared = " (cores shared)" if q["p"] > args.cores else ""
            lines.append(f"| {r['ranks']} x {r['threads']}{shared} | {r['grid']} | {r['split']} | "
                         f"{q['rate']:.3g} | {q['speedup']:.2f} | {q['efficiency']:.0%} | "
                         f"{q['halo_share']:.1%} | {r['revision']} | {r['date']} |")
        lines.append("")
        inside = [q for q in points if q["p"] <= args.cores]
        beyond = [q for q in points if q["p"] > args.cores]
        marker = "o" if kind == "strong" else "s"
        ax.plot([q["p"] for q in inside], [q["efficiency"] for q in inside], marker=marker,
                linestyle="-", label=f"{kind} ({first['grid'] if kind == 'strong' else 'per core'})")
        for q in inside + beyond:
            ax.annotate(f"{q['row']['ranks']}x{q['row']['threads']}", (q["p"], q["efficiency"]),
                        textcoords="offset points", xytext=(4, 4), fontsize=8)
        if beyond:
            ax.plot([q["p"] for q in beyond], [q["efficiency"] for q in beyond], marker=marker,
                    linestyle="none", fillstyle="none", color=ax.lines[-1].get_color(),
                    label=f"{kind}, cores shared")
    ax.axhline(1.0, color="grey", linewidth=0.8)
    ax.set_xlabel("ranks x threads")
    ax.set_ylabel("efficiency r(p) / (p r(1))")
    ax.set_ylim(0, 1.2)
    ax.set_xscale("log", base=2)
    ax.legend(fontsize=8)
    ax.set_title(args.title, fontsize=10)
    fig.tight_layout()
    fig.savefig(args.output + ".png", dpi=120)
    with open(args.output + ".md", "w") as f:
        f.write("# Scaling efficiency\n\n" + "\n".join(lines))
    print(f"wrote {args.output}.md, {args.output}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
