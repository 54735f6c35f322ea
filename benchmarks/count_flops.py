#!/usr/bin/python3
"""Flops and bytes of one Verlet step per node, counted dynamically.

Runs sheet_steps (N Verlet steps of the benchmark sheet) under callgrind at two step counts
and subtracts, so MPI_Init and the setup cancel and what is left is exactly the steps between.
Each executed instruction's count is matched with its mnemonic from objdump, and the FP64
arithmetic is counted as Intel's FP_ARITH_INST_RETIRED counts it: add, sub, mul, div, sqrt,
min, max, rcp14, rsqrt14 once per lane, FMA and dppd twice; scalar 1 lane, xmm 2, ymm 4,
zmm 8; compares, moves, logic and conversions not at all. Masked AVX-512 instructions are
counted on all lanes (an upper bound). Costs are split by the source file whose object defines
each function (the force kernel is cosserat_energy.cpp), and by function.

With --cache, also runs cachegrind at two step counts with a simulated L1 and L2 of this
machine's sizes; the L2 misses times the line size are the bytes a step pulls from the L3 (no
hardware prefetch; dirty write-backs are not simulated and not included).

valgrind (3.19 here, and every release so far) cannot decode AVX-512 (EVEX) instructions: the
binary must be built without them, e.g. -march=native -mno-avx512f (run_roofline.sh builds
build/flopcount so). --native-binary then disassembles the real -march=native build and
reports, statically, the vector widths of its FP64 arithmetic by source file.

  /usr/bin/python3 benchmarks/count_flops.py build/flopcount/benchmarks/sheet_steps \\
      [--nodes 256] [--steps 2 4] [--cache] [--native-binary build/benchmark/benchmarks/sheet_steps] \\
      [--json out.json]
"""

import argparse
import bisect
import collections
import glob
import json
import os
import re
import subprocess
import sys
import tempfile

# Prefixes objdump prints before a mnemonic.
PREFIXES = {"lock", "rep", "repz", "repnz", "repe", "repne", "notrack", "bnd", "data16",
            "cs", "ds", "es", "ss", "fs", "gs", "addr32", "rex", "rex.W", "{vex}", "{evex}"}

FMA = re.compile(r"^vf(n?m)(add|sub)(132|213|231)(s|p)([sd])$")
FMA_ALTERNATING = re.compile(r"^vf(maddsub|msubadd)(132|213|231)p([sd])$")
ARITHMETIC = re.compile(r"^v?(add|sub|mul|div|sqrt|min|max|hadd|hsub|addsub)(s|p)([sd])$")
APPROXIMATE = re.compile(r"^v(rcp14|rsqrt14)(s|p)([sd])$")
DOT = re.compile(r"^v?dpp([sd])$")
# The op classes reported.
OPS = ("add", "mul", "fma", "div", "sqrt", "minmax", "approx", "dot")
WIDTHS = ("scalar", "xmm", "ymm", "zmm")


def classify(mnemonic, operands):
    """(op, precision, width, lanes, flops per instruction) of an FP arithmetic instruction,
    or None."""
    m = FMA.match(mnemonic)
    if m:
        op, kind, precision, per_lane = "fma", m.group(4), m.group(5), 2
    elif FMA_ALTERNATING.match(mnemonic):
        m = FMA_ALTERNATING.match(mnemonic)
        op, kind, precision, per_lane = "fma", "p", m.group(3), 2
    elif ARITHMETIC.match(mnemonic):
        m = ARITHMETIC.match(mnemonic)
        base, kind, precision = m.group(1), m.group(2), m.group(3)
        op = {"add": "add", "sub": "add", "hadd": "add", "hsub": "add", "addsub": "add",
              "mul": "mul", "div": "div", "sqrt": "sqrt", "min": "minmax", "max": "minmax"}[base]
        per_lane = 1
    elif APPROXIMATE.match(mnemonic):
        m = APPROXIMATE.match(mnemonic)
        op, kind, precision, per_lane = "approx", m.group(2), m.group(3), 1
    elif DOT.match(mnemonic):
        op, kind, precision, per_lane = "dot", "p", DOT.match(mnemonic).group(1), 2
    else:
        return None
    element = 8 if precision == "d" else 4
    if kind == "s":
        width, lanes = "scalar", 1
    else:
        width = "zmm" if "%zmm" in operands else "ymm" if "%ymm" in operands else "xmm"
        lanes = {"xmm": 16, "ymm": 32, "zmm": 64}[width] // element
    return op, "fp64" if precision == "d" else "fp32", width, lanes, per_lane * lanes


