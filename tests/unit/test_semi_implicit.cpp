// The PETSc semi-implicit baseline (docs/semi-implicit.md): what its step must
// reduce to, and what it must buy. Order and free fall are in
// test_integrators.cpp with every scheme.

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cosserat/baseline/semi_implicit.hpp"
#include "cosserat/model/wave_speed.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

#if defined(COSSERAT_HAVE_PETSC)

// Every velocity-dependent and external term, a pinned corner, a fix switched
// on at step 5 and a load, on a small sheet moving out of its rest state.
Scene busy_sheet(Integrator scheme) {
  Scene scene = testing::flat_sheet(9, 7);
  scene.integrator = scheme;
  scene.gravity = {0.0, -9.8, 0.0};
  scene.damping = 0.2;
  scene.fluid = Fluid{0.032, {3.0, 1.0, 5.0}, {}};
  scene.initial_velocity = {0.2, 0.5, -0.1};
  scene.fixes.push_back(testing::fix_nodes({{0, 0}}));
  Fix later = testing::fix_nodes({{8, 6}, {4, 3}});
  later.window.start = 5;
  scene.fixes.push_back(later);
  Load load;
  load.nodes.nodes = {{6, 2}};
  load.force = {0.3, 0.2, -0.1};
  load.window.end = 20;
  scene.loads.push_back(load);
  scene.dt = 2e-3;
  return scene;
}

// With J = 0 the step is explicit Verlet with the velocity terms at the centre
// (docs/equations.md §4). A sheet without stiffness has f_int = 0 and so J = 0 exactly:
// the two schemes must agree to the linear solver's tolerance with damping,
// fluid, a load and held components all on.
TEST(SemiImplicit, WithoutStiffnessItIsVerlet) {
  Scene verlet = busy_sheet(Integrator::verlet);
  verlet.material.zeta = {0.0, 0.0, 0.0};
  verlet.material.xi = {0.0, 0.0, 0.0};
  verlet.material.phi = {0.0, 0.0, 0.0};
  Scene implicit = verlet;
  implicit.integrator = Integrator::semi_implicit;
  Simulation a(verlet, MPI_COMM_SELF, any_scheme), b(implicit, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(a, 60));
  ASSERT_TRUE(testing::advance(b, 60));
  double worst = 0.0, moved = 0.0;
  for (int l = 0; l < verlet.n; ++l)
    for (int k = 0; k < verlet.m; ++k) {
      worst = std::max(worst, norm(a.positions()(k, l) - b.positions()(k, l)));
      moved = std::max(moved, norm(a.positions()(k, l) - b.positions()(0, 0)));
    }
  EXPECT_GT(moved, 1.0);  // the comparison is not between two resting sheets
  EXPECT_LT(worst, 1e-12 * verlet.size1);
}

// Held components do not move, whatever the solve does with the others. (Here
// the step and Verlet's differ by design: Verlet solves a node's 3 x 3 fluid
// system and then overwrites the held component; the solve eliminates it first.
// docs/semi-implicit.md.)
TEST(SemiImplicit, HeldComponentsStay) {
  Scene scene = busy_sheet(Integrator::semi_implicit);
  scene.fixes.back().axes = {false, true, false};
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(sim, 5));
  const Vec3 pinned = sim.positions()(0, 0);
  const double y_held = sim.positions()(8, 6).y;
  const Vec3 y_node = sim.positions()(8, 6);
  ASSERT_TRUE(testing::advance(sim, 40));
  EXPECT_EQ(sim.positions()(0, 0).x, pinned.x);
  EXPECT_EQ(sim.positions()(0, 0).y, pinned.y);
  EXPECT_EQ(sim.positions()(0, 0).z, pinned.z);
  EXPECT_EQ(sim.positions()(8, 6).y, y_held);
  EXPECT_GT(norm(sim.positions()(8, 6) - y_node),
            1e-3);  // its free components did move
}

// A moving fix holds its components on their line in the semi-implicit step too: the solve
// takes them there, not just the overwrite after it.
TEST(SemiImplicit, MovingHeldComponentsFollowTheirVelocity) {
  Scene scene = busy_sheet(Integrator::semi_implicit);
  scene.fixes.back().velocity = {0.1, -0.2, 0.05};
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(sim, 5));
  const Vec3 caught = sim.positions()(8, 6);
  const double caught_at = sim.time();
  ASSERT_TRUE(testing::advance(sim, 40));
  const double t = sim.time() - caught_at;
  const Vec3 r = sim.positions()(8, 6);
  EXPECT_EQ(r.x, caught.x + 0.1 * t);
  EXPECT_EQ(r.y, caught.y - 0.2 * t);
  EXPECT_EQ(r.z, caught.z + 0.05 * t);
  EXPECT_LT(norm(sim.velocities()(8, 6) - Vec3{0.1, -0.2, 0.05}), 1e-9);
}

// The point of the baseline: S1 (docs/scenes.md) at three times the CFL estimate (0.0133 s; 3.2
// times Verlet's limit of 0.0124 s measured by `cosserat stable-dt`) runs stably for 3 s, where
// Verlet is stopped by the monitor. The Jacobian must be right for this, not just present.
TEST(SemiImplicit, StableBeyondTheExplicitLimit) {
  Scene scene = load_scene(std::string(COSSERAT_SOURCE_DIR) + "/scenes/s1_clothesline.toml");
  scene.dt = 3.0 * cfl_estimate(scene.material, scene.areal_density(), scene.h1(), scene.h2()).dt;
  const long steps = std::lround(3.0 / scene.dt);
  scene.integrator = Integrator::verlet;
  Simulation verlet(scene, MPI_COMM_SELF, any_scheme);
  EXPECT_FALSE(testing::advance(verlet, steps));
  scene.integrator = Integrator::semi_implicit;
  Simulation implicit(scene, MPI_COMM_SELF, any_scheme);
  EXPECT_TRUE(testing::advance(implicit, steps));
  const Diagnostics d = implicit.diagnostics();
  EXPECT_NEAR(d.area_ratio, 1.0, 0.1);
}

