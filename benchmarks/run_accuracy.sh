#!/usr/bin/env bash
# The integrator study of issue 4 (docs/integrator-study.md): largest stable Δt of S1-S6 and the
# hard cases per scheme beside the CFL estimate, speed against error on S1, S2 and a 120 x 120
# hanging sheet, and time to rest on S1, S2, S3, S5. Writes
# benchmarks/results/accuracy-<host>-<date>{-stability,-accuracy,-rest}.csv, the plots
# (-work-precision.png, -error-vs-dt.png), the summary (.md) and the log of every run (.log).
# About four hours on two cores (docs/integrator-study.md); --quick checks the pipeline in a
# few minutes. A part, some cases or some schemes at a time merge into the files already there:
#   benchmarks/run_accuracy.sh [--quick] [--parts stability,accuracy,rest] [--cases "S1,S6 xi=0"]
#       [--schemes verlet,rk4] [--accuracy-scenes S1,S2,hanging] [--timeout SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
source benchmarks/context.sh accuracy release cosserat
# The day's files themselves, not a fresh stem: the parts merge into them (above).
stem=$stem_base
case " $* " in *" --quick "*) stem=$stem-quick ;; esac

/usr/bin/python3 tools/accuracy_study.py --exe build/release/cosserat --out "$stem" "$@"
/usr/bin/python3 tools/accuracy_report.py "$stem" --machine "$cpu, $(nproc) cores, $host" \
  --build "$compiler, release (-O3), git $revision" --date "$date"
