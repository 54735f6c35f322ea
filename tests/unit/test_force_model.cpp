// The step sees a model only through ForceModel (docs/model.md, "Force models"). Whatever form
// the factory picks, the interface must say what that form is: a flat sheet at rest feels no
// internal force, the node masses add up to the sheet's mass, its stencil fits the ghost rings,
// and the areal density the velocity terms use is the rest one exactly when the form's masses
// are constant.

#include <gtest/gtest.h>

#include <cmath>

#include "cosserat/model/force_model.hpp"
#include "cosserat/model/wave_speed.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

class EveryForm : public ::testing::TestWithParam<Discretisation> {};

TEST_P(EveryForm, SaysWhatItIs) {
  Scene scene = testing::flat_sheet(9, 7);
  scene.discretisation = GetParam();
  const Block block = Block::whole(scene.m, scene.n, MPI_COMM_SELF);
  const double rest_area = scene.size1 * scene.size2;
  const std::unique_ptr<ForceModel> model = make_force_model(scene.model_spec(), block, rest_area);
  ASSERT_NE(model, nullptr);

  EXPECT_LE(model->reach(), kGhostWidth);
  const bool energy_form = is_energy_form(GetParam());
  EXPECT_EQ(model->fuses_rows(), energy_form);
  EXPECT_EQ(model->density_follows_area(), !energy_form);

  // The node masses add up to M, but in the nodal quadrature, whose border nodes carry a full
  // cell's mass: M mn/((m−1)(n−1)) (docs/model.md, "The energy form").
  double total = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) total += model->node_mass()(k, l);
  const double cells = static_cast<double>(scene.m - 1) * (scene.n - 1);
  const double expected = GetParam() == Discretisation::energy_nodal
                              ? scene.material.mass * scene.m * scene.n / cells
                              : scene.material.mass;
  EXPECT_NEAR(total, expected, 1e-12 * expected);

  // At rest: no internal force, so the acceleration is gravity alone, and no stored energy.
  const Field<Vec3> r = testing::rest_positions(scene, block);
  const Vec3 g{0.0, -9.81, 0.0};
  Field<Vec3> a(block);
  model->free_acceleration(r, g, a, nullptr);
  double largest = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) largest = std::max(largest, norm(a(k, l) - g));
  EXPECT_LT(largest, 1e-9 * norm(g));
  EXPECT_NEAR(model->block_energy(r), 0.0, 1e-15);

  // A stretched sheet stores energy and is pulled back: the force does negative work on the
  // stretch (the rows' x components point towards the middle column).
  Field<Vec3> stretched(block);
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) {
      stretched(k, l) = r(k, l);
      stretched(k, l).x *= 1.01;
    }
  EXPECT_GT(model->block_energy(stretched), 0.0);
  model->free_acceleration(stretched, {}, a, nullptr);
  const double middle = stretched(scene.m / 2, scene.n / 2).x;
  double work = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) work += a(k, l).x * (stretched(k, l).x - middle);
  EXPECT_LT(work, 0.0);
}

INSTANTIATE_TEST_SUITE_P(ForceModel, EveryForm,
                         ::testing::Values(Discretisation::energy, Discretisation::energy_nodal,
                                           Discretisation::flux));

// The step estimate a model gives before it exists is the rest sheet's CFL step, and a stretched
// sheet's is shorter (its membrane stiffens), never longer.
TEST(ForceModel, StepEstimatesShortenWithStretch) {
  const ModelSpec spec = testing::flat_sheet(9, 7).model_spec();
  const CflEstimate rest = rest_step_estimate(spec);
  EXPECT_GT(rest.dt, 0.0);
  EXPECT_DOUBLE_EQ(stretched_step_estimate(spec, 1.0), rest.dt);
  EXPECT_LT(stretched_step_estimate(spec, 1.21), rest.dt);
}

}  // namespace
}  // namespace cosserat
