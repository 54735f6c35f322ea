#!/usr/bin/env bash
# Speed against total error, space and time together (issue 28, item 4;
# docs/integrator-study.md, "Total error: space and time"): for both energy quadratures
# (model.discretisation = "energy", trapezoidal, and "energy-nodal"), the wall time to reach
# 1e-2, 1e-3 and 1e-4 m of total error on (a) an edge-hung sheet against its exact 1-D rest
# state and (b) an S1-like sheet with segment supports at T = 2 s against the finest
# trapezoidal grid. Writes benchmarks/results/total-error-<host>-<date>{.md,.csv,
# -work-precision.png,.log}. One cosserat process at a time, 1 thread: about 20 min on the
# 2-core VM with another job on the other core; --quick checks the pipeline in a minute,
# --parts hung or --parts s1 redoes one problem (its rows are replaced, the report redone).
# The binary: $COSSERAT if set (no build), else the release build made here.
#   [COSSERAT=path/to/cosserat] benchmarks/run_total_error.sh [tools/total_error_study.py options]
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "${COSSERAT:-}" ]; then
  COSSERAT=$(realpath "$COSSERAT")
  CONTEXT_BUILD=0 source benchmarks/context.sh total-error release cosserat
  # The compiler that built the given binary, from its .comment section.
  compiler=$(readelf -p .comment "$COSSERAT" 2>/dev/null | sed -n 's/^ *\[ *[0-9a-f]*\] *//p' \
    | head -1)
  compiler=${compiler:-unknown}
  binary="\`$COSSERAT\` as given (sha256 $(sha256sum "$COSSERAT" | cut -c1-12), $("$COSSERAT" --version))"
else
  source benchmarks/context.sh total-error release cosserat
  COSSERAT=build/release/cosserat
  binary="\`build/release/cosserat\`, built from this checkout"
fi
case " $* " in *" --quick "*) stem=$stem-quick ;; esac
dirty=$(git status --porcelain --untracked-files=no 2>/dev/null | grep -q . && echo ", modified" || true)
start=$(date +%s)
context=$(/usr/bin/python3 -c 'import json, sys; print(json.dumps(dict(zip(
  ["machine", "build", "date", "binary"], sys.argv[1:]))))' \
  "$cpu, $(nproc) cores, $host" "$compiler, release (-O3); checkout at git $revision$dirty" \
  "$date" "$binary")
OMP_NUM_THREADS=1 /usr/bin/python3 tools/total_error_study.py --exe "$COSSERAT" --out "$stem" \
  --context "$context" "$@"
echo "run_total_error.sh: $(( ($(date +%s) - start) / 60 )) min $(( ($(date +%s) - start) % 60 )) s"
