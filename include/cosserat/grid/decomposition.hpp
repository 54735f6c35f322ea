#pragma once
// The 2D Cartesian split of the m x n grid over the ranks of a communicator (docs/design.md,
// principle 1): parts_k blocks along x1 (k) times parts_l along x2 (l), uneven by at most one
// node, rank = i + parts_k j for the block (i, j).

#include <mpi.h>

#include <stdexcept>
#include <vector>

#include "cosserat/grid/block.hpp"

namespace cosserat {

// The grid cannot be split as asked: bad input, reported before any work.
class DecompositionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Decomposition {
 public:
  // The split of an m x n grid over `ranks` that cuts the fewest node pairs (the halo volume,
  // (parts_k − 1) n + (parts_l − 1) m), among those whose blocks are at least kGhostWidth
  // nodes wide in every split direction; ties go to fewer parts along k, whose halos are
  // contiguous rows. Throws DecompositionError when no split fits.
  static Decomposition choose(int m, int n, int ranks);

  // Exactly parts_k x parts_l blocks; throws DecompositionError if a block is too narrow.
  static Decomposition with_parts(int m, int n, int parts_k, int parts_l);

  int parts_k() const { return static_cast<int>(k_cuts_.size()) - 1; }
  int parts_l() const { return static_cast<int>(l_cuts_.size()) - 1; }
  int ranks() const { return parts_k() * parts_l(); }

  // Nodes per block along k (one entry per part) and along l: PETSc's DMDA ownership ranges.
  std::vector<int> widths_k() const;
  std::vector<int> widths_l() const;

  // The block of `rank`; the communicator must have ranks() ranks.
  Block block(int rank, MPI_Comm comm) const;

  // Rank of block (i, j), or MPI_PROC_NULL outside the grid of blocks.
  int rank_of(int i, int j) const;

 private:
  Decomposition(int m, int n, int parts_k, int parts_l);

  int m_, n_;
  std::vector<int> k_cuts_, l_cuts_;  // block (i, j) owns [k_cuts_[i], k_cuts_[i+1]) x ...
};

}  // namespace cosserat
