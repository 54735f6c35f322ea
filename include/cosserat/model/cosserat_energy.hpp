#pragma once
// The Cosserat surface in its energy forms (docs/equations.md, "Energy quadrature"): the stored
// energy of the discrete strains summed over the grid, and the internal force as its exact
// negative gradient.

#include <array>
#include <functional>
#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/threads.hpp"
#include "cosserat/grid/wide_copy.hpp"
#include "cosserat/model/cosserat_model.hpp"
#include "cosserat/model/node_hessian.hpp"
#include "cosserat/model/node_mass.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat {

namespace energy {

// The constants of the interior gradient (docs/equations.md §2.5, "Nodal quadrature"), with every
// grid factor folded in so that a node multiplies as little as it can. With i = 11, 12, 22,
// H_i = h₁², h₁h₂, h₂², the weight w_i = 1, 2, 1 of the (1, 2) terms in Σ_αβ, the forward edges
// D₁ = r(k+1, l) − r and D₂ = r(k, l+1) − r, and β_i = n · Δ_i with Δ_i = H_i r_,αβ (the
// stencil's differences before its division):
//   ε_i = e_i (D_α · D_β) − ½A_i,   κ_i = −β_i / H_i,
//   ν_i = area (2Φ_i ε_i + Θ_i κ_i) / H_i      (∂E_p/∂(D_α · D_β), times 2 for i = 11, 22),
//   μ_i = ∂E_p/∂β_i = −area w_i (2Ψ_i κ_i + Θ_i ε_i) / H_i.
// Built once from the moduli by interior_coefficients in cosserat_energy.cpp.
//
// The thresholds below which a vector the normals are made from counts as crushed
// (docs/equations.md, "Crushed cells"): δ and 1/δ².
struct Crush {
  double delta, inverse_delta2;
};

struct InteriorCoefficients {
  Sym2 e;          // 1/(2H_i)
  Sym2 half_A;     // ½A_i
  Sym2 nu_eps;     // ν_i = nu_eps_i ε_i + nu_beta_i β_i
  Sym2 nu_beta;
  Sym2 mu_beta;    // μ_i = mu_beta_i β_i + mu_eps_i ε_i
  Sym2 mu_eps;
  Crush corner;  // c = E × F of a corner triangle
  Crush cell;    // c = t₁ × t₂ of a cell (the trapezoidal twist)
  Crush sum;     // s, the sum of a node's corner units
};

// The terms a material switches off: ξ = 0 and φ = 0 leave no curvature term at all (Ψ = Θ =
// 0), φ = 0 no coupling (Θ = 0); a kernel built without them skips their arithmetic. Skipping
// is exact: every skipped product has a zero factor.
struct Terms {
  bool bending;   // Ψ or Θ nonzero: κ enters E
  bool coupling;  // Θ nonzero
};

}  // namespace energy

// How the stored energy is summed (docs/equations.md, "Energy quadrature"). trapezoidal: each
// strain where its difference is centred (stretch on its edge, shear and twist on the cell,
// bending at the node), with the trapezoidal rule's weights and masses from the dual areas;
// the default. nodal: every strain at its node from one-sided differences, every node weighted
// alike (docs/equations.md, "Nodal quadrature"; the default until 2026-12).
enum class Quadrature { trapezoidal, nodal };

class CosseratEnergy {
 public:
  CosseratEnergy(const Block& block, double h1, double h2, const RestState& rest,
                 Quadrature quadrature = Quadrature::trapezoidal);

  Quadrature quadrature() const { return quadrature_; }
  // The lumped masses that go with the quadrature, for a node of all four neighbours carrying
  // `interior` kg.
  NodeMass node_mass(double interior) const {
    return {interior, block_->m, block_->n, quadrature_ == Quadrature::trapezoidal};
  }

  // −∂E/∂r at every owned node, in newtons. Each node's energy depends on the 3 × 3 box around
  // it, so the force at q gathers the gradients of the nine nodes around q, always in the same
  // order: any decomposition gives the same bits. Reads positions two nodes beyond the owned
  // range (ghosts must be current). With `normals`, also the unit normal n of every owned node.
  void internal_force(const Field<Vec3>& positions, Field<Vec3>& force,
                      Field<Vec3>* normals = nullptr);

  // The force as an acceleration: inverse_mass · f / w + offset, w = node_mass(…).weight(k, l),
  // so that the step's f/m + g takes no sweep of its own (inverse_mass = 1/interior mass).
  void acceleration(const Field<Vec3>& positions, Field<Vec3>& a, Field<Vec3>* normals,
                    double inverse_mass, const Vec3& offset);

  // A finished row l of acceleration's a, as three component arrays over the owned columns
  // (column b.k0 first), handed over while it is still in cache instead of written to a field;
  // the consumer may change them. Called from the thread that owns the row, once per owned row,
  // in ascending order within a thread.
  using RowConsumer = std::function<void(int l, double* x, double* y, double* z)>;
  void internal_force_rows(const Field<Vec3>& positions, double inverse_mass,
                           const Vec3& offset, const RowConsumer& consume);

  // This block's share of E (J): the energies of the nodes it owns, summed row by row in order.
  // Reads the ghosts one node beyond the owned range.
  double block_energy(const Field<Vec3>& positions) const;

  // The stored energy per unit rest area (J/m²) at every owned node: in the trapezoidal
  // quadrature the node's bending terms, half of each edge and a quarter of each cell around
  // it, over its dual area; in the nodal one E_p/(h₁h₂). Either way Σ density · dual area = E.
  // Reads the ghosts one node beyond the owned range.
  void energy_density(const Field<Vec3>& positions, Field<double>& density) const;

