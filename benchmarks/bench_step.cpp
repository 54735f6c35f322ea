// Throughput of one Verlet step of the Cosserat model on a flat N x N sheet with the S1 terms
// (gravity, damping: the step then also reduces the total area), on 1 and 2 threads, and on
// 4, 8, ... threads up to the machine's CPUs where it has more.
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

void thread_counts(benchmark::internal::Benchmark* b) {
  for (const long nodes : {256, 1024, 2048, 4096})
    for (long threads = 1; threads == 1 || threads <= omp_get_num_procs(); threads *= 2)
      b->Args({nodes, threads});
}

BENCHMARK(verlet_step)
    ->ArgNames({"nodes", "threads"})
    ->Apply(thread_counts)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

// Model only what a scene needs: the same step with each term of the flat sheet present or
// absent, one bit of `terms` each (1 curvature ξ, 2 coupling φ, 4 damping, 8 fluid, 16 a point
// load on every 64th node), on one thread at 1024². An absent term should cost nothing.
void verlet_step_terms(benchmark::State& state) {
  const int nodes = 1024;
  const long terms = state.range(0);
  omp_set_num_threads(1);
  cosserat::Scene scene = cosserat::bench::flat_sheet(nodes);
  if (!(terms & 1)) scene.material.xi = {0.0, 0.0, 0.0};
  if (!(terms & 2)) scene.material.phi = {0.0, 0.0, 0.0};
  if (!(terms & 4)) scene.damping = 0.0;
  if (terms & 8) scene.fluid = cosserat::Fluid{0.05, {1.0, 0.0, 0.5}, {}};
  if (terms & 16) {
    cosserat::Load load;
    for (int l = 0; l < nodes; l += 8)
      for (int k = 0; k < nodes; k += 8) load.nodes.nodes.push_back({k, l});
    load.force = {0.0, 1e-6, 0.0};
    scene.loads.push_back(load);
  }
  cosserat::Simulation sim(scene, MPI_COMM_WORLD);
  for (auto _ : state) {
    if (sim.step()) state.SkipWithError("unstable");
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(nodes) * nodes);
  state.counters["threads"] = 1;
  state.counters["ranks"] = 1;
}

BENCHMARK(verlet_step_terms)
    ->ArgName("terms")
    ->Args({0})
    ->Args({1})
    ->Args({3})
    ->Args({7})
    ->Args({4})
    ->Args({8})
    ->Args({16})
    ->Args({31})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

}  // namespace
