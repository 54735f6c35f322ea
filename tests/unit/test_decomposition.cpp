// The split of the grid over ranks (issue 3): the least halo for the grid's shape, blocks that
// tile the grid and differ by at most one node, and a clear refusal when blocks would be
// narrower than the ghost width.

#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "cosserat/grid/decomposition.hpp"

namespace cosserat {
namespace {

TEST(Decomposition, ChoosesTheSplitThatCutsTheFewestNodePairs) {
  // Candidates for 37 x 23 on 6 ranks cut 5·37 = 185 (1 x 6), 23 + 2·37 = 97 (2 x 3),
  // 2·23 + 37 = 83 (3 x 2) or 5·23 = 115 (6 x 1) node pairs.
  const Decomposition odd = Decomposition::choose(37, 23, 6);
  EXPECT_EQ(odd.parts_k(), 3);
  EXPECT_EQ(odd.parts_l(), 2);
  // A long thin grid is cut across its length only.
  const Decomposition strip = Decomposition::choose(1000, 100, 4);
  EXPECT_EQ(strip.parts_k(), 4);
  EXPECT_EQ(strip.parts_l(), 1);
  // A square on a square number of ranks: a square of blocks.
  const Decomposition square = Decomposition::choose(1024, 1024, 16);
  EXPECT_EQ(square.parts_k(), 4);
  EXPECT_EQ(square.parts_l(), 4);
  // A tie goes to whole rows (contiguous halos).
  const Decomposition two = Decomposition::choose(1024, 1024, 2);
  EXPECT_EQ(two.parts_k(), 1);
  EXPECT_EQ(two.parts_l(), 2);
  // A prime number of ranks on a grid too short for it along k.
  const Decomposition prime = Decomposition::choose(4, 100, 5);
  EXPECT_EQ(prime.parts_k(), 1);
  EXPECT_EQ(prime.parts_l(), 5);
}

TEST(Decomposition, BlocksTileTheGridAndDifferByAtMostOneNode) {
  for (const auto& [parts_k, parts_l] : {std::pair{1, 1}, {3, 2}, {2, 3}, {6, 1}, {1, 6}, {5, 4}}) {
    const Decomposition d = Decomposition::with_parts(37, 23, parts_k, parts_l);
    ASSERT_EQ(d.ranks(), parts_k * parts_l);
    std::multiset<std::pair<int, int>> owned;
    std::set<int> widths, heights;
    for (int rank = 0; rank < d.ranks(); ++rank) {
      const Block b = d.block(rank, MPI_COMM_SELF);
      widths.insert(b.owned_k());
      heights.insert(b.owned_l());
      for (int l = b.l0; l < b.l1; ++l)
        for (int k = b.k0; k < b.k1; ++k) owned.insert({k, l});
      EXPECT_EQ(d.rank_of(rank % parts_k, rank / parts_k), rank);
    }
    EXPECT_EQ(owned.size(), 37u * 23u) << parts_k << " x " << parts_l;
    const std::set<std::pair<int, int>> distinct(owned.begin(), owned.end());
    EXPECT_EQ(distinct.size(), owned.size()) << "a node owned twice";
    EXPECT_LE(*widths.rbegin() - *widths.begin(), 1);
    EXPECT_LE(*heights.rbegin() - *heights.begin(), 1);
  }
}

TEST(Decomposition, RefusesBlocksNarrowerThanTheGhostWidth) {
  EXPECT_THROW(Decomposition::choose(3, 6, 4), DecompositionError);
  EXPECT_THROW(Decomposition::with_parts(10, 10, 6, 1), DecompositionError);  // 1-node blocks
  EXPECT_NO_THROW(Decomposition::with_parts(10, 10, 5, 1));                  // 2-node blocks
  try {
    Decomposition::choose(3, 3, 4);
    FAIL();
  } catch (const DecompositionError& e) {
    EXPECT_NE(std::string(e.what()).find("3 x 3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cosserat
