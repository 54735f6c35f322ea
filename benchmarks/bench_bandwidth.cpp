// Memory bandwidth of this machine (STREAM triad, a = b + s c, arrays far larger than the
// caches), on 1 and 2 threads: the yardstick for whether the force kernel is bound by memory.
// Reported as bytes per second counting 24 B per element (no write-allocate traffic).

#include <benchmark/benchmark.h>
#include <omp.h>

#include <vector>

namespace {

void triad(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  const std::size_t n = std::size_t{1} << 26;  // 512 MiB per array
  std::vector<double> a(n, 1.0), b(n, 2.0), c(n, 3.0);
  for (auto _ : state) {
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + 1.5 * c[i];
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * static_cast<long>(n) * 24);
}

BENCHMARK(triad)->ArgName("threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
