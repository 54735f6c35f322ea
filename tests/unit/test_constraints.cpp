// Fixed nodes, axis masks, step windows and point loads (docs/equations.md §1 and §4.1).

#include <gtest/gtest.h>

#include <cmath>

#include "support/sheets.hpp"

namespace cosserat {
namespace {

using testing::flat_sheet;

// Loads of F newtons times each node's share of the dual area (1 inside, ½ on a border, ¼ at a
// corner: a uniform load per unit area) on a free, weightless sheet move it rigidly with the
// acceleration F/(μ0 h1 h2) = F (m−1)(n−1)/M: loads are newtons on the node's lumped mass,
// whatever the resolution (docs/model.md, "Energy quadrature").
TEST(Loads, NewtonsOnTheLumpedMass) {
  for (const Integrator scheme : {Integrator::verlet, Integrator::rk4}) {
    Scene scene = flat_sheet(9, 6);
    scene.integrator = scheme;
    const Vec3 force{0.0, 0.02, 0.0};
    const NodeMass share{1.0, scene.m, scene.n, true};
    for (const double weight : {1.0, 0.5, 0.25}) {
      Load load;
      for (int l = 0; l < scene.n; ++l)
        for (int k = 0; k < scene.m; ++k)
          if (share(k, l) == weight) load.nodes.nodes.push_back({k, l});
      load.force = weight * force;
      scene.loads.push_back(load);
    }
    Simulation sim(scene, MPI_COMM_SELF);
    ASSERT_TRUE(testing::advance(sim, 400));
    const double t = sim.time();
    const double a = force.y * (scene.m - 1) * (scene.n - 1) / scene.material.mass;
    EXPECT_NEAR(sim.positions()(4, 3).y, 0.5 * a * t * t, 1e-9);
    EXPECT_NEAR(sim.positions()(0, 3).y, 0.5 * a * t * t, 1e-9);
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

// A fix with a velocity carries its node along a prescribed straight line whatever the forces
// (gravity, the sheet pulling back): from the step it switches on, the node is exactly where it
// was then plus v (t − t₀), and moves at v. A still fix later in the scene takes over at the
// last step of the moving one's window and holds the node where it got to, not where it was
// caught.
TEST_P(Schemes, MovingFixCarriesItsNodeAtItsVelocity) {
  Scene scene = flat_sheet(6, 6);
  scene.integrator = GetParam();
  scene.gravity = {1.0, -9.8, 0.0};
  Fix moving = testing::fix_nodes({{2, 3}});
  moving.velocity = {0.3, 0.1, -0.2};
  moving.window.start = 50;
  moving.window.end = 150;
  scene.fixes.push_back(moving);
  Fix still = testing::fix_nodes({{2, 3}});
  still.window.start = 150;
  scene.fixes.push_back(still);
  Simulation sim(scene, MPI_COMM_SELF);
  ASSERT_TRUE(testing::advance(sim, 50));
  const Vec3 caught = sim.positions()(2, 3);
  const double caught_at = sim.time();
  ASSERT_LT(caught.y, -0.01);  // it has fallen before the fix acts
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(testing::advance(sim, 25));
    const double t = sim.time() - caught_at;
    const Vec3 r = sim.positions()(2, 3);
    EXPECT_EQ(r.x, caught.x + moving.velocity.x * t);
    EXPECT_EQ(r.y, caught.y + moving.velocity.y * t);
    EXPECT_EQ(r.z, caught.z + moving.velocity.z * t);
    EXPECT_LT(norm(sim.velocities()(2, 3) - moving.velocity), 1e-9);
  }
  const Vec3 drawn = sim.positions()(2, 3);
  ASSERT_TRUE(testing::advance(sim, 50));
  const Vec3 r = sim.positions()(2, 3);
  EXPECT_EQ(r.x, drawn.x);
  EXPECT_EQ(r.y, drawn.y);
  EXPECT_EQ(r.z, drawn.z);
  EXPECT_LT(sim.positions()(5, 5).y, -0.1);  // the free nodes went on falling
}

// Only the held axes move: a node held in x at a velocity falls freely in y and z, as if
// unheld, while its x follows the fix.
TEST_P(Schemes, MovingFixLeavesTheFreeAxesFree) {
  Scene scene = flat_sheet(6, 6);
  scene.integrator = GetParam();
  scene.gravity = {0.0, -9.8, 0.0};
  scene.material.zeta = {0.0, 0.0, 0.0};  // no stiffness: every free node falls freely
  scene.material.xi = {0.0, 0.0, 0.0};
  scene.material.phi = {0.0, 0.0, 0.0};
  Fix rail = testing::fix_nodes({{0, 0}});
  rail.axes = {true, false, false};
  rail.velocity = {-0.5, 0.0, 0.0};
  scene.fixes.push_back(rail);
  Simulation sim(scene, MPI_COMM_SELF);
  const Vec3 start = sim.positions()(0, 0);
  ASSERT_TRUE(testing::advance(sim, 200));
  const double t = sim.time();
  EXPECT_EQ(sim.positions()(0, 0).x, start.x + rail.velocity.x * t);
  // It falls as a free node does (free fall itself, to each scheme's order, is
  // test_integrators.cpp's).
  EXPECT_NEAR(sim.positions()(0, 0).y, sim.positions()(3, 3).y, 1e-12);
  EXPECT_LT(sim.positions()(0, 0).y, -0.4 * 9.8 * t * t);
  EXPECT_EQ(sim.positions()(0, 0).z, start.z);
}

// A runner dragging a sheet: one corner of a weightless, damped sheet (drag 1 /s) is moved
// away from the sheet along its edge at 0.2 m/s for 6 s. Nothing but the membrane carries the
// pull, so the sheet is dragged after the runner: its centre of mass moves the same way, behind
// the runner, and at the end faster than half the runner's speed (a free sheet under drag
// reaches a pulled speed within about 1/(1 /s) = 1 s); the sheet stays in one piece, the far
// corner no farther from the runner than a few per cent beyond the rest diagonal.
TEST(MovingFix, ARunnerDragsTheSheet) {
  Scene scene = flat_sheet(9, 6);
  scene.damping = 1.0;
  Fix runner = testing::fix_nodes({{0, 0}});
  runner.velocity = {-0.2, 0.0, 0.0};
  scene.fixes.push_back(runner);
  Simulation sim(scene, MPI_COMM_SELF);
  const auto mean_x = [&] {
    double sum = 0.0;
    for (int l = 0; l < scene.n; ++l)
      for (int k = 0; k < scene.m; ++k) sum += sim.positions()(k, l).x;
    return sum / (scene.m * scene.n);
  };
  const double start = mean_x();
  const double diagonal = norm(sim.positions()(8, 5) - sim.positions()(0, 0));
  ASSERT_TRUE(testing::advance(sim, 5900));
  const double before = mean_x();
  ASSERT_TRUE(testing::advance(sim, 100));
  const double drawn = runner.velocity.x * sim.time();  // -1.2 m
  EXPECT_EQ(sim.positions()(0, 0).x, drawn);
  const double moved = mean_x() - start;
  EXPECT_LT(moved, 0.0);
  EXPECT_GT(moved, drawn);
  EXPECT_LT((mean_x() - before) / 0.1, 0.5 * runner.velocity.x);
  EXPECT_LT(norm(sim.positions()(8, 5) - sim.positions()(0, 0)), 1.05 * diagonal);
}

// A turning fix carries its nodes round a circle about its axis whatever the forces: from the
// step it switches on, each node is where it was then turned through ω (t − t₀) about the axis
// through the centre (Rodrigues' formula, docs/scene-format.md "Fixes and loads"), so it stays
// at its distance from the axis and at its height along it, and moves at ω × (r − c). A quarter
// turn about z takes (x, y) to (−y, x) about the centre. When the window ends, a still fix later
// in the file holds each node where the turn left it.
TEST_P(Schemes, TurningFixCarriesItsNodesRoundItsAxis) {
  Scene scene = flat_sheet(6, 6);
  scene.integrator = GetParam();
  scene.gravity = {1.0, -9.8, 0.0};
  Fix turning = testing::fix_nodes({{0, 0}, {0, 5}});
  turning.angular_velocity = {0.0, 0.0, 2.0};
  turning.center = {0.5, 1.0, 0.25};
  turning.window.start = 50;
  turning.window.end = 150;
  scene.fixes.push_back(turning);
  Fix still = testing::fix_nodes({{0, 0}, {0, 5}});
  still.window.start = 150;
  scene.fixes.push_back(still);
  Simulation sim(scene, MPI_COMM_SELF);
  ASSERT_TRUE(testing::advance(sim, 50));
  const Vec3 caught[2] = {sim.positions()(0, 0), sim.positions()(0, 5)};
  const double caught_at = sim.time();
  ASSERT_LT(caught[0].y, -0.01);  // it has fallen before the fix acts
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(testing::advance(sim, 25));
    const double angle = 2.0 * (sim.time() - caught_at);
    const double cosine = std::cos(angle), sine = std::sin(angle);
    for (int j = 0; j < 2; ++j) {
      const Vec3 offset = caught[j] - turning.center;
      const Vec3 expected = turning.center + Vec3{cosine * offset.x - sine * offset.y,
                                                  sine * offset.x + cosine * offset.y, offset.z};
      const Vec3 r = sim.positions()(0, 5 * j);
      EXPECT_LT(norm(r - expected), 1e-14) << "node " << j << " at step " << 50 + 25 * (i + 1);
      const Vec3 spin_velocity = cross(turning.angular_velocity, r - turning.center);
      // Verlet reports the held positions' difference over the last step and leapfrog its
      // half-step velocity: both are the turn's at the step's end to within half the angle of a
      // step, ω Δt / 2, relative. The schemes that carry velocities at the end hold them exactly.
      const bool one_sided =
          scene.integrator == Integrator::verlet || scene.integrator == Integrator::leapfrog;
      EXPECT_LT(norm(sim.velocities()(0, 5 * j) - spin_velocity),
                (one_sided ? 0.5 * 2.0 * scene.dt * 1.01 : 1e-14) * norm(spin_velocity));
    }
  }
  const Vec3 left = sim.positions()(0, 5);
  ASSERT_TRUE(testing::advance(sim, 50));
  EXPECT_EQ(norm(sim.positions()(0, 5) - left), 0.0);
  EXPECT_LT(sim.positions()(5, 5).y, -0.1);  // the free nodes went on falling
}

INSTANTIATE_TEST_SUITE_P(Constraints, Schemes,
                         ::testing::Values(Integrator::verlet, Integrator::leapfrog,
                                           Integrator::rk4, Integrator::velocity_verlet,
                                           Integrator::symplectic_euler),
                         testing::scheme_test_name);

}  // namespace
}  // namespace cosserat
