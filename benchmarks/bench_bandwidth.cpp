// Bandwidth of this machine's memory levels (STREAM triad, a = b + s c), on 1 and 2 threads:
// the yardsticks for whether the force kernel is bound by memory. Footprints of the three
// arrays together: 768 KiB lives in the L2 (2 MiB a core); 24 MiB in the L3; 96 MiB should
// too by the L3's size (300 MiB, shared with the host's other guests), but streams no faster
// than DRAM (measured 2026-11-27: 20.5 GiB/s from 3 to 48 MiB, 12.5 GiB/s at 96 MiB, 10.7 at
// 1.5 GiB, 1 thread); 1.5 GiB only in DRAM. A step of a 512² sheet touches ~83 MB, of a
// 1024² sheet ~330 MB (4 position-sized fields and the 216-byte gradients, ghosts included).
// Reported as bytes per second counting 24 B per element (no write-allocate traffic), over the
// longest CPU time of the threads (thread_time.hpp); on 2 threads that overstates the shared
// L3's and DRAM's bandwidth when another process keeps the threads from overlapping.

#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <vector>

#include "thread_time.hpp"

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
    double longest = 0.0;
#pragma omp parallel reduction(max : longest)
    {
      const double start = cosserat::bench::thread_seconds();
      for (long s = 0; s < sweeps; ++s) {
#pragma omp for schedule(static) nowait
        for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + 1.5 * c[i];
        benchmark::ClobberMemory();
      }
      longest = cosserat::bench::thread_seconds() - start;
    }
    state.SetIterationTime(longest);
  }
  state.SetBytesProcessed(state.iterations() * sweeps * static_cast<long>(n) * 24);
  state.counters["threads"] = static_cast<double>(state.range(1));
}

BENCHMARK(triad)
    ->ArgNames({"KiB", "threads"})
    ->ArgsProduct({{768, 24 * 1024, 96 * 1024, 1536 * 1024}, {1, 2}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