def disassemble(binary):
    """{address: (mnemonic, operands)} of every instruction, and {address: symbol} of every
    function start."""
    out = subprocess.run(["objdump", "-d", "-w", "--no-show-raw-insn", binary],
                         check=True, capture_output=True, text=True).stdout
    instructions, symbols = {}, {}
    line_re = re.compile(r"^\s*([0-9a-f]+):\s+(.*)$")
    symbol_re = re.compile(r"^([0-9a-f]+) <(.*)>:$")
    for line in out.splitlines():
        m = line_re.match(line)
        if m:
            words = m.group(2).split()
            while words and words[0] in PREFIXES:
                words = words[1:]
            if words:
                instructions[int(m.group(1), 16)] = (words[0], " ".join(words[1:]))
            continue
        m = symbol_re.match(line)
        if m:
            symbols[int(m.group(1), 16)] = m.group(2)
    return instructions, symbols


def symbol_sources(build_dir):
    """{mangled function name: source file} from the object files of a CMake build; names
    defined in several objects (inline functions, templates) map to 'inline/template'."""
    sources = collections.defaultdict(set)
    objects = glob.glob(os.path.join(build_dir, "**", "*.o"), recursive=True)
    for obj in objects:
        source = os.path.basename(obj)[:-2]
        out = subprocess.run(["nm", "--defined-only", obj], capture_output=True, text=True).stdout
        for line in out.splitlines():
            parts = line.split()
            if len(parts) == 3 and parts[1] in "TtWw":
                sources[parts[2]].add(source)
    return {name: next(iter(s)) if len(s) == 1 else "inline/template" for name, s in sources.items()}


def demangle(names):
    names = list(names)
    out = subprocess.run(["c++filt"], input="\n".join(names), capture_output=True, text=True,
                         check=True).stdout.splitlines()
    return dict(zip(names, out))


def run_tool(tool, binary, nodes, steps, workdir, extra):
    """Runs one valgrind tool on sheet_steps; returns the output file of the main process and
    what sheet_steps printed."""
    stem = os.path.join(workdir, f"{tool}.{steps}")
    env = dict(os.environ, OMP_NUM_THREADS="1")
    result = subprocess.run(
        ["valgrind", f"--tool={tool}", f"--{tool}-out-file={stem}.%p", *extra,
         binary, str(nodes), str(steps)],
        env=env, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"{tool} run of {binary} failed:\n{result.stderr[-3000:]}")
    # MPI's singleton start may fork helpers under valgrind too: the run's file is the one
    # that saw the binary itself.
    files = [f for f in glob.glob(stem + ".*") if binary_named_in(f, binary)]
    if len(files) != 1:
        sys.exit(f"expected one {tool} output for {binary}, found {files}")
    report = json.loads(result.stdout.strip().splitlines()[-1])
    return files[0], report


def binary_named_in(path, binary):
    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith("cmd:"):
                return os.path.realpath(binary) in line or binary in line
    return False


