#!/usr/bin/env bash
# Parity of the energy form (model.discretisation = "energy", docs/equations.md §2.5) with the
# flux form (issue 11, item 6, and item 1's node-steps/s): the largest stable Verlet Δt of S1-S6
# per form, a refinement study of an S1-like sheet on nested grids (10, 19, 37, 73, 145 nodes a
# side; S1's corner supports, edge segments of fixed length, and those undamped) with the
# distance between the forms and each form's self-convergence, and node-steps/s of both forms on
# a 1024 x 1024 sheet with 1 and 2 threads. Writes
# benchmarks/results/parity-<host>-<date>{.md,-stability.csv,-refinement.csv,
# -refinement-runs.csv,-throughput.csv,-refinement.png,.log}. About 17 min on the 2-core VM
# (measured under load 4-9); --parts stability,refinement,throughput runs a part (its CSV is
# replaced, the report redone). The binary: $COSSERAT if set (no build), else the release build
# made here.
#   [COSSERAT=path/to/cosserat] benchmarks/run_parity.sh [tools/parity_study.py options]
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "${COSSERAT:-}" ]; then
  COSSERAT=$(realpath "$COSSERAT")
  CONTEXT_BUILD=0 source benchmarks/context.sh parity release cosserat
  # The compiler that built the given binary, from its .comment section.
  compiler=$(readelf -p .comment "$COSSERAT" 2>/dev/null | sed -n 's/^ *\[ *[0-9a-f]*\] *//p' \
    | head -1)
  compiler=${compiler:-unknown}
  binary="\`$COSSERAT\` as given (sha256 $(sha256sum "$COSSERAT" | cut -c1-12), $("$COSSERAT" --version))"
else
  source benchmarks/context.sh parity release cosserat
  COSSERAT=build/release/cosserat
  binary="\`build/release/cosserat\`, built from this checkout"
fi
dirty=$(git status --porcelain --untracked-files=no 2>/dev/null | grep -q . && echo ", modified" || true)
start=$(date +%s)
context=$(/usr/bin/python3 -c 'import json, sys; print(json.dumps(dict(zip(
  ["machine", "build", "layout", "date", "binary"], sys.argv[1:]))))' \
  "$cpu, $(nproc) cores, $host" "$compiler, release (-O3); checkout at git $revision$dirty" \
  "1 rank × 1 thread per run, two runs side by side (stability, refinement); 1 rank × 1 and 2 threads, one run at a time (throughput)" \
  "$date" "$binary")
/usr/bin/python3 tools/parity_study.py --exe "$COSSERAT" --out "$stem" --context "$context" "$@"
echo "run_parity.sh: $(( ($(date +%s) - start) / 60 )) min $(( ($(date +%s) - start) % 60 )) s"
