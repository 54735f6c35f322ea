#!/usr/bin/env bash
# The Verlet step against this machine's roofline: the ceilings (bench_flops: peak FP64 FMA,
# sqrt, div; bench_bandwidth: triad in L2, L3, DRAM), the flops and bytes of a node-step
# (count_flops.py under valgrind, which cannot decode AVX-512, so on the same sources built for
# this CPU without it, in build/flopcount), the step's rate on 1024², 1 thread (bench_step),
# the force kernel's share of the step's time (time_share.py, perf), the memory per node
# (sheet_steps' resident set at 512² and 1024²), and the plot (roofline.py). Into
# benchmarks/results/roofline[-LABEL]-<host>-<date>.{json,md,png} and -{flops,bandwidth,
# counts,share,memory,roofline}.json, with the machine, compiler, git revision and date.
#   benchmarks/run_roofline.sh [LABEL]     (LABEL, e.g. "after", names a rerun on a new kernel)
# STEP_BYTES / KERNEL_BYTES replace cachegrind's bytes per node-step of the step / force kernel
# (e.g. with a count from the code).
set -euo pipefail
cd "$(dirname "$0")/.."
label=${1:-}
source benchmarks/context.sh "roofline${label:+-$label}" benchmark bench_step
cmake --build --preset benchmark --target bench_flops bench_bandwidth sheet_steps -j "$(nproc)" >/dev/null
cmake --preset benchmark -B build/flopcount -DCOSSERAT_NATIVE=OFF \
  "-DCMAKE_CXX_FLAGS=-march=native -mno-avx512f" >/dev/null
cmake --build build/flopcount --target sheet_steps -j "$(nproc)" >/dev/null

bench=build/benchmark/benchmarks
context=(--benchmark_context=cpu="$cpu" --benchmark_context=compiler="$compiler"
  --benchmark_context=preset=benchmark --benchmark_context=git="$revision")
# Five repetitions each: other work on the machine only ever slows a run, so the ceiling is the
# best of them; the median is kept beside it.
for ceiling in flops bandwidth; do
  OMP_PROC_BIND=close "$bench/bench_$ceiling" --benchmark_repetitions=5 \
    --benchmark_display_aggregates_only=true "${context[@]}" \
    --benchmark_out="$stem-$ceiling.json" --benchmark_out_format=json
done
run_step_benchmark "$bench/bench_step" --benchmark_filter='nodes:1024/threads:1'

/usr/bin/python3 benchmarks/count_flops.py build/flopcount/benchmarks/sheet_steps --nodes 256 \
  --steps 2 4 --cache --native-binary "$bench/sheet_steps" --json "$stem-counts.json"
/usr/bin/python3 benchmarks/time_share.py "$bench/sheet_steps" --nodes 1024 --steps 4 16 \
  --json "$stem-share.json"
for nodes in 512 1024; do OMP_NUM_THREADS=1 "$bench/sheet_steps" "$nodes" 2; done >"$stem-memory.json"

/usr/bin/python3 - "$stem" "$cpu" "$compiler" "$revision" "$date" "${label:-current}" \
  "${STEP_BYTES:-}" "${KERNEL_BYTES:-}" <<'PY'
import json, statistics, sys
stem, cpu, compiler, revision, date, label, step_bytes, kernel_bytes = sys.argv[1:]
load = lambda suffix: json.load(open(stem + suffix))

def runs(suffix, key):
    """{benchmark name: (best, median)} of a counter over the repetitions."""
    values = {}
    for b in load(suffix)["benchmarks"]:
        if b.get("run_type") == "iteration":
            values.setdefault(b["run_name"].rsplit("/", 1)[0], []).append(b[key])
    return {name: (max(v), statistics.median(v)) for name, v in values.items()}

flops = runs("-flops.json", "results_per_second")
bandwidth = runs("-bandwidth.json", "bytes_per_second")
# The step's rate by wall time (bench_step's own), and by its CPU time, as the ceilings are
# timed: the rate while the step has its core, which the plot shows.
step_run = [b for b in load(".json")["benchmarks"] if b.get("aggregate_name") == "median"][0]
wall_rate = step_run["items_per_second"]
seconds = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[step_run["time_unit"]]
step_rate = wall_rate * step_run["real_time"] / step_run["cpu_time"]
counts, share = load("-counts.json"), load("-share.json")
memory = [json.loads(line) for line in open(stem + "-memory.json")]
kernel_source = "cosserat_energy.cpp"
kernel_share = share["share"].get(kernel_source, 0.0)