def parse_callgrind(path):
    """{(object, function): {address: Ir}} of a callgrind --dump-instr=yes file."""
    # Compressed names, "(id) name" at first use and "(id)" after, one table per kind.
    table_of = {"ob": "ob", "cob": "ob", "fn": "fn", "cfn": "fn", "jfn": "fn",
                "fl": "fl", "fi": "fl", "fe": "fl", "cfi": "fl", "cfl": "fl", "jfi": "fl"}
    names = {"ob": {}, "fn": {}, "fl": {}}
    costs = collections.defaultdict(lambda: collections.defaultdict(int))
    obj = fn = None
    positions = 1
    last = [0, 0]
    in_call = False
    with open(path) as f:
        for line in f:
            if not line.strip() or line[0] == "#":
                continue
            c = line[0]
            if c.isdigit() or c in "+-*":
                words = line.split()
                for i in range(positions):
                    w = words[i]
                    if w[0] == "+":
                        last[i] += int(w[1:])
                    elif w[0] == "-":
                        last[i] -= int(w[1:])
                    elif w[0] != "*":
                        last[i] = int(w, 0)
                if in_call:
                    # The inclusive cost of a call, already counted in the callee.
                    in_call = False
                    continue
                costs[(obj, fn)][last[0]] += int(words[positions]) if len(words) > positions else 0
                continue
            key, _, value = line.rstrip("\n").partition("=")
            if key in table_of:
                table = names[table_of[key]]
                m = re.match(r"^\((\d+)\)\s*(.*)$", value)
                if m:
                    if m.group(2):
                        table[m.group(1)] = m.group(2)
                    value = table[m.group(1)]
                if key == "ob":
                    obj = value
                elif key == "fn":
                    fn = value
            elif key == "calls":
                in_call = True
            elif line.startswith("positions:"):
                positions = len(line.split()[1:])
                last = [0] * positions
    return costs


def parse_cachegrind(path):
    """{function: {event: count}} of a cachegrind file."""
    totals = collections.defaultdict(lambda: collections.defaultdict(int))
    events, fn = [], None
    with open(path) as f:
        for line in f:
            if line.startswith("events:"):
                events = line.split()[1:]
            elif line.startswith("fn="):
                fn = line[3:].strip()
            elif line[:1].isdigit():
                words = line.split()
                for e, v in zip(events, words[1:]):
                    totals[fn][e] += int(v)
    return totals


def empty_tally():
    return {"instructions": 0, "fp64_instructions": 0, "flops": 0, "fp32_flops": 0,
            **{f"{op}_flops": 0 for op in OPS},
            "div_results": 0, "sqrt_results": 0, "fma_instructions": 0,
            **{f"{w}_fp64_instructions": 0 for w in WIDTHS}}


def add_instruction(tally, count, kind):
    tally["instructions"] += count
    if kind is None:
        return
    op, precision, width, lanes, flops = kind
    if precision == "fp32":
        tally["fp32_flops"] += count * flops
        return
    tally["fp64_instructions"] += count
    tally[f"{width}_fp64_instructions"] += count
    tally["flops"] += count * flops
    tally[f"{op}_flops"] += count * flops
    if op in ("div", "sqrt"):
        tally[f"{op}_results"] += count * lanes
    if op == "fma":
        tally["fma_instructions"] += count


def per_node_step(tally, node_steps):
    return {k: v / node_steps for k, v in tally.items()}


