// Throughput of one Verlet step of the Cosserat model on a flat N x N sheet with the S1 terms
// (gravity, damping: the step then also reduces the total area), on 1 and 2 threads.
// Reported as items per second = node-steps per second.

#include <benchmark/benchmark.h>
#include <mpi.h>
#include <omp.h>

#include "bench_sheet.hpp"
#include "cosserat/time/simulation.hpp"

namespace {

void verlet_step(benchmark::State& state) {
  const int nodes = static_cast<int>(state.range(0));
  omp_set_num_threads(static_cast<int>(state.range(1)));
  const cosserat::Scene scene = cosserat::bench::flat_sheet(nodes);
  cosserat::Simulation sim(scene, MPI_COMM_WORLD);
  for (auto _ : state) {
    if (sim.step()) state.SkipWithError("unstable");
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(nodes) * nodes);
  state.counters["threads"] = static_cast<double>(state.range(1));
  state.counters["ranks"] = 1;
}

BENCHMARK(verlet_step)
    ->ArgNames({"nodes", "threads"})
    ->ArgsProduct({{256, 1024, 2048}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

}  // namespace
