// The per-node measures the output writes (docs/output.md, "Fields") on sheets whose answer is
// known: a uniform stretch and shear, a cylinder, and the stored energy they share with the
// summary.

#include <gtest/gtest.h>

#include <cmath>

#include "cosserat/model/cosserat_energy.hpp"
#include "cosserat/model/surface_measures.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

struct Sheet {
  Scene scene;
  Block block;
  Field<Vec3> r;
  Field<double> values;

  explicit Sheet(const Scene& s)
      : scene(s), block(Block::whole(s.m, s.n, MPI_COMM_SELF)), r(block), values(block) {}
  template <class Place>
  void place(Place&& at) {
    for (int l = 0; l < scene.n; ++l)
      for (int k = 0; k < scene.m; ++k) r(k, l) = at(k * scene.h1(), l * scene.h2());
  }
  Sym2 rest_metric() const { return flat_rest_state(scene.material, scene.u, scene.v).metric; }
};

// r = x a₁ + z a₂: the tangents are a₁ and a₂ at every node, the borders' one-sided ones too,
// so the area ratio is |a₁ × a₂| everywhere and the sheet is flat.
TEST(SurfaceMeasures, AHomogeneousDeformationStretchesEveryNodeAlikeAndBendsNone) {
  Sheet sheet(testing::flat_sheet(7, 9));
  const Vec3 a1{1.2, 0.1, 0.0}, a2{0.3, -0.2, 0.9};
  sheet.place([&](double x, double z) { return x * a1 + z * a2 + Vec3{1.0, 2.0, 3.0}; });
  area_ratio(sheet.r, sheet.scene.h1(), sheet.scene.h2(), sheet.rest_metric(), sheet.values);
  for (int l = 0; l < sheet.scene.n; ++l)
    for (int k = 0; k < sheet.scene.m; ++k)
      EXPECT_NEAR(sheet.values(k, l), norm(cross(a1, a2)), 1e-13) << k << ", " << l;
  mean_curvature(sheet.r, sheet.scene.h1(), sheet.scene.h2(), sheet.values);
  for (int l = 0; l < sheet.scene.n; ++l)
    for (int k = 0; k < sheet.scene.m; ++k)
      EXPECT_NEAR(sheet.values(k, l), 0.0, 1e-12) << k << ", " << l;
}

// The rest sheet need not be spanned by orthogonal directions: the ratio is against √A.
TEST(SurfaceMeasures, TheRestSheetHasAreaRatioOneWhateverItsAxes) {
  Scene scene = testing::flat_sheet(5, 6);
  scene.u = Vec3{1.0, 0.0, 0.0};
  scene.v = Vec3{0.6, 0.0, 0.8};
  Sheet sheet(scene);
  sheet.place([&](double x, double z) { return x * scene.u + z * scene.v; });
  area_ratio(sheet.r, scene.h1(), scene.h2(), sheet.rest_metric(), sheet.values);
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) EXPECT_NEAR(sheet.values(k, l), 1.0, 1e-14);
}

// Rolled along x¹ onto a cylinder of radius R towards +y, against n = a₁ × a₂ / |a₁ × a₂| = −y:
// H = −1/(2R) inside, to the O(h²) of the second differences; the tangent a₁ is the chord of
// an arc h₁, so the area ratio is its length over h₁, 2R sin(h₁/2R)/h₁, at every node.
TEST(SurfaceMeasures, ACylinderHasHalfItsCurvatureAsMeanCurvature) {
  Scene scene = testing::flat_sheet(41, 6);
  Sheet sheet(scene);
  const double R = 5.0;
  sheet.place([&](double x, double z) {
    return Vec3{R * std::sin(x / R), R * (1.0 - std::cos(x / R)), z};
  });
  const double h1 = scene.h1();
  mean_curvature(sheet.r, h1, scene.h2(), sheet.values);
  for (int l = 0; l < scene.n; ++l)
    for (int k = 1; k + 1 < scene.m; ++k)
      EXPECT_NEAR(sheet.values(k, l), -0.5 / R, 0.5 / R * h1 * h1 / (R * R)) << k << ", " << l;
  area_ratio(sheet.r, h1, scene.h2(), sheet.rest_metric(), sheet.values);
  const double chord = 2.0 * R * std::sin(h1 / (2.0 * R)) / h1;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) EXPECT_NEAR(sheet.values(k, l), chord, 1e-14);
}

// The density times the rest area of a node is its share of the stored energy the summary
// reports (docs/equations.md §2.5), border nodes' left-out terms included.
TEST(SurfaceMeasures, EnergyDensityAddsUpToTheStoredEnergy) {
  Scene scene = testing::flat_sheet(9, 7);
  scene.size2 = 8.0;
  scene.material.phi = {0.05, 0.02, 0.03};
  Sheet sheet(scene);
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) sheet.r(k, l) = testing::deformed(scene, k, l);
  const CosseratEnergy energy(sheet.block, scene.h1(), scene.h2(),
                              flat_rest_state(scene.material, scene.u, scene.v));
  energy.energy_density(sheet.r, sheet.values);
  // Each node's density stands for its dual area: h₁h₂ inside, half of it on a border.
  const NodeMass share = energy.node_mass(scene.h1() * scene.h2());
  double sum = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) {
      EXPECT_GE(sheet.values(k, l), 0.0);
      sum += sheet.values(k, l) * share(k, l);
    }
  const double total = energy.block_energy(sheet.r);
  EXPECT_GT(total, 0.0);
  EXPECT_NEAR(sum, total, 1e-12 * total);
}

}  // namespace
}  // namespace cosserat