def cache_bytes(r):
    # Fills of the simulated L2, plus one write-back per line a store brought in (cachegrind
    # does not simulate write-backs; lines read and then written are not counted).
    return r["l2_fill_bytes"] + r["l2_write_miss_bytes"]

step = {"flops": counts["total"]["flops"], "cache_bytes": cache_bytes(counts["cache"]["total"])}
kernel = {"flops": counts["by_source"][kernel_source]["flops"],
          "cache_bytes": cache_bytes(counts["cache"]["by_source"][kernel_source])}
step["bytes"] = float(step_bytes) if step_bytes else step["cache_bytes"]
kernel["bytes"] = float(kernel_bytes) if kernel_bytes else kernel["cache_bytes"]
gflops = lambda lanes, threads: 2 * flops[f"fma/lanes:{lanes}/threads:{threads}"][0] / 1e9
gbs = lambda kib, threads: bandwidth[f"triad/KiB:{kib}/threads:{threads}"][0] / 1e9
# The L3 as this guest sees it: 96 MiB already streams at DRAM's rate (bench_bandwidth.cpp).
levels = {"L2": 768, "L3": 24 * 1024, "DRAM": 1536 * 1024}
widths = {8: "zmm", 4: "ymm", 1: "scalar"}
# A 1024² step touches ~330 MB, more than the L3 this guest gets: its bound is DRAM's.
spec = {
    "title": f"Verlet step of the Cosserat sheet ({label}), 1 thread",
    "note": f"{cpu}; {compiler}, -O3 -march=native; git {revision}; {date}. Ceilings: best of 5; "
            "rates by CPU time; bytes: " + ("given" if step_bytes else "cachegrind L2 fills + write-backs"),
    "compute": [{"name": f"FP64 FMA {widths[lanes]}", "gflops": gflops(lanes, 1)}
                for lanes in widths if f"fma/lanes:{lanes}/threads:1" in flops],
    "bandwidth": [{"name": level, "gbs": gbs(kib, 1)} for level, kib in levels.items()],
    "kernels": [{"name": f"Verlet step, 1024² ({label})", "flops_per_node_step": step["flops"],
                 "bytes_per_node_step": step["bytes"], "node_steps_per_second": step_rate,
                 "bandwidth": "DRAM"}]}
if kernel_share > 0:
    spec["kernels"].append({"name": f"force kernel alone ({label}, {kernel_share:.0%} of the step)",
                            "flops_per_node_step": kernel["flops"], "bytes_per_node_step": kernel["bytes"],
                            "node_steps_per_second": step_rate / kernel_share, "bandwidth": "DRAM"})
json.dump(spec, open(stem + "-roofline.json", "w"), indent=1)

lines = [f"# Roofline of the Verlet step ({label}), {date}", "",
         f"Machine: {cpu}; compiler: {compiler}, -O3 -march=native (counts: -march=native "
         f"-mno-avx512f, which valgrind can run); git {revision}; 1 rank. "
         "`benchmarks/run_roofline.sh`; the other engineers' builds share the 2 cores, so rates vary.", "",
         "## Ceilings (best and median of 5)", "",
         "| operation | lanes | threads | best | median |", "|---|---|---|---|---|"]
for name, (best, median) in flops.items():
    op, lanes, threads = name.split("/")[:3]
    unit, scale = ("GFLOP/s", 2e-9) if op == "fma" else ("G results/s", 1e-9)
    lines.append(f"| {op} | {lanes.split(':')[1]} | {threads.split(':')[1]} | "
                 f"{best * scale:.2f} {unit} | {median * scale:.2f} {unit} |")
lines += ["", "| triad footprint | threads | best GB/s | median GB/s |", "|---|---|---|---|"]
for name, (best, median) in bandwidth.items():
    kib, threads = (part.split(":")[1] for part in name.split("/")[1:3])
    lines.append(f"| {int(kib) / 1024:g} MiB | {threads} | {best / 1e9:.1f} | {median / 1e9:.1f} |")
lines += ["", f"## Per node-step ({counts['nodes']}² sheet, steps {counts['steps'][0]} → "
          f"{counts['steps'][1]}, `count_flops.py`)", "",
          "| source | instructions | FP64 flops | FMA flops | add/sub | mul | div | sqrt | "
          "scalar / xmm / ymm / zmm FP64 instructions |", "|---|---|---|---|---|---|---|---|---|"]
