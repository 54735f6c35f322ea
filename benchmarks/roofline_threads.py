#!/usr/bin/python3
"""The Verlet step on one and on two threads against the roofline of as many cores.

Takes the ceilings and counts of a run_roofline.sh run (ROOFLINE_STEM-{flops,bandwidth,
counts}.json) and the medians of a run_throughput.sh run (THROUGHPUT_JSON), and writes
OUT_STEM.json (roofline.py's input) and OUT_STEM.png, and prints a table: each grid's step on
1 and 2 threads, and the fraction of its bound, min(FMA peak, intensity × triad bandwidth), on
that many cores. A 256² sheet (about 10 MB) is held to the bandwidth of a 24 MiB triad, larger
ones to that of memory. If two threads reach a smaller fraction of their roof than one, what
they lose is not a ceiling of the machine.

  /usr/bin/python3 benchmarks/roofline_threads.py ROOFLINE_STEM THROUGHPUT_JSON OUT_STEM
"""

import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from roofline import bound, plot  # noqa: E402


def best(path, key):
    """{benchmark name without its time suffix: best counter over the repetitions}."""
    values = {}
    for b in json.load(open(path))["benchmarks"]:
        if b.get("run_type") == "iteration":
            name = b["run_name"].rsplit("/", 1)[0]
            values[name] = max(values.get(name, 0.0), b[key])
    return values


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    stem, throughput_path, out = sys.argv[1:]
    flops = best(stem + "-flops.json", "results_per_second")
    bandwidth = best(stem + "-bandwidth.json", "bytes_per_second")
    counts = json.load(open(stem + "-counts.json"))
    cache = counts["cache"]["total"]
    step_flops = counts["total"]["flops"]
    step_bytes = cache["l2_fill_bytes"] + cache["l2_write_miss_bytes"]
    throughput = json.load(open(throughput_path))
    rates = {}
    for b in throughput["benchmarks"]:
        if b.get("aggregate_name") == "median":
            nodes = int(b["name"].split("nodes:")[1].split("/")[0])
            rates[(nodes, int(b["threads"]))] = b["items_per_second"]

    threads_name = {1: "1 thread", 2: "2 threads"}
    compute = [{"name": f"FP64 FMA, {threads_name[t]}",
                "gflops": 2 * flops[f"fma/lanes:8/threads:{t}"] / 1e9} for t in (1, 2)]
    levels = {"L3 (24 MiB)": 24 * 1024, "DRAM": 1536 * 1024}
    roofs = [{"name": f"{level}, {threads_name[t]}",
              "gbs": bandwidth[f"triad/KiB:{kib}/threads:{t}"] / 1e9}
             for level, kib in levels.items() for t in (1, 2)]
    kernels = []
    for nodes in sorted({n for n, _ in rates}):
        if nodes not in (256, 1024):
            continue
        level = "L3 (24 MiB)" if nodes <= 256 else "DRAM"
        for t in (1, 2):
            if (nodes, t) not in rates:
                continue
            kernels.append({"name": f"Verlet step, {nodes}², {threads_name[t]}",
                            "flops_per_node_step": step_flops, "bytes_per_node_step": step_bytes,
                            "node_steps_per_second": rates[(nodes, t)],
                            "compute": f"FP64 FMA, {threads_name[t]}",
                            "bandwidth": f"{level}, {threads_name[t]}"})
    context = throughput.get("context", {})
    spec = {"title": "Verlet step on 1 and 2 threads, each against its cores' roofline",
            "note": f"{context.get('cpu', '')}; {context.get('compiler', '')}; rates: medians "
                    f"of {os.path.basename(throughput_path)} (git {context.get('git', '?')}, "
                    f"wall time); ceilings and counts: {os.path.basename(stem)} (best of 5; "
                    "bytes: cachegrind L2 fills + write-backs)",
            "compute": compute, "bandwidth": roofs, "kernels": kernels}
    with open(out + ".json", "w") as f:
        json.dump(spec, f, indent=1)
    plot(spec, out + ".png")

    peaks = {c["name"]: c["gflops"] for c in compute}
    bws = {b["name"]: b["gbs"] for b in roofs}
    print("| step | node-steps/s | GFLOP/s | bound (GFLOP/s, set by) | fraction of the bound |")
    print("|---|---|---|---|---|")
    for k in kernels:
        gflops = k["flops_per_node_step"] * k["node_steps_per_second"] / 1e9
        limit, name = bound(k, peaks, bws)
        print(f"| {k['name']} | {k['node_steps_per_second']:.3e} | {gflops:.1f} | "
              f"{limit:.1f}, {name} | {gflops / limit:.1%} |")


if __name__ == "__main__":
    main()
