// The Verlet step takes the energy form's acceleration row by row from the kernel's buffers
// (Dynamics::free_acceleration_rows) instead of from a field: it must be the field's numbers,
// bit for bit, or a run's trajectory would depend on which path computed it.

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>

#include "cosserat/time/dynamics.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

TEST(FusedRows, AreTheFieldsAccelerationBitForBit) {
  Scene scene = testing::flat_sheet(37, 23);
  scene.gravity = {0.0, -9.8, 0.0};
  scene.damping = 0.3;
  // Two loads on one node, whose order of summation must be kept, one on another row, and one
  // whose window is over at step 5.
  Load first{{{{3, 4}, {20, 11}}}, {0.5, -0.25, 0.125}, false, {}};
  Load second{{{{3, 4}}}, {1e-3, 7.0, -2.0}, false, {}};
  Load ended{{{{30, 0}}}, {1.0, 1.0, 1.0}, false, {}};
  ended.window.end = 4;
  scene.loads = {first, second, ended};
  const Block block = Block::whole(scene.m, scene.n, MPI_COMM_SELF);
  Dynamics dynamics(scene, block, testing::rest_positions(scene, block));
  ASSERT_TRUE(dynamics.fuses_rows());
  Scene without_loads = scene;
  without_loads.loads.clear();
  Dynamics unloaded_dynamics(without_loads, block, testing::rest_positions(scene, block));

  Field<Vec3> r(block);
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) r(k, l) = testing::deformed(scene, k, l);
  const int threads_before = omp_get_max_threads();
  for (const int threads : {1, 3}) {
    omp_set_num_threads(threads);
    for (const long step : {0L, 5L}) {
      Field<Vec3> whole(block), by_rows(block);
      const VelocityTerms terms = dynamics.free_acceleration(r, step, whole, nullptr);
      EXPECT_EQ(terms.damping, dynamics.row_velocity_terms().damping);
      EXPECT_EQ(terms.fluid, dynamics.row_velocity_terms().fluid);
      int rows = 0;
      dynamics.free_acceleration_rows(r, step, [&](int l, double* x, double* y, double* z) {
#pragma omp atomic
        ++rows;
        for (int k = 0; k < scene.m; ++k) by_rows(k, l) = {x[k], y[k], z[k]};
      });
      EXPECT_EQ(rows, scene.n);
      int differ = 0;
      for (int l = 0; l < scene.n; ++l)
        for (int k = 0; k < scene.m; ++k) differ += !same_bits(whole(k, l), by_rows(k, l));
      EXPECT_EQ(differ, 0) << threads << " threads, step " << step;
      // The loads were applied, each only while its window is open: against the same sheet
      // without loads, the loaded nodes gain force / node mass.
      Field<Vec3> unloaded(block);
      unloaded_dynamics.free_acceleration(r, step, unloaded, nullptr);
      const NodeMass& m = dynamics.node_mass();
      const Vec3 gained = by_rows(3, 4) - unloaded(3, 4);
      EXPECT_NEAR(gained.y, (first.force.y + second.force.y) / m(3, 4),
                  1e-9 * std::abs(gained.y));
      EXPECT_NEAR(by_rows(20, 11).x - unloaded(20, 11).x, first.force.x / m(20, 11),
                  1e-9 / m(20, 11));
      EXPECT_EQ(same_bits(by_rows(30, 0), unloaded(30, 0)), step > 4);
    }
  }
  omp_set_num_threads(threads_before);
}

}  // namespace
}  // namespace cosserat