for source, r in list(counts["by_source"].items()) + [("total", counts["total"])]:
    if abs(r["instructions"]) >= 0.5:
        lines.append(f"| {source} | {r['instructions']:.1f} | {r['flops']:.1f} | {r['fma_flops']:.1f} | "
                     f"{r['add_flops']:.1f} | {r['mul_flops']:.1f} | {r['div_results']:.2f} | "
                     f"{r['sqrt_results']:.2f} | {r['scalar_fp64_instructions']:.1f} / "
                     f"{r['xmm_fp64_instructions']:.1f} / {r['ymm_fp64_instructions']:.1f} / "
                     f"{r['zmm_fp64_instructions']:.1f} |")
c = counts["cache"]
lines += ["", f"Bytes per node-step, cachegrind (L1d {c['D1']}, L2 {c['L2']}; fills = misses × 64 B; "
          "write-backs estimated as one per write-missed line):", "",
          "| source | L2→L1 fills | L3→L2 fills | of which write misses | fills + write-backs |",
          "|---|---|---|---|---|"]
for source, r in list(c["by_source"].items()) + [("total", c["total"])]:
    if r["l1_fill_bytes"] >= 0.5:
        lines.append(f"| {source} | {r['l1_fill_bytes']:.1f} | {r['l2_fill_bytes']:.1f} | "
                     f"{r['l2_write_miss_bytes']:.1f} | {cache_bytes(r):.1f} |")
lines += ["", "Static FP64 arithmetic instructions by width in the -march=native binary:", "",
          "| source | scalar | xmm | ymm | zmm |", "|---|---|---|---|---|"]
for source in (kernel_source, "stepper.cpp", "verlet_family.cpp", "dynamics.cpp"):
    w = counts["native_static_widths"].get(source, {})
    lines.append(f"| {source} | " + " | ".join(str(w.get(k, 0)) for k in ("scalar", "xmm", "ymm", "zmm")) + " |")
lines += ["", "## Rates and memory", "",
          f"- bench_step 1024², 1 thread (median of 3): {wall_rate:.3e} node-steps/s by wall time, "
          f"{step_rate:.3e} by CPU time ({step_run['real_time'] * seconds * 1e3:.0f} ms wall, "
          f"{step_run['cpu_time'] * seconds * 1e3:.0f} ms CPU a step); the roofline uses the CPU-time rate",
          f"- force kernel's share of the step's time (perf cpu-clock, 1024²): {kernel_share:.1%}"
          f" → kernel alone {step_rate / kernel_share:.3e} node-steps/s" if kernel_share else "",
          f"- resident set: {memory[0]['rss_bytes'] / 2**20:.0f} MiB at {memory[0]['nodes']}², "
          f"{memory[1]['rss_bytes'] / 2**20:.0f} MiB at {memory[1]['nodes']}²: "
          f"{(memory[1]['rss_bytes'] - memory[0]['rss_bytes']) / (memory[1]['nodes']**2 - memory[0]['nodes']**2):.0f} B per node; "
          f"Simulation::memory_bytes: {memory[1]['memory_bytes'] / memory[1]['nodes']**2:.0f} B per node", "",
          "## Roofline (1 thread)", "", "Bound: min(peak FMA zmm, intensity × bandwidth).", "",
          "| point | flops/node-step | bytes/node-step | intensity | node-steps/s | GFLOP/s | "
          "fraction of the DRAM bound | of the L3 bound |", "|---|---|---|---|---|---|---|---|"]
peak = spec["compute"][0]["gflops"]
bw = {b["name"]: b["gbs"] for b in spec["bandwidth"]}
for k in spec["kernels"]:
    ai = k["flops_per_node_step"] / k["bytes_per_node_step"]
    achieved = k["flops_per_node_step"] * k["node_steps_per_second"] / 1e9
    fraction = lambda level: f"{achieved / min(peak, ai * bw[level]):.1%} of {min(peak, ai * bw[level]):.1f} GFLOP/s"
    lines.append(f"| {k['name']} | {k['flops_per_node_step']:.0f} | {k['bytes_per_node_step']:.0f} | "
                 f"{ai:.2f} | {k['node_steps_per_second']:.3e} | {achieved:.2f} | {fraction('DRAM')} | "
                 f"{fraction('L3')} |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
/usr/bin/python3 benchmarks/roofline.py "$stem-roofline.json" "$stem.png"
echo "wrote $stem.md, $stem.png"
