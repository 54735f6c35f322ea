// The energy form of MODEL.md §2.5: its force is the exact negative gradient of its energy, the
// energy is that of the §2.1 strains, and a damped run never gains energy.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "cosserat/baseline/semi_implicit.hpp"
#include "cosserat/model/cosserat_energy.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

struct Sheet {
  Scene scene;
  Block block;
  Field<Vec3> r;
  CosseratEnergy energy;

  explicit Sheet(const Scene& s)
      : scene(s),
        block(Block::whole(s.m, s.n, MPI_COMM_SELF)),
        r(block),
        energy(block, s.h1(), s.h2(), flat_rest_state(s.material, s.u, s.v)) {
    for (int l = 0; l < s.n; ++l)
      for (int k = 0; k < s.m; ++k) r(k, l) = testing::deformed(s, k, l);
  }
  double total() const { return energy.block_energy(r); }
};

Scene coupled_sheet() {
  // Unequal spacings and a coupling φ, so every term of E is exercised.
  Scene s = testing::flat_sheet(7, 6);
  s.size2 = 8.0;
  s.material.xi = {0.3, 0.2, 0.4};
  s.material.phi = {0.05, 0.02, 0.03};
  return s;
}

// −∂E/∂r by central differences of E, against the kernel's force at every node and component.
TEST(EnergyForm, ForceIsMinusTheGradientOfTheEnergy) {
  Sheet sheet(coupled_sheet());
  Field<Vec3> force(sheet.block);
  sheet.energy.internal_force(sheet.r, force);
  const double step = 1e-6;
  double worst = 0.0, largest = 0.0;
  for (int l = 0; l < sheet.scene.n; ++l)
    for (int k = 0; k < sheet.scene.m; ++k)
      for (int c = 0; c < 3; ++c) {
        const double kept = sheet.r(k, l)[c];
        sheet.r(k, l)[c] = kept + step;
        const double up = sheet.total();
        sheet.r(k, l)[c] = kept - step;
        const double down = sheet.total();
        sheet.r(k, l)[c] = kept;
        const double expected = -(up - down) / (2.0 * step);
        worst = std::max(worst, std::abs(force(k, l)[c] - expected));
        largest = std::max(largest, std::abs(expected));
      }
  ASSERT_GT(largest, 1.0);  // the sheet is well away from rest
  EXPECT_LT(worst, 1e-6 * largest) << "largest force component " << largest;
}

// The Jacobian of the force is the negative Hessian of E: symmetric, to finite-difference noise.
TEST(EnergyForm, JacobianIsSymmetric) {
  Sheet sheet(coupled_sheet());
  const int m = sheet.scene.m, n = sheet.scene.n, size = 3 * m * n;
  std::vector<double> J(static_cast<std::size_t>(size) * size);
  Field<Vec3> up(sheet.block), down(sheet.block);
  const double step = 1e-6;
  double largest = 0.0;
  for (int column = 0; column < size; ++column) {
    const int node = column / 3, c = column % 3, k = node % m, l = node / m;
    const double kept = sheet.r(k, l)[c];
    sheet.r(k, l)[c] = kept + step;
    sheet.energy.internal_force(sheet.r, up);
    sheet.r(k, l)[c] = kept - step;
    sheet.energy.internal_force(sheet.r, down);
    sheet.r(k, l)[c] = kept;
    for (int row = 0; row < size; ++row) {
      const int rn = row / 3, rc = row % 3;
      const double d = (up(rn % m, rn / m)[rc] - down(rn % m, rn / m)[rc]) / (2.0 * step);
      J[static_cast<std::size_t>(row) * size + column] = d;
      largest = std::max(largest, std::abs(d));
    }
  }
  double worst = 0.0;
  for (int row = 0; row < size; ++row)
    for (int column = 0; column < row; ++column)
      worst = std::max(worst, std::abs(J[static_cast<std::size_t>(row) * size + column] -
                                        J[static_cast<std::size_t>(column) * size + row]));
  EXPECT_LT(worst, 1e-6 * largest) << "largest entry " << largest;
}

// MODEL.md §5 item 1 for the energy form: a rotated and translated rest sheet stores no energy
// and feels no force.
TEST(EnergyForm, RigidMotionHasNoEnergyAndNoForce) {
  Sheet sheet(coupled_sheet());
  const double c = std::cos(0.7), s = std::sin(0.7);
  for (int l = 0; l < sheet.scene.n; ++l)
    for (int k = 0; k < sheet.scene.m; ++k) {
      const double x = k * sheet.scene.h1(), z = l * sheet.scene.h2();
      // A shear-free rotation needs orthonormal tangents: rotate in a plane, then tilt it.
      const Vec3 in_plane{c * x - s * z, 0.0, s * x + c * z};
      const double t = 0.4;
      sheet.r(k, l) = Vec3{in_plane.x, std::sin(t) * in_plane.z, std::cos(t) * in_plane.z} +
                      Vec3{3.0, -1.0, 0.5};
    }
  Field<Vec3> force(sheet.block);
  sheet.energy.internal_force(sheet.r, force);
  double worst = 0.0;
  for (int l = 0; l < sheet.scene.n; ++l)
    for (int k = 0; k < sheet.scene.m; ++k) worst = std::max(worst, norm(force(k, l)));
  // Against the force of a 1 % stretch, the scale of what a real deformation gives.
  const double zeta = sheet.scene.material.zeta[0];
  EXPECT_LT(worst, 1e-12 * zeta * sheet.scene.h2());
  EXPECT_LT(std::abs(sheet.total()), 1e-20 * zeta * sheet.scene.size1 * sheet.scene.size2);
}

// Kinetic + elastic + gravitational energy of a damped sheet falling from a held corner, after
// every step: the largest rise from one step to the next, and what damping took in all.
double largest_energy_rise(double dt, double* total_drop) {
  Scene scene = testing::flat_sheet(10, 10);
  scene.discretisation = Discretisation::energy;
  scene.integrator = Integrator::velocity_verlet;
  scene.gravity = {0.0, -9.8, 0.0};
  scene.damping = 0.2;
  scene.fixes.push_back(testing::fix_nodes({{0, 9}}));
  scene.u = {1.0, 0.0, 0.0};
  scene.v = {0.0, -1.0, 0.0};
  scene.dt = dt;
  Simulation sim(scene, MPI_COMM_SELF, any_scheme);
  auto total = [&] {
    const Diagnostics d = sim.diagnostics();
    return d.kinetic_energy + d.gravitational_energy + sim.elastic_energy();
  };
  const double first = total();
  double previous = first, rise = 0.0;
  const long steps = std::lround(1.0 / dt);
  for (long s = 0; s < steps; ++s) {
    EXPECT_FALSE(sim.step().has_value());
    const double now = total();
    rise = std::max(rise, now - previous);
    previous = now;
  }
  *total_drop = first - previous;
  return rise;
}

// The integrator may let the total wobble by its O(Δt²) error; measured, the total falls at
// every step at both steps here (largest rise 0), so the bound is round-off of the total.
TEST(EnergyForm, DampedRunNeverGainsEnergy) {
  for (const double dt : {2e-3, 1e-3}) {
    double drop = 0.0;
    const double rise = largest_energy_rise(dt, &drop);
    EXPECT_GT(drop, 10.0) << "dt " << dt;  // the sheet falls: hundreds of joules damped
    EXPECT_LE(rise, 1e-12 * drop) << "dt " << dt;
  }
}

}  // namespace
}  // namespace cosserat