def count(binary, nodes, steps, sources, workdir):
    instructions, _ = disassemble(binary)
    runs = [run_tool("callgrind", binary, nodes, s, workdir, ["--dump-instr=yes", "--demangle=no"])
            for s in steps]
    costs = [parse_callgrind(path) for path, _ in runs]
    node_steps = nodes * nodes * (steps[1] - steps[0])
    main_object = os.path.realpath(binary)
    by_source = collections.defaultdict(empty_tally)
    by_function = collections.defaultdict(empty_tally)
    total = empty_tally()
    unmatched = 0
    for key in set(costs[0]) | set(costs[1]):
        obj, fn = key
        in_main = obj is not None and os.path.realpath(obj) == main_object
        source = sources.get(fn, "other") if in_main else os.path.basename(obj or "?")
        addresses = set(costs[0].get(key, {})) | set(costs[1].get(key, {}))
        for address in addresses:
            n = costs[1].get(key, {}).get(address, 0) - costs[0].get(key, {}).get(address, 0)
            if n == 0:
                continue
            kind = None
            if in_main:
                if address not in instructions:
                    unmatched += abs(n)
                else:
                    kind = classify(*instructions[address])
            for tally in (by_source[source], by_function[(source, fn)], total):
                add_instruction(tally, n, kind)
    if unmatched > 1e-3 * total["instructions"]:
        sys.exit(f"{unmatched} executed instructions of {binary} not found in its disassembly")
    names = demangle(fn for _, fn in by_function)
    functions = sorted(by_function.items(), key=lambda item: -item[1]["instructions"])
    return {
        "binary": binary, "nodes": nodes, "steps": steps, "node_steps": node_steps,
        "total": per_node_step(total, node_steps),
        "by_source": {s: per_node_step(t, node_steps) for s, t in
                      sorted(by_source.items(), key=lambda item: -item[1]["instructions"])},
        "by_function": [{"function": names[fn], "source": source, **per_node_step(t, node_steps)}
                        for (source, fn), t in functions if t["instructions"] > 0.001 * node_steps],
    }


def cache_traffic(binary, nodes, steps, sources, workdir, d1, l2):
    extra = ["--cache-sim=yes", f"--D1={d1}", f"--LL={l2}", "--I1=32768,8,64", "--demangle=no"]
    runs = [run_tool("cachegrind", binary, nodes, s, workdir, extra) for s in steps]
    totals = [parse_cachegrind(path) for path, _ in runs]
    node_steps = nodes * nodes * (steps[1] - steps[0])
    line = int(l2.split(",")[2])
    by_source = collections.defaultdict(lambda: collections.defaultdict(int))
    for fn in set(totals[0]) | set(totals[1]):
        source = sources.get(fn, "other")
        for e in ("Dr", "Dw", "D1mr", "D1mw", "DLmr", "DLmw"):
            by_source[source][e] += totals[1].get(fn, {}).get(e, 0) - totals[0].get(fn, {}).get(e, 0)

    def bytes_of(t):
        return {"l1_fill_bytes": line * (t["D1mr"] + t["D1mw"]) / node_steps,
                "l2_fill_bytes": line * (t["DLmr"] + t["DLmw"]) / node_steps,
                "l2_read_miss_bytes": line * t["DLmr"] / node_steps,
                "l2_write_miss_bytes": line * t["DLmw"] / node_steps,
                "loads": t["Dr"] / node_steps, "stores": t["Dw"] / node_steps}

    total = collections.defaultdict(int)
    for t in by_source.values():
        for e, v in t.items():
            total[e] += v
    return {"nodes": nodes, "steps": steps, "D1": d1, "L2": l2, "total": bytes_of(total),
            "by_source": {s: bytes_of(t) for s, t in
                          sorted(by_source.items(), key=lambda item: -item[1]["DLmr"])}}


def static_widths(binary, sources):
    """Static count of FP64 arithmetic instructions by width in each source file's functions."""
    instructions, symbols = disassemble(binary)
    starts = sorted(symbols)
    widths = collections.defaultdict(collections.Counter)
    for address, (mnemonic, operands) in instructions.items():
        kind = classify(mnemonic, operands)
        if kind and kind[1] == "fp64":
            function = symbols[starts[bisect.bisect_right(starts, address) - 1]]
            widths[sources.get(function, "other")][kind[2]] += 1
    return {s: dict(c) for s, c in widths.items()}


