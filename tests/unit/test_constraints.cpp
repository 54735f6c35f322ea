// Fixed nodes, axis masks, step windows and point loads (MODEL.md §1 and §4.1).

#include <gtest/gtest.h>

#include "support/sheets.hpp"

namespace cosserat {
namespace {

using testing::flat_sheet;

// A load of F newtons on every node of a free, weightless sheet moves it rigidly with the
// acceleration F/(μ h1 h2) = F (m−1)(n−1)/M of MODEL.md §1: loads are newtons on the node's
// lumped mass, whatever the resolution.
TEST(Loads, NewtonsOnTheLumpedMass) {
  for (const Integrator scheme : {Integrator::verlet, Integrator::rk4}) {
    Scene scene = flat_sheet(9, 6);
    scene.integrator = scheme;
    Load load;
    for (int l = 0; l < scene.n; ++l)
      for (int k = 0; k < scene.m; ++k) load.nodes.nodes.push_back({k, l});
    load.force = {0.0, 0.02, 0.0};
    scene.loads.push_back(load);
    Simulation sim(scene, MPI_COMM_SELF);
    ASSERT_TRUE(testing::advance(sim, 400));
    const double t = sim.time();
    const double a = load.force.y * (scene.m - 1) * (scene.n - 1) / scene.material.mass;
    EXPECT_NEAR(sim.positions()(4, 3).y, 0.5 * a * t * t, 1e-9);
    EXPECT_NEAR(sim.positions()(0, 0).y, 0.5 * a * t * t, 1e-9);
  }
}

// A load acts only inside its step window, and a fixed node ignores loads.
TEST(Loads, ActOnlyInTheirWindowAndFixedWins) {
  Scene scene = flat_sheet(6, 6);
  Load load;
  load.nodes.nodes = {{5, 5}, {0, 0}};
  load.force = {0.0, 0.5, 0.0};
  load.window.start = 100;
  load.window.end = 200;
  scene.loads.push_back(load);
  scene.fixes.push_back(testing::fix_nodes({{0, 0}}));
  Simulation sim(scene, MPI_COMM_SELF);
  ASSERT_TRUE(testing::advance(sim, 100));
  EXPECT_EQ(sim.positions()(5, 5).y, 0.0);  // nothing has acted yet
  ASSERT_TRUE(testing::advance(sim, 150));
  EXPECT_GT(sim.positions()(5, 5).y, 0.0);
  EXPECT_EQ(sim.positions()(0, 0).y, 0.0);  // held
}

class Schemes : public ::testing::TestWithParam<Integrator> {};

// A fix that switches on mid-run holds the node where it is at that step (not at its rest
// position), only along its axes, and only until its window ends.
TEST_P(Schemes, FixHoldsTheValueItFindsAlongItsAxes) {
  Scene scene = flat_sheet(6, 6);
  scene.integrator = GetParam();
  scene.gravity = {1.0, -9.8, 0.0};
  Fix fix = testing::fix_nodes({{2, 3}});
  fix.axes = {false, true, false};  // "y"
  fix.window.start = 50;
  fix.window.end = 150;
  scene.fixes.push_back(fix);
  Simulation sim(scene, MPI_COMM_SELF);
  ASSERT_TRUE(testing::advance(sim, 50));
  const Vec3 caught = sim.positions()(2, 3);
  ASSERT_LT(caught.y, -0.01);  // it has fallen before the fix acts
  ASSERT_TRUE(testing::advance(sim, 100));
  const Vec3 held = sim.positions()(2, 3);
  EXPECT_EQ(held.y, caught.y);
  EXPECT_GT(held.x, caught.x);  // x is free: gravity's x part pulls it on
  ASSERT_TRUE(testing::advance(sim, 50));
  EXPECT_LT(sim.positions()(2, 3).y, caught.y);  // released after step 150
}

INSTANTIATE_TEST_SUITE_P(Constraints, Schemes,
                         ::testing::Values(Integrator::verlet, Integrator::leapfrog,
                                           Integrator::rk4, Integrator::velocity_verlet,
                                           Integrator::symplectic_euler),
                         testing::scheme_test_name);

}  // namespace
}  // namespace cosserat
