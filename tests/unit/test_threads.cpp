// DESIGN.md principle 5: the same inputs give bitwise the same trajectory for any thread
// count (reductions run in a fixed order, each node's update is independent).

#include <gtest/gtest.h>
#include <omp.h>

#include "support/sheets.hpp"

namespace cosserat {
namespace {

std::vector<Vec3> run_with_threads(int threads, Integrator scheme) {
  omp_set_num_threads(threads);
  Scene scene = testing::flat_sheet(13, 11);
  scene.integrator = scheme;
  scene.gravity = {0.0, -9.8, 0.0};
  scene.damping = 0.2;
  scene.fluid = Fluid{0.032, {3.0, 0.0, 1.0}};
  scene.fixes.push_back(testing::fix_nodes({{0, 0}, {0, 10}}));
  Load load;
  load.nodes.nodes = {{12, 5}};
  load.force = {0.5, 0.0, 0.0};
  scene.loads.push_back(load);
  Simulation sim(scene, MPI_COMM_SELF);
  EXPECT_TRUE(testing::advance(sim, 300));
  std::vector<Vec3> out;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) out.push_back(sim.positions()(k, l));
  out.push_back(sim.diagnostics().center_of_mass);
  return out;
}

TEST(Threads, TrajectoryIsBitwiseTheSameForOneAndThreeThreads) {
  for (const Integrator scheme : {Integrator::verlet, Integrator::rk4}) {
    const auto one = run_with_threads(1, scheme);
    const auto three = run_with_threads(3, scheme);
    ASSERT_EQ(one.size(), three.size());
    for (std::size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ(one[i].x, three[i].x) << i;
      EXPECT_EQ(one[i].y, three[i].y) << i;
      EXPECT_EQ(one[i].z, three[i].z) << i;
    }
  }
  omp_set_num_threads(1);
}

}  // namespace
}  // namespace cosserat
