#pragma once
// The Cosserat surface in its energy form (MODEL.md §2.5): the stored energy of the strains of
// §2.1, summed over the nodes, and the internal force as its exact negative gradient.

#include <array>

#include "cosserat/grid/block.hpp"
#include "cosserat/model/cosserat_model.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat {

class CosseratEnergy {
 public:
  CosseratEnergy(const Block& block, double h1, double h2, const RestState& rest);

  // −∂E/∂r at every owned node, in newtons. Each node's energy depends on the 3 × 3 box around
  // it, so the force at q gathers the gradients of the nine nodes around q, always in the same
  // order: any decomposition gives the same bits. Reads positions two nodes beyond the owned
  // range (ghosts must be current). With `normals`, also the unit normal n of every owned node.
  void internal_force(const Field<Vec3>& positions, Field<Vec3>& force,
                      Field<Vec3>* normals = nullptr);

  // This block's share of E (J): the energies of the nodes it owns, summed row by row in order.
  // Reads the ghosts one node beyond the owned range.
  double block_energy(const Field<Vec3>& positions) const;

  // E_p of one node and, with `gradient`, ∂E_p/∂r at the nodes of its 3 × 3 box, indexed
  // 3 (dl + 1) + (dk + 1) for the node (k + dk, l + dl). Public for the gradient tests.
  using StencilGradient = std::array<Vec3, 9>;
  double node_energy(const Field<Vec3>& positions, int k, int l, StencilGradient* gradient,
                     Vec3* normal = nullptr) const;

 private:
  const Block* block_;
  double h1_, h2_;
  RestState rest_;
  Field<StencilGradient> gradient_;  // allocated by the first internal_force
  bool has_gradient_field_ = false;
};

}  // namespace cosserat
