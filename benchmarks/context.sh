# Sourced by the benchmark scripts: builds TARGET with PRESET and sets what every result file
# records beside its numbers (date, host, cpu, compiler, git revision) and the stem
# benchmarks/results/NAME-<host>-<date> of the result files (-2, -3, ... after it for a later run
# the same day: a rerun never writes over a result); defines run_step_benchmark and claim_stem.
# Runs from the repository root.
#   source benchmarks/context.sh NAME PRESET TARGET
# CONTEXT_BUILD=0 skips the build (a script given a prebuilt binary, e.g. run_parity.sh).
if [ "${CONTEXT_BUILD:-1}" != 0 ]; then
  cmake --preset "$2" >/dev/null
  cmake --build --preset "$2" --target "$3" -j "$(nproc)" >/dev/null
fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
preset=$2
date=$(date -u +%Y-%m-%d)
host=$(hostname -s)
stem_base=benchmarks/results/$1-$host-$date
stem=$stem_base
cpu=$(lscpu | sed -n 's/^Model name: *//p' | head -1)
compiler=$(c++ --version | head -1)
revision=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)

# Moves $stem on to $stem-2, -3, ... until no result file starts with it. A script that names
# its files from a variant of the stem (e.g. a quick run's) sets stem from $stem_base and calls
# this again.
claim_stem() {
  local base=$stem i=2
  while compgen -G "$stem.*" >/dev/null || compgen -G "$stem-*" >/dev/null; do
    stem=$base-$i
    i=$((i + 1))
  done
}
claim_stem

# Google Benchmark 1.7 drops a --benchmark_context value holding a second '=' (and a program
# whose main checks its flags stops), so the flags are named by their preset in
# CMakePresets.json rather than spelled out.
# Runs one of the step benchmarks on one rank (OMP_PROC_BIND=close), median of 3 repetitions of
# at least 2 s each, with the context above in its JSON output, $stem.json.
#   run_step_benchmark BINARY [extra Google Benchmark flags]
run_step_benchmark() {
  local binary=$1
  shift
  OMP_PROC_BIND=close "$binary" --benchmark_min_time=2 --benchmark_repetitions=3 \
    --benchmark_report_aggregates_only=true \
    --benchmark_context=cpu="$cpu" --benchmark_context=compiler="$compiler" \
    --benchmark_context=preset="$preset" --benchmark_context=git="$revision" \
    --benchmark_context=ranks=1 \
    --benchmark_out="$stem.json" --benchmark_out_format=json "$@"
}
