// Throughput of one Verlet step of the Cosserat model on a flat N x N sheet with the S1 terms
// (gravity, damping: the step then also reduces the total area), on 1 and 2 threads.
// Reported as items per second = node-steps per second.

#include <benchmark/benchmark.h>
#include <mpi.h>
#include <omp.h>

#include "cosserat/time/simulation.hpp"

namespace {

cosserat::Scene flat_sheet(int nodes) {
  cosserat::Scene s;
  s.name = "bench";
  s.m = s.n = nodes;
  s.size1 = s.size2 = 10.0;
  s.material.mass = 10.0;
  s.material.zeta = {100.0, 100.0, 100.0};
  s.material.xi = {0.3, 0.3, 0.3};
  s.material.phi = {0.001, 0.001, 0.001};
  s.gravity = {0.0, -9.8, 0.0};
  s.damping = 0.2;
  s.integrator = cosserat::Integrator::verlet;
  // Below the bending-wave limit, which scales with h² (about 5e-6 s at 1024²), so the
  // sheet stays stable for as many steps as the benchmark takes.
  const double h = s.size1 / (nodes - 1);
  s.dt = 0.02 * h * h;
  s.steps = 1;
  s.output_every = 1;
  return s;
}

void verlet_step(benchmark::State& state) {
  const int nodes = static_cast<int>(state.range(0));
  omp_set_num_threads(static_cast<int>(state.range(1)));
  const cosserat::Scene scene = flat_sheet(nodes);
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

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  MPI_Finalize();
  return 0;
}
