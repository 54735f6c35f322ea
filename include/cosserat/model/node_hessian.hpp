#pragma once
// The Hessian of one node's energy E_p over its 3 × 3 box (docs/semi-implicit.md, "The
// Jacobian"), as the energy form gives it and the semi-implicit baseline assembles it.

#include <array>

namespace cosserat {

struct NodeHessian {
  // ∂²E_p/∂r_a∂r_b: component i of slot a and j of slot b at (3a + i) · 27 + 3b + j, the slots
  // 3 (dl + 1) + (dk + 1) of the nodes (k + dk, l + dl) around p = (k, l). The rows and
  // columns of the slots E_p does not read are zero.
  std::array<double, 27 * 27> entries;
  // The slots E_p reads, ascending: six around a node inside the grid, up to nine on its
  // borders, only slots inside the grid.
  int read[9];
  int count;
};

}  // namespace cosserat
