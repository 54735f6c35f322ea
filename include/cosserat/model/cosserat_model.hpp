#pragma once
// Internal force of the elastic Cosserat surface (docs/equations.md §1–§2) on a local block.


#include "cosserat/grid/block.hpp"
#include "cosserat/model/borders.hpp"
#include "cosserat/model/material.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat {


// Rest data of a flat sheet: uniform, so kept as constants (docs/equations.md §3).
struct RestState {
  Sym2 metric{};          // A_ab
  Sym2 inverse_metric{};  // A^ab
  Sym2 Phi{}, Psi{}, Theta{};  // docs/equations.md §1, from the material and A^ab
};

// Rest state of a flat sheet spanned by unit vectors u (x1) and v (x2).
RestState flat_rest_state(const Material& material, const Vec3& u, const Vec3& v);

// Everything the force phase needs from one node's geometry and resultants
// (docs/equations.md §2.1).
struct NodeResultants {
  Vec3 a1, a2, normal;
  double N11, N12, N21, N22;  // N^{ab}: membrane resultants less the curvature coupling
  double M11, M12, M22;       // bending moments M^{ab} (symmetric)
  double shear_christoffel1, shear_christoffel2;  // Γ·M part of N^{3a}
  double christoffel_trace1, christoffel_trace2;  // Σ_λ Γ^λ_aλ, for the divergence
};

class CosseratModel {
 public:
  CosseratModel(const Block& block, double h1, double h2, const RestState& rest,
                Borders borders);

  // Internal force per unit current area at every owned node, for the area factor f = 1:
  // the physical force is (S0/S) times this (docs/equations.md §1), so the internal acceleration is
  // this times S0/M whatever the current area. Reads positions up to two nodes outside the
  // owned range (ghosts must be current). With `normals`, also the unit normal n of every
  // owned node at these positions, which the fluid term needs (§1).
  void internal_force(const Field<Vec3>& positions, Field<Vec3>& force,
                      Field<Vec3>* normals = nullptr);

 private:
  void compute_resultants(const Field<Vec3>& r, int k, int l);
  double near_border_difference(double M_here, double M_next, double h) const;
  double on_face(double at_node, double at_next_node) const;
  Vec3 traction1(int k, int l) const;
  Vec3 traction2(int k, int l) const;

  const Block* block_;
  double h1_, h2_;
  RestState rest_;
  bool symmetric_borders_;
  Field<NodeResultants> resultants_;
  Field<Vec3> traction1_, traction2_;
};

}  // namespace cosserat
