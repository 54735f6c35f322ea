// Bandwidth of this machine's memory levels (STREAM triad, a = b + s c), on 1 and 2 threads:
// the yardsticks for whether the force kernel is bound by memory. Three footprints of the
// three arrays together: 768 KiB lives in the L2 (2 MiB a core), 96 MiB in the shared L3
// (300 MiB), where a 1024² sheet's working set (~100 MB) lives too, and 1.5 GiB only in DRAM.
// Reported as bytes per second counting 24 B per element (no write-allocate traffic).

#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <vector>

namespace {

void triad(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0)) * 1024 / 24;
  omp_set_num_threads(static_cast<int>(state.range(1)));
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 3.0);
  // A cache-resident sweep takes microseconds, as long as a parallel region's start and end
  // barrier: each timed iteration sweeps enough times to move ~3 GB, with no barrier between
  // sweeps (each thread keeps its own static share of the arrays, in its own cache).
  const long sweeps = std::max(1L, 3'000'000'000L / static_cast<long>(24 * n));
  for (auto _ : state) {
#pragma omp parallel
    for (long s = 0; s < sweeps; ++s) {
#pragma omp for schedule(static) nowait
      for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + 1.5 * c[i];
      benchmark::ClobberMemory();
    }
  }
  state.SetBytesProcessed(state.iterations() * sweeps * static_cast<long>(n) * 24);
  state.counters["threads"] = static_cast<double>(state.range(1));
}

BENCHMARK(triad)
    ->ArgNames({"KiB", "threads"})
    ->ArgsProduct({{768, 96 * 1024, 1536 * 1024}, {1, 2}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
