// docs/equations.md §5 item 6: a scene symmetric under a mirror of the grid stays symmetric.

#include <gtest/gtest.h>

#include <cstdio>

#include "support/sheets.hpp"

namespace cosserat {
namespace {

// Largest distance between node (k, l) and the mirror image of its partner, over the sheet.
template <class Partner, class Mirror>
double asymmetry(const Simulation& sim, const Scene& scene, Partner partner, Mirror mirror) {
  double worst = 0.0;
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) {
      const auto [pk, pl] = partner(k, l);
      worst = std::max(worst, norm(sim.positions()(k, l) - mirror(sim.positions()(pk, pl))));
    }
  return worst;
}

// The grid mirror (k, l) -> (l, k) on a square sheet is the world mirror x <-> z. A sheet
// hanging from corner [0,0] (S2, the cape) is symmetric under it, and so is the discrete
// operator of every form, which treats x1 and x2 alike. (The mirrors k -> m-1-k and
// l -> n-1-l are symmetries of the trapezoidal quadrature alone; see the tests below.)
TEST(Symmetry, CapeStaysSymmetricAboutTheDiagonal) {
  for (const auto& [discretisation, borders] :
       {std::pair{Discretisation::energy, Borders::symmetric},
        std::pair{Discretisation::energy_nodal, Borders::symmetric},
        std::pair{Discretisation::flux, Borders::symmetric},
        std::pair{Discretisation::flux, Borders::published}}) {
    Scene scene = testing::flat_sheet(10, 10);
    scene.discretisation = discretisation;
    scene.borders = borders;
    scene.gravity = {0.0, -9.8, 0.0};
    scene.damping = 0.2;
    scene.initial_velocity = {0.5, 0.0, 0.5};
    scene.fixes.push_back(testing::fix_nodes({{0, 0}}));
    Simulation sim(scene, MPI_COMM_SELF);
    ASSERT_TRUE(testing::advance(sim, 2000));
    const double moved = std::abs(sim.diagnostics().center_of_mass.y);
    const double worst = asymmetry(
        sim, scene, [](int k, int l) { return std::pair{l, k}; },
        [](Vec3 p) { return Vec3{p.z, p.y, p.x}; });
    std::printf("[symmetry] %s form, %s borders: asymmetry %.3e m after a fall of %.3f m\n",
                discretisation_name(discretisation),
                borders == Borders::symmetric ? "symmetric" : "published", worst, moved);
    EXPECT_LT(worst, 1e-10 * moved);
  }
}

// S1 (the clothesline: held at [0,0] and [0,9]) is symmetric under l -> n-1-l, the world
// mirror z -> -z. The trapezoidal quadrature's energy is invariant under every mirror of the
// grid (docs/equations.md, "Energy quadrature"), so after 2000 steps the sheet is symmetric to
// round-off; the nodal one, whose forward differences become backward ones under the mirror,
// is asymmetric by an O(h) error (measured: 5.1e-3 of the deflection), which shows the test
// can see it.
TEST(Symmetry, ClotheslineStaysSymmetricUnderTheGridMirror) {
  for (const Discretisation d : {Discretisation::energy, Discretisation::energy_nodal}) {
    Scene scene = testing::flat_sheet(10, 10);
    // Centred on z = 0, so that the world mirror is z -> -z, exact in floating point: mirrored
    // nodes then have coordinates of the same precision (with the sheet from z = 0 to 10 m,
    // rounding alone leaves 1e-10 of the deflection).
    scene.origin = {0.0, 0.0, -5.0};
    scene.discretisation = d;
    scene.gravity = {0.0, -9.8, 0.0};
    scene.damping = 0.2;
    scene.fixes.push_back(testing::fix_nodes({{0, 0}, {0, 9}}));
    Simulation sim(scene, MPI_COMM_SELF);
    ASSERT_TRUE(testing::advance(sim, 2000));
    double deflection = 0.0;
    for (int l = 0; l < scene.n; ++l)
      for (int k = 0; k < scene.m; ++k)
        deflection = std::max(deflection, std::abs(sim.positions()(k, l).y));
    const double worst = asymmetry(
        sim, scene, [&](int k, int l) { return std::pair{k, scene.n - 1 - l}; },
        [&](Vec3 p) { return Vec3{p.x, p.y, -p.z}; });
    std::printf("[symmetry] S1, %s: asymmetry %.3e of the deflection %.3f m\n",
                discretisation_name(d), worst / deflection, deflection);
    if (d == Discretisation::energy)
      EXPECT_LT(worst, 1e-10 * deflection);
    else
      EXPECT_GT(worst, 1e-3 * deflection);
  }
}

// A sheet held at its four corners with a load at its centre is symmetric under both mirrors
// of the grid and the diagonal one; so is the solution, to round-off.
TEST(Symmetry, FourCornerSheetWithACentredLoadStaysSymmetric) {
  Scene scene = testing::flat_sheet(11, 11);
  // Centred on the origin, so that the world mirrors are x -> -x and z -> -z, exact in
  // floating point (as for S1 above).
  scene.origin = {-5.0, 0.0, -5.0};
  scene.damping = 0.2;
  scene.fixes.push_back(testing::fix_nodes({{0, 0}, {10, 0}, {0, 10}, {10, 10}}));
  Load load;
  load.nodes.nodes = {{5, 5}};
  load.force = {0.0, -2.0, 0.0};
  scene.loads.push_back(load);
  Simulation sim(scene, MPI_COMM_SELF);
  ASSERT_TRUE(testing::advance(sim, 2000));
  const double deflection = std::abs(sim.positions()(5, 5).y);
  ASSERT_GT(deflection, 0.1);
  const int last = scene.m - 1;
  const double k_mirror = asymmetry(
      sim, scene, [&](int k, int l) { return std::pair{last - k, l}; },
      [](Vec3 p) { return Vec3{-p.x, p.y, p.z}; });
  const double l_mirror = asymmetry(
      sim, scene, [&](int k, int l) { return std::pair{k, last - l}; },
      [](Vec3 p) { return Vec3{p.x, p.y, -p.z}; });
  const double diagonal = asymmetry(
      sim, scene, [](int k, int l) { return std::pair{l, k}; },
      [](Vec3 p) { return Vec3{p.z, p.y, p.x}; });
  std::printf("[symmetry] four corners: asymmetry %.3e %.3e %.3e of the deflection %.3f m\n",
              k_mirror / deflection, l_mirror / deflection, diagonal / deflection, deflection);
  EXPECT_LT(k_mirror, 1e-10 * deflection);
  EXPECT_LT(l_mirror, 1e-10 * deflection);
  EXPECT_LT(diagonal, 1e-10 * deflection);
}

}  // namespace
}  // namespace cosserat