def report(result):
    t = result["total"]
    print(f"{result['binary']}: {result['nodes']}² sheet, steps {result['steps'][0]} → "
          f"{result['steps'][1]}, per node-step:")
    header = f"{'':28} {'instr':>8} {'flops':>7} {'fma fl':>7} {'add':>6} {'mul':>6} " \
             f"{'div':>5} {'sqrt':>5} {'scalar':>7} {'xmm':>6} {'ymm':>6} {'zmm':>6}"
    print(header)

    def row(name, r):
        print(f"{name[:28]:28} {r['instructions']:8.1f} {r['flops']:7.1f} {r['fma_flops']:7.1f} "
              f"{r['add_flops']:6.1f} {r['mul_flops']:6.1f} {r['div_results']:5.2f} "
              f"{r['sqrt_results']:5.2f} {r['scalar_fp64_instructions']:7.1f} "
              f"{r['xmm_fp64_instructions']:6.1f} {r['ymm_fp64_instructions']:6.1f} "
              f"{r['zmm_fp64_instructions']:6.1f}")

    for source, r in result["by_source"].items():
        if abs(r["instructions"]) >= 0.5:
            row(source, r)
    row("total", t)
    print("\nfunctions (instructions per node-step):")
    for f in result["by_function"][:12]:
        print(f"  {f['instructions']:8.1f} instr {f['flops']:7.1f} flops  {f['source']}: "
              f"{f['function'][:100]}")
    if "cache" in result:
        c = result["cache"]
        print(f"\ncachegrind, {c['nodes']}² sheet, D1 {c['D1']}, L2 {c['L2']}, bytes per node-step:")
        for source, r in list(c["by_source"].items()) + [("total", c["total"])]:
            if r["l1_fill_bytes"] >= 0.5 or source == "total":
                print(f"  {source[:28]:28} L2→L1 fills {r['l1_fill_bytes']:7.1f}  "
                      f"L3→L2 fills {r['l2_fill_bytes']:7.1f} (read misses "
                      f"{r['l2_read_miss_bytes']:.1f}, write misses {r['l2_write_miss_bytes']:.1f})")
    if "native_static_widths" in result:
        print(f"\nstatic FP64 arithmetic instructions by width in {result['native_binary']}:")
        for source, c in sorted(result["native_static_widths"].items(), key=lambda i: -sum(i[1].values())):
            print(f"  {source[:28]:28} " + "  ".join(f"{w} {c.get(w, 0)}" for w in WIDTHS))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("binary", help="sheet_steps built without AVX-512 (valgrind runs it)")
    parser.add_argument("--nodes", type=int, default=256, help="sheet of NODES² (default 256)")
    parser.add_argument("--steps", type=int, nargs=2, default=[2, 4], metavar=("FEW", "MORE"),
                        help="the two step counts whose difference is measured (default 2 4)")
    parser.add_argument("--build-dir", help="CMake build holding the binary's object files "
                        "(default: two levels above the binary)")
    parser.add_argument("--cache", action="store_true", help="also simulate the caches (cachegrind)")
    parser.add_argument("--d1", default="49152,12,64", help="simulated L1d: size,assoc,line")
    parser.add_argument("--l2", default="2097152,16,64", help="simulated L2 (cachegrind's LL)")
    parser.add_argument("--native-binary", help="the -march=native build, for static vector widths")
    parser.add_argument("--json", help="write the counts here")
    args = parser.parse_args()
    if args.steps[1] <= args.steps[0]:
        parser.error("--steps: the second count must be larger")
    build_dir = args.build_dir or os.path.dirname(os.path.dirname(os.path.abspath(args.binary)))
    sources = symbol_sources(build_dir)
    with tempfile.TemporaryDirectory(prefix="count_flops.") as workdir:
        result = count(args.binary, args.nodes, args.steps, sources, workdir)
        if args.cache:
            result["cache"] = cache_traffic(args.binary, args.nodes, args.steps, sources, workdir,
                                            args.d1, args.l2)
    if args.native_binary:
        native_dir = os.path.dirname(os.path.dirname(os.path.abspath(args.native_binary)))
        result["native_binary"] = args.native_binary
        result["native_static_widths"] = static_widths(args.native_binary, symbol_sources(native_dir))
    report(result)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
