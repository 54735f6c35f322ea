// docs/equations.md §2.4: the force at a node depends only on positions within two nodes of it, so
// a block that holds its owned nodes plus two ghost rings computes exactly the forces the whole
// grid does. Checked here for several splits inside one process (the MPI halo exchange that
// fills real ghosts comes with the decomposition); every block's forces must be bitwise those
// of the single block.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cosserat/model/cosserat_model.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

// Forces on a block whose ghosts are filled `rings` deep; the ghosts further out hold the
// flat sheet, wrong but not degenerate (left at zero they would coincide, and the unit normal
// of a corner triangle of zero area is 0/0, which the debug build's FPE traps stop at).
Field<Vec3> forces_on(const Block& block, const Scene& scene, int rings = kGhostWidth) {
  Field<Vec3> r(block), f(block);
  const int g = block.ghost;
  for (int l = std::max(block.l0 - g, 0); l < std::min(block.l1 + g, block.n); ++l)
    for (int k = std::max(block.k0 - g, 0); k < std::min(block.k1 + g, block.m); ++k)
      r(k, l) = Vec3{k * scene.h1(), 0.0, l * scene.h2()};
  for (int l = std::max(block.l0 - rings, 0); l < std::min(block.l1 + rings, block.n); ++l)
    for (int k = std::max(block.k0 - rings, 0); k < std::min(block.k1 + rings, block.m); ++k)
      r(k, l) = testing::deformed(scene, k, l);
  CosseratModel model(block, scene.h1(), scene.h2(),
                      flat_rest_state(scene.material, scene.u, scene.v), scene.borders);
  model.internal_force(r, f);
  return f;
}

TEST(Blocks, AnySplitGivesTheForcesOfTheWholeGrid) {
  for (const Borders borders : {Borders::symmetric, Borders::published}) {
    Scene scene = testing::flat_sheet(13, 11);
    scene.borders = borders;
    scene.material.phi = {0.1, 0.05, 0.1};
    const Block whole = Block::whole(scene.m, scene.n, MPI_COMM_SELF);
    const Field<Vec3> reference = forces_on(whole, scene);
    // Splits along k and l, uneven, down to blocks of one node's width.
    const std::vector<std::vector<int>> k_cuts = {{0, 13}, {0, 6, 13}, {0, 1, 5, 12, 13}};
    const std::vector<std::vector<int>> l_cuts = {{0, 11}, {0, 4, 11}, {0, 3, 4, 10, 11}};
    for (const auto& kc : k_cuts)
      for (const auto& lc : l_cuts)
        for (std::size_t i = 0; i + 1 < kc.size(); ++i)
          for (std::size_t j = 0; j + 1 < lc.size(); ++j) {
            const Block block{MPI_COMM_SELF, scene.m, scene.n, kc[i], kc[i + 1], lc[j], lc[j + 1],
                              kGhostWidth};
            const Field<Vec3> f = forces_on(block, scene);
            for (int l = block.l0; l < block.l1; ++l)
              for (int k = block.k0; k < block.k1; ++k) {
                ASSERT_EQ(f(k, l).x, reference(k, l).x) << "node " << k << "," << l;
                ASSERT_EQ(f(k, l).y, reference(k, l).y) << "node " << k << "," << l;
                ASSERT_EQ(f(k, l).z, reference(k, l).z) << "node " << k << "," << l;
              }
          }
  }
}

// One ghost ring is not enough: with the second ring left unfilled the forces differ, which
// shows the check above can fail and that the kernel does read two rings.
TEST(Blocks, OneGhostRingIsNotEnough) {
  Scene scene = testing::flat_sheet(13, 11);
  const Block whole = Block::whole(scene.m, scene.n, MPI_COMM_SELF);
  const Field<Vec3> reference = forces_on(whole, scene);
  const Block block{MPI_COMM_SELF, scene.m, scene.n, 5, 9, 4, 8, kGhostWidth};
  const Field<Vec3> f = forces_on(block, scene, 1);
  bool differs = false;
  for (int l = block.l0; l < block.l1; ++l)
    for (int k = block.k0; k < block.k1; ++k) differs = differs || !(f(k, l).x == reference(k, l).x);
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace cosserat
