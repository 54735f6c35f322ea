// docs/equations.md §5 items 2 (free fall) and 7 (convergence order of every scheme, damping on).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>

#include "cosserat/baseline/semi_implicit.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

using testing::flat_sheet;

class EveryScheme : public ::testing::TestWithParam<Integrator> {};

// §5.2: gravity only, no constraints: every node follows r0 + v0 t + ½ g t². Schemes exact for
// a constant acceleration reproduce it to round-off; the two Euler schemes carry their known
// first-order bias ∓½ g Δt t, which is asserted exactly as well.
TEST_P(EveryScheme, FreeFall) {
  Scene scene = flat_sheet(7, 5);
  scene.integrator = GetParam();
  scene.gravity = {0.3, -9.8, 0.1};
  scene.initial_velocity = {1.0, 2.0, -0.5};
  scene.dt = 1e-3;
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  const long steps = 500;
  ASSERT_TRUE(testing::advance(sim, steps));
  const double t = sim.time();
  double bias = 0.0;
  if (scene.integrator == Integrator::euler) bias = -0.5 * scene.dt * t;
  if (scene.integrator == Integrator::symplectic_euler ||
      scene.integrator == Integrator::verlet_lagged)
    bias = 0.5 * scene.dt * t;
  const Vec3 shift = t * scene.initial_velocity + (0.5 * t * t + bias) * scene.gravity;
  double worst = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) {
      const Vec3 start = (k * scene.h1()) * scene.u + (l * scene.h2()) * scene.v;
      worst = std::max(worst, norm(sim.positions()(k, l) - (start + shift)));
    }
  // The semi-implicit steps add J δ, zero for a rigid δ to round-off, and stop their solves
  // at a relative residual of 1e-10.
  const double tolerance = is_semi_implicit(scene.integrator) ? 1e-7 : 1e-9;
  EXPECT_LT(worst, tolerance) << "t = " << t;
}

// Final positions of a smooth scene: an 8 x 8 sheet hanging from one corner, with damping
// and a fluid term (both treated at the step centre by the Verlet family), at T = 0.2 s.
// `gusts`: a wind that changes over 0.05 s, which a scheme must read at each stage's own time.
std::vector<Vec3> smooth_run(Integrator scheme, double dt, std::optional<Gusts> gusts = {}) {
  Scene scene = flat_sheet(8, 8);
  scene.integrator = scheme;
  scene.gravity = {0.0, -9.8, 0.0};
  scene.damping = 0.2;
  scene.fluid = Fluid{0.032, {0.0, 0.0, 5.0}, gusts};
  scene.fixes.push_back(testing::fix_nodes({{0, 0}}));
  scene.dt = dt;
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  const long steps = std::lround(0.2 / dt);
  EXPECT_TRUE(testing::advance(sim, steps));
  std::vector<Vec3> out;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) out.push_back(sim.positions()(k, l));
  return out;
}

double rms_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += dot(a[i] - b[i], a[i] - b[i]);
  return std::sqrt(sum / static_cast<double>(a.size()));
}

int expected_order(Integrator s) {
  switch (s) {
    case Integrator::euler:
    case Integrator::symplectic_euler:
    case Integrator::verlet_lagged:
    // The force is taken at the new positions, linearised (docs/semi-implicit.md): J δ is an
    // O(Δt) change of the force, so the scheme the issue specifies is first order.
    case Integrator::semi_implicit: return 1;
    case Integrator::rk4: return 4;
    default: return 2;
  }
}

// §5.7: with Δt halved, the differences between successive solutions shrink by 2^order.
// Self-convergence needs no reference solution; the observed order is printed for the note.
TEST_P(EveryScheme, ConvergenceOrder) {
  const Integrator scheme = GetParam();
  const int order = expected_order(scheme);
  // RK4's error reaches round-off sooner: start it at a coarser step.
  const double dt0 = order == 4 ? 8e-3 : 2e-3;
  const auto coarse = smooth_run(scheme, dt0);
  const auto medium = smooth_run(scheme, dt0 / 2);
  const auto fine = smooth_run(scheme, dt0 / 4);
  const double observed =
      std::log2(rms_difference(coarse, medium) / rms_difference(medium, fine));
  std::printf("[order] %-17s observed %.3f (expected %d)\n", integrator_name(scheme).c_str(),
              observed, order);
  EXPECT_NEAR(observed, order, 0.3);
}

// The same with gusts of 20 m/s that change over 0.05 s: a scheme that read the wind at the
// step's start in a stage that belongs to its middle or end would fall to first order.
TEST_P(EveryScheme, ConvergenceOrderInGusts) {
  const Integrator scheme = GetParam();
  const int order = expected_order(scheme);
  const Gusts gusts{20.0, 0.05, 5.0, 3};
  const double dt0 = order == 4 ? 8e-3 : 2e-3;
  const auto coarse = smooth_run(scheme, dt0, gusts);
  const auto medium = smooth_run(scheme, dt0 / 2, gusts);
  const auto fine = smooth_run(scheme, dt0 / 4, gusts);
  const double observed =
      std::log2(rms_difference(coarse, medium) / rms_difference(medium, fine));
  std::printf("[order in gusts] %-17s observed %.3f (expected %d)\n",
              integrator_name(scheme).c_str(), observed, order);
  EXPECT_NEAR(observed, order, 0.3);
}

INSTANTIATE_TEST_SUITE_P(Integrators, EveryScheme,
                         ::testing::ValuesIn(testing::every_scheme()),
                         testing::scheme_test_name);

}  // namespace
}  // namespace cosserat
