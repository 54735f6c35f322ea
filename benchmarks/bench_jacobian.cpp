// The exact Jacobian's own cost, without PETSc: node_hessian (∂²E_p/∂r², docs/semi-implicit.md,
// "The Jacobian") over every node of a bent N x N sheet, against one evaluation of the internal
// force on the same sheet, both per node, one thread. The semi-implicit step's Jacobian is these
// node Hessians plus their assembly into the PETSc matrix; the run summary's "Jacobian" time is
// both.

#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>

#include "bench_sheet.hpp"
#include "cosserat/model/cosserat_energy.hpp"
#include "cosserat/model/cosserat_model.hpp"
#include "cosserat/model/node_hessian.hpp"

namespace {

using namespace cosserat;

// The reference sheet rolled about x by up to a quarter turn and rippled, so that every strain
// and both curvatures are nonzero at every node.
struct BentSheet {
  Scene scene;
  Block block;
  Field<Vec3> r;
  CosseratEnergy energy;

  explicit BentSheet(int nodes)
      : scene(bench::flat_sheet(nodes)),
        block(Block::whole(nodes, nodes, MPI_COMM_SELF)),
        r(block),
        energy(block, scene.h1(), scene.h2(),
               flat_rest_state(scene.material, scene.u, scene.v)) {
    const double radius = 2.0 * scene.size2 / M_PI;
    for (int l = 0; l < nodes; ++l)
      for (int k = 0; k < nodes; ++k) {
        const double x = k * scene.h1(), s = l * scene.h2(), angle = s / radius;
        const double ripple = 0.01 * std::sin(3.0 * x) * std::cos(2.0 * s);
        r(k, l) = {1.001 * x, (radius + ripple) * std::sin(angle),
                   radius - (radius + ripple) * std::cos(angle)};
      }
  }
};

void node_hessians(benchmark::State& state) {
  const int nodes = static_cast<int>(state.range(0));
  omp_set_num_threads(1);
  const BentSheet sheet(nodes);
  NodeHessian h;
  for (auto _ : state) {
    for (int l = 0; l < nodes; ++l)
      for (int k = 0; k < nodes; ++k) {
        sheet.energy.node_hessian(sheet.r, k, l, h);
        benchmark::DoNotOptimize(h.entries.data());
      }
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(nodes) * nodes);
}

void internal_force(benchmark::State& state) {
  const int nodes = static_cast<int>(state.range(0));
  omp_set_num_threads(1);
  BentSheet sheet(nodes);
  Field<Vec3> force(sheet.block);
  for (auto _ : state) {
    sheet.energy.internal_force(sheet.r, force);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(nodes) * nodes);
}

BENCHMARK(node_hessians)->ArgName("nodes")->Arg(120)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(internal_force)->ArgName("nodes")->Arg(120)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace
