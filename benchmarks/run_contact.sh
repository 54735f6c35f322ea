#!/usr/bin/env bash
# Node-steps per second of one Verlet step at 1024² with no solid, one plane, one sphere and
# ten solids (bench_contact), on 1 and 2 threads, into
# benchmarks/results/contact-<host>-<date>.{json,md} with the machine, compiler, git revision,
# ranks x threads and date beside every number.
#   benchmarks/run_contact.sh [extra Google Benchmark flags]
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh contact benchmark bench_contact

run_step_benchmark build/benchmark/benchmarks/bench_contact "$@"

/usr/bin/python3 - "$stem" "$cpu" "$compiler" "$revision" "$date" <<'PY'
import json, sys
stem, cpu, compiler, revision, date = sys.argv[1:]
runs = [b for b in json.load(open(stem + ".json"))["benchmarks"] if b.get("aggregate_name") == "median"]
names = {0: "no solid", 1: "one plane (every node in contact)", 2: "one sphere (radius 5 m)", 3: "ten solids"}
rows = {}
for b in runs:
    fields = dict(part.split(":") for part in b["name"].split("/")[1:] if ":" in part)
    rows[(int(fields["case"]), int(fields["threads"]))] = b
lines = [f"# Verlet step with solids at 1024², {date}", "",
         f"Machine: {cpu}; compiler: {compiler}, -O3 -march=native; git {revision}; 1 rank.",
         "Median of 3 repetitions of at least 2 s each (`benchmarks/run_contact.sh`).",
         "Contact cost per node-step: 1/rate − 1/rate(no solid).", "",
         "| solids | threads | nodes in contact | node-steps/s | contact cost (ns per node-step) |",
         "|---|---|---|---|---|"]
for (case, threads), b in sorted(rows.items()):
    rate = b["items_per_second"]
    base = rows[(0, threads)]["items_per_second"]
    cost = (1.0 / rate - 1.0 / base) * 1e9
    lines.append(f"| {names[case]} | {threads} | {int(b.get('contacts', 0))} | {rate:.3e} | {cost:.1f} |")
open(stem + ".md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
