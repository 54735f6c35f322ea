# Sourced by the benchmark scripts: builds TARGET with PRESET and sets what every result file
# records beside its numbers (date, host, cpu, compiler, git revision) and the stem
# benchmarks/results/NAME-<host>-<date> of the result files. Runs from the repository root.
#   source benchmarks/context.sh NAME PRESET TARGET
# CONTEXT_BUILD=0 skips the build (a script given a prebuilt binary, e.g. run_parity.sh).
if [ "${CONTEXT_BUILD:-1}" != 0 ]; then
  cmake --preset "$2" >/dev/null
  cmake --build --preset "$2" --target "$3" -j "$(nproc)" >/dev/null
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
date=$(date -u +%Y-%m-%d)
host=$(hostname -s)
stem=benchmarks/results/$1-$host-$date
cpu=$(lscpu | sed -n 's/^Model name: *//p' | head -1)
compiler=$(c++ --version | head -1)
revision=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
