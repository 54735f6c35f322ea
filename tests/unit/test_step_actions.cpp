// The one place a per-step action hooks in (Stepper::add_action): it runs on every step of
// every scheme, on the proposed state, before the stability check accepts it.

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <vector>

#include "cosserat/baseline/semi_implicit.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

// A floor y ≥ floor_height that stops what reaches it: the simplest position-and-velocity
// response, as a contact response will be.
class Floor final : public StepAction {
 public:
  Floor(const Block& block, double height, std::vector<long>& steps_seen)
      : block_(&block), height_(height), steps_seen_(&steps_seen) {}

  void apply(ProposedStep& proposed) override {
    steps_seen_->push_back(proposed.step);
    const Block& b = *block_;
    for (int l = b.l0; l < b.l1; ++l)
      for (int k = b.k0; k < b.k1; ++k) {
        Vec3& r = proposed.next_positions(k, l);
        if (r.y > height_) continue;
        r.y = height_;
        if (proposed.next_velocities != nullptr) (*proposed.next_velocities)(k, l).y = 0.0;
      }
  }

 private:
  const Block* block_;
  double height_;
  std::vector<long>* steps_seen_;
};

class EverySchemeWithAnAction : public ::testing::TestWithParam<Integrator> {};

// A sheet falls 0.2 m onto the floor: the action sees every step once, in order, and every
// accepted state lies on or above the floor; free fall alone would take it 1.2 m below.
TEST_P(EverySchemeWithAnAction, SeesEveryStepAndItsChangesAreAccepted) {
  Scene scene = testing::flat_sheet(6, 5);
  scene.integrator = GetParam();
  scene.gravity = {0.0, -9.8, 0.0};
  scene.dt = 1e-3;
  const double floor_height = -0.2;
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  std::vector<long> steps_seen;
  sim.stepper().add_action(std::make_unique<Floor>(sim.block(), floor_height, steps_seen));
  const long steps = 500;
  ASSERT_TRUE(testing::advance(sim, steps));
  ASSERT_EQ(steps_seen.size(), static_cast<std::size_t>(steps));
  for (long s = 0; s < steps; ++s) EXPECT_EQ(steps_seen[static_cast<std::size_t>(s)], s + 1);
  double lowest = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) lowest = std::min(lowest, sim.positions()(k, l).y);
  EXPECT_EQ(lowest, floor_height);
  // Resting on the floor: no node moves down any more.
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) EXPECT_GE(sim.velocities()(k, l).y, -1e-12);
}

// An action that throws node (2, 2) a grid spacing away at step 3; `marks`: it says which row
// it moved, as the contact response does.
class Kick final : public StepAction {
 public:
  Kick(double distance, bool marks) : distance_(distance), marks_(marks) {}
  void apply(ProposedStep& proposed) override {
    if (marks_) {
      ASSERT_NE(proposed.moved_rows, nullptr);
    }
    if (proposed.step != 3) return;
    proposed.next_positions(2, 2).y += distance_;
    if (marks_) (*proposed.moved_rows)[2] = 1;
  }
  bool marks_moved_rows() const override { return marks_; }

 private:
  double distance_;
  bool marks_;
};

// The kick stops the run at step 3, at its node, and the state stays at the last good one.
void expect_the_kick_stops_the_run(const Scene& scene, bool marks) {
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  sim.stepper().add_action(std::make_unique<Kick>(scene.h1(), marks));
  ASSERT_TRUE(testing::advance(sim, 2));
  const auto failure = sim.step();
  ASSERT_TRUE(failure.has_value());
  EXPECT_EQ(failure->step, 3);
  EXPECT_EQ(failure->k, 2);
  EXPECT_EQ(failure->l, 2);
  EXPECT_EQ(sim.step_index(), 2);
}

// The action runs before the check: a node it throws a whole grid spacing away stops the run
// at that step, and the state stays at the last good one.
TEST_P(EverySchemeWithAnAction, RunsBeforeTheStabilityCheck) {
  Scene scene = testing::flat_sheet(6, 5);
  scene.integrator = GetParam();
  expect_the_kick_stops_the_run(scene, false);
}

// The same with an action that says which rows it moved, as the contact response does: the
// stability check's edge test then runs in the Verlet step's row walk, before the action, and
// tests the marked row again after it.
TEST_P(EverySchemeWithAnAction, RunsBeforeTheStabilityCheckWhenItMarksItsRows) {
  Scene scene = testing::flat_sheet(6, 5);
  scene.integrator = GetParam();
  // One thread: the walk then tests every edge of the block, none is left to the check.
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  expect_the_kick_stops_the_run(scene, true);
  omp_set_num_threads(threads);
}

// Issue 12, defect 14: a sheet in fast rigid motion is not unstable. At 2000 m/s a node moves
// 2 m per step, 1.8 spacings; before, the monitor compared that with h/2 and stopped the run at
// its first step (S1 in free fall stopped at t = 57 s). Nothing deforms, so every scheme
// carries it exactly (the internal force of the flat sheet is zero): the explicit ones to
// round-off, the semi-implicit one to its linear solves' tolerance (measured 9e-7 m of 81 m).
TEST_P(EverySchemeWithAnAction, FastRigidMotionIsNotAnInstability) {
  Scene scene = testing::flat_sheet(8, 7);
  scene.integrator = GetParam();
  scene.initial_velocity = {300.0, 2000.0, -150.0};
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(sim, 40));
  const double t = 40 * scene.dt;
  const double tolerance = (is_semi_implicit(GetParam()) ? 1e-7 : 1e-12) *
                           norm(t * scene.initial_velocity);
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) {
      const Vec3 start{k * scene.h1(), 0.0, l * scene.h2()};
      EXPECT_LT(norm(sim.positions()(k, l) - (start + t * scene.initial_velocity)), tolerance);
    }
}

INSTANTIATE_TEST_SUITE_P(Schemes, EverySchemeWithAnAction,
                         ::testing::ValuesIn(testing::every_scheme()),
                         testing::scheme_test_name);

}  // namespace
}  // namespace cosserat