  // The terms of E_p by where they live (trapezoidal quadrature), each with its weight: the
  // node's bending terms, the edges to (k+1, l) and (k, l+1), the cell (k+½, l+½).
  struct Parts {
    double node = 0.0, edge1 = 0.0, edge2 = 0.0, cell = 0.0;
  };

  // E_p of one node — in the trapezoidal quadrature the terms at the node, on its forward edges
  // and on its forward cell, so that each term of E belongs to one node — and, with `gradient`,
  // ∂E_p/∂r at the nodes of its 3 × 3 box, indexed 3 (dl + 1) + (dk + 1) for the node
  // (k + dk, l + dl). Public for the gradient tests.
  using StencilGradient = std::array<Vec3, 9>;
  double node_energy(const Field<Vec3>& positions, int k, int l, StencilGradient* gradient,
                     Vec3* normal = nullptr, Parts* parts = nullptr) const;

  // ∂²E_p/∂r∂r over p's 3 × 3 box (NodeHessian): the exact derivative of node_energy's
  // gradient, by forward-mode differentiation of the same code (docs/semi-implicit.md, "The
  // Jacobian"); trapezoidal quadrature only.
  void node_hessian(const Field<Vec3>& positions, int k, int l, NodeHessian& hessian) const;

  // The threads' bands of owned rows, which follow the threads' speeds. Public for the tests that
  // hold the forces to the same bits on every split.
  RowBalance& row_balance() { return balance_; }

  // Whether the interior rows run the kernel's 256-bit copy: a portable x86-64 build (the
  // release preset) carries one compiled for AVX2 and takes it where the CPU has AVX2. It
  // computes the same bits, and the step runs 2.4-2.7 times as fast (docs/kernel.md, "The
  // run-time wide kernel"). Settable for the test that holds the two copies to the same bits;
  // where the build has no such copy or the CPU no AVX2 (wide_copies_available()), always
  // false.
  bool wide_kernel() const { return wide_; }
  void set_wide_kernel(bool wide) { wide_ = wide && wide_copies_available(); }

 private:
  // One thread's row buffers (internal_force): three rows of positions and of forces, and one
  // row of gradients (nine slots) and normals, each component a contiguous array of `width`.
  struct RowScratch {
    int width = 0;
    std::vector<double> positions, gradient, force, normal;
    int position_row[3] = {-1, -1, -1};  // the grid row each positions slot holds
    void resize(int columns);
  };

  void load_row(const Field<Vec3>& positions, int l, int k_base, int k_end, RowScratch& s) const;
  template <bool Trapezoidal, bool Bending, bool Coupling, bool Normal>
  void interior_row(int l, int ka, int kb, int k_base, RowScratch& s) const;
  // interior_row compiled for AVX2, where the build's baseline lacks it (cosserat_energy.cpp).
  template <bool Trapezoidal, bool Bending, bool Coupling, bool Normal>
  void interior_row_wide(int l, int ka, int kb, int k_base, RowScratch& s) const;
  void border_node(const Field<Vec3>& positions, int k, int l, int k_base, RowScratch& s) const;
  template <bool Trapezoidal, bool Bending, bool Coupling, bool Normal>
  void band(const Field<Vec3>& positions, Field<Vec3>* normals, double scale,
            const Vec3& offset, bool per_mass, const RowConsumer& consume, int qa, int qb,
            RowScratch& s) const;
  template <bool Trapezoidal>
  void bands_of(const Field<Vec3>& positions, Field<Vec3>* normals, double scale,
                const Vec3& offset, bool per_mass, const RowConsumer& consume, int qa, int qb,
                RowScratch& s) const;
  void all_bands(const Field<Vec3>& positions, Field<Vec3>* normals, double scale,
                 const Vec3& offset, bool per_mass, const RowConsumer& consume);
  void acceleration_or_force(const Field<Vec3>& positions, Field<Vec3>& out,
                             Field<Vec3>* normals, double scale, const Vec3& offset,
                             bool per_mass);
  double nodal_energy(const Field<Vec3>& positions, int k, int l, StencilGradient* gradient,
                      Vec3* normal) const;
  // Without `node_terms`, the edges and the cell alone (they read no normal of p).
  double trapezoidal_energy(const Field<Vec3>& positions, int k, int l,
                            StencilGradient* gradient, Vec3* normal, Parts* parts,
                            bool node_terms = true) const;
  // trapezoidal_energy for positions `at(dk, dl)` around (k, l) of type V: Vec3, or the dual
  // numbers of node_hessian. Defined and instantiated in cosserat_energy.cpp.
  template <class V, class At>
  auto trapezoidal_terms(const At& at, int k, int l, std::array<V, 9>* gradient, V* normal,
                         Parts* parts, bool node_terms) const;
  // node_hessian of any node, seeded with every slot of its box (cosserat_energy.cpp).
  void stencil_hessian(const Field<Vec3>& positions, int k, int l, NodeHessian& hessian) const;
  // node_hessian of an interior node, through the kernel's trapezoidal_gradient.
  template <bool Bending, bool Coupling>
  void interior_hessian(const Field<Vec3>& positions, int k, int l, NodeHessian& hessian) const;

  const Block* block_;
  double h1_, h2_;
  RestState rest_;
  Quadrature quadrature_;
  energy::InteriorCoefficients interior_;
  energy::Terms terms_;
  std::vector<RowScratch> scratch_;  // one per thread, sized by the first internal_force
  RowBalance balance_;                // the threads' bands of owned rows
  bool wide_;                         // interior rows through interior_row_wide
};

}  // namespace cosserat
