#!/usr/bin/python3
"""Roofline plot of kernels against the machine's ceilings.

Reads a JSON file of ceilings and kernel points and writes a log-log PNG: arithmetic
intensity (flops per byte) on x, GFLOP/s on y, each compute ceiling a horizontal line, each
bandwidth a diagonal, each kernel a point labelled with its node-steps per second and the
fraction it reaches of its roofline bound, min(compute, intensity × bandwidth) for the
ceilings it names.

  {"title": "...", "note": "machine, compiler, date (printed under the plot)",
   "compute": [{"name": "FP64 FMA zmm, 1 thread", "gflops": 86.3}, ...],
   "bandwidth": [{"name": "L3, 1 thread", "gbs": 30.1}, ...],
   "kernels": [{"name": "Verlet step, 1024²", "flops_per_node_step": 792,
                "bytes_per_node_step": 936, "node_steps_per_second": 2.9e6,
                "compute": "FP64 FMA zmm, 1 thread", "bandwidth": "L3, 1 thread"}]}

A kernel's "compute" and "bandwidth" default to the first of each list. Given several files
(e.g. before and after a rewrite), the plot takes the ceilings and title of the first and the
kernels of all.

  /usr/bin/python3 benchmarks/roofline.py roofline.json [more.json ...] roofline.png
"""

import json
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def bound(kernel, compute, bandwidth):
    """The kernel's roofline bound in GFLOP/s and the ceiling that sets it."""
    peak = compute[kernel.get("compute", next(iter(compute)))]
    bw_name = kernel.get("bandwidth", next(iter(bandwidth)))
    intensity = kernel["flops_per_node_step"] / kernel["bytes_per_node_step"]
    memory = intensity * bandwidth[bw_name]
    if memory < peak:
        return memory, bw_name
    return peak, kernel.get("compute", next(iter(compute)))


def plot(spec, path):
    compute = {c["name"]: c["gflops"] for c in spec["compute"]}
    bandwidth = {b["name"]: b["gbs"] for b in spec["bandwidth"]}
    kernels = spec["kernels"]
    intensities = [k["flops_per_node_step"] / k["bytes_per_node_step"] for k in kernels]
    top = max(compute.values())
    x_lo = min([0.05] + [0.3 * i for i in intensities])
    x_hi = max([100.0] + [3 * i for i in intensities])
    y_lo = min([0.5] + [0.3 * k["flops_per_node_step"] * k["node_steps_per_second"] / 1e9
                        for k in kernels])
    x = np.logspace(np.log10(x_lo), np.log10(x_hi), 400)

    # The legend in a panel of its own under the plot, so that it hides no point however many.
    legend_height = 0.42 * len(kernels)
    fig, (ax, legend_ax) = plt.subplots(
        2, 1, figsize=(9, 5.5 + legend_height),
        gridspec_kw={"height_ratios": [5.5, legend_height]})
    legend_ax.axis("off")
    for i, (name, gbs) in enumerate(sorted(bandwidth.items(), key=lambda item: -item[1])):
        ax.plot(x, np.minimum(x * gbs, top), color=f"C{i}", lw=1.6)
        # Labelled along the diagonal, where it is still below the highest roof.
        xl = x_lo * 1.6
        ax.text(xl, xl * gbs * 1.15, f"{name}: {gbs:.0f} GB/s", color=f"C{i}", rotation=0,
                fontsize=8, va="bottom")
    # Ceilings within 2 % of each other (ymm and zmm where the units are 256 bits wide) are
    # one line with both names, so that their labels do not print over each other.
    roofs = []
    for name, gflops in sorted(compute.items(), key=lambda item: -item[1]):
        if roofs and gflops > roofs[-1][1] / 1.02:
            roofs[-1][0].append(name)
        else:
            roofs.append(([name], gflops))
    for j, (names, gflops) in enumerate(roofs):
        ax.axhline(gflops, color="black", lw=1.4 if j == 0 else 0.9, ls="-" if j == 0 else "--",
                   xmin=0, xmax=1)
        ax.text(x_hi / 1.1, gflops * 1.06, f"{', '.join(names)}: {gflops:.1f} GFLOP/s",
                ha="right", fontsize=8)

    # Points close together would hide each other's labels: the labels go in the legend.
    for i, (k, intensity) in enumerate(zip(kernels, intensities)):
        gflops = k["flops_per_node_step"] * k["node_steps_per_second"] / 1e9
        limit, limit_name = bound(k, compute, bandwidth)
        color = f"C{(i + 3) % 10}"
        ax.plot([intensity, intensity], [gflops, limit], color=color, lw=0.8, ls=":")
        ax.plot(intensity, gflops, "os^Dv"[i % 5], color=color, ms=8, zorder=5,
                label=f"{k['name']}: {k['node_steps_per_second']:.2e} node-steps/s, "
                      f"{gflops:.2f} GFLOP/s,\n{gflops / limit:.1%} of its bound ({limit:.1f} "
                      f"GFLOP/s, {limit_name}); {k['flops_per_node_step']:.0f} flops, "
                      f"{k['bytes_per_node_step']:.0f} B per node-step")
    legend_ax.legend(*ax.get_legend_handles_labels(), loc="center", fontsize=7.5, frameon=False)

    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(y_lo, top * 2.5)
    ax.set_xlabel("arithmetic intensity (FP64 flops per byte)")
    ax.set_ylabel("GFLOP/s (FP64)")
    ax.set_title(spec.get("title", "roofline"))
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    if spec.get("note"):
        fig.text(0.01, 0.005, textwrap.fill(spec["note"], 150), fontsize=7, va="bottom")
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(path, dpi=130)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    specs = []
    for path in sys.argv[1:-1]:
        with open(path) as f:
            specs.append(json.load(f))
    spec = dict(specs[0], kernels=[k for s in specs for k in s["kernels"]])
    plot(spec, sys.argv[-1])


if __name__ == "__main__":
    main()