// The run summary's numbers: one solve per step, at least one iteration each.
TEST(SemiImplicit, CountsItsSolves) {
  Scene scene = busy_sheet(Integrator::semi_implicit);
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(sim, 12));
  const auto solves = sim.stepper().linear_solves();
  ASSERT_TRUE(solves.has_value());
  EXPECT_EQ(solves->solves, 12);
  EXPECT_GE(solves->iterations, 12);
  EXPECT_GE(solves->most_iterations, 1);
  scene.integrator = Integrator::verlet;
  Simulation explicit_run(scene, MPI_COMM_SELF, any_scheme);
  EXPECT_FALSE(explicit_run.stepper().linear_solves().has_value());
}

// time.solver.jacobian_every = 4 builds a Jacobian on steps 0, 4 and 8 of 12 and solves with
// it (and its preconditioner) until the next: the trajectory stays within the linearisation's
// error of the one that builds every step, and is not the same.
TEST(SemiImplicit, KeepsItsJacobianForTheStepsAsked) {
  Scene scene = busy_sheet(Integrator::semi_implicit);
  Simulation every_step(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(every_step, 12));
  EXPECT_EQ(every_step.stepper().linear_solves()->jacobians, 12);
  scene.solver.jacobian_every = 4;
  Simulation kept(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(kept, 12));
  EXPECT_EQ(kept.stepper().linear_solves()->jacobians, 3);
  EXPECT_EQ(kept.stepper().linear_solves()->solves, 12);
  const Simulation start(scene, MPI_COMM_SELF, any_scheme);
  double apart = 0.0, moved = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) {
      const Vec3 r = every_step.positions()(k, l);
      apart = std::max(apart, norm(kept.positions()(k, l) - r));
      moved = std::max(moved, norm(r - start.positions()(k, l)));
    }
  std::printf("[jacobian_every] 4: %.3g m from building every step, which moved %.3g m\n",
              apart, moved);
  EXPECT_GT(apart, 1e-12);
  EXPECT_LT(apart, 1e-2 * moved);
}

// The exact Jacobian's node Hessians are taken on the threads and summed in the order of the
// nodes (docs/semi-implicit.md, "The Jacobian"): on one thread and on three, the trajectory is
// the same to the bit.
TEST(SemiImplicit, ThreadsGiveTheSameBits) {
  const Scene scene = busy_sheet(Integrator::semi_implicit_2);
  const int threads_before = omp_get_max_threads();
  omp_set_num_threads(1);
  Simulation one(scene, MPI_COMM_SELF, any_scheme);
  const bool one_ran = testing::advance(one, 12);
  omp_set_num_threads(3);
  Simulation three(scene, MPI_COMM_SELF, any_scheme);
  const bool three_ran = testing::advance(three, 12);
  omp_set_num_threads(threads_before);
  ASSERT_TRUE(one_ran && three_ran);
  ASSERT_EQ(one.stepper().linear_solves()->jacobians, 12);
  const Simulation start(scene, MPI_COMM_SELF, any_scheme);
  double moved = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) {
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(one.positions()(k, l)[c], three.positions()(k, l)[c]) << k << ", " << l;
      moved = std::max(moved, norm(one.positions()(k, l) - start.positions()(k, l)));
    }
  EXPECT_GT(moved, 1e-3);
}

// Without ksp and pc the baseline takes cg with hypre's BoomerAMG only where block Jacobi
// stalls and BoomerAMG converges: an exact (energy-form) Jacobian on a grid of 240 × 240 nodes
// or more, from a PETSc built with hypre (docs/semi-implicit.md, "Preconditioners, against
// grid size").
TEST(SemiImplicit, ChoosesMultigridForLargeSheetsOfTheEnergyForm) {
  const auto chosen = [](bool exact, long nodes, bool have_hypre) {
    const KrylovChoice choice = default_linear_solver(exact, nodes, have_hypre);
    return choice.ksp + " + " + choice.pc;
  };
  EXPECT_EQ(chosen(true, 239L * 240L, true), "gmres + bjacobi");
  EXPECT_EQ(chosen(true, 240L * 240L, true), "cg + hypre");
  EXPECT_EQ(chosen(true, 480L * 480L, false), "gmres + bjacobi");  // a PETSc without hypre
  EXPECT_EQ(chosen(false, 1000L * 1000L, true), "gmres + bjacobi");  // a differenced Jacobian
  EXPECT_TRUE(LinearSolver{}.ksp.empty());
  EXPECT_TRUE(LinearSolver{}.pc.empty());
}

// A solver name PETSc does not know is bad input, found before the first step.
TEST(SemiImplicit, UnknownKrylovMethodIsASceneError) {
  Scene scene = busy_sheet(Integrator::semi_implicit);
  scene.solver.ksp = "no-such-method";
  EXPECT_THROW(Simulation(scene, MPI_COMM_SELF, any_scheme), SceneError);
  scene.solver.ksp = "gmres";
  scene.solver.pc = "no-such-preconditioner";
  EXPECT_THROW(Simulation(scene, MPI_COMM_SELF, any_scheme), SceneError);
}

#else

TEST(SemiImplicit, NeedsPetsc) { GTEST_SKIP() << "built without PETSc (COSSERAT_WITH_PETSC=OFF)"; }

#endif

}  // namespace
}  // namespace cosserat
