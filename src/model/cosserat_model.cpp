#include "cosserat/model/cosserat_model.hpp"

#include <algorithm>

#include "cosserat/model/surface_measures.hpp"
#include "surface_geometry.hpp"

// Reach of the stencil (docs/equations.md §2.4), which sizes the ghost layer (kGhostWidth = 2):
//  - resultants at p read positions in the 3x3 box around p;
//  - traction T^1 at p reads resultants at p, p+e1 (∂_1 M^11) and p-e2 (∂_2 M^12);
//    T^2 at p reads resultants at p, p+e2 and p-e1;
//  - the force at p reads T^a at p and p-e_a.
// So resultants are needed on the owned range grown by one node on every side (p-e1-e2
// included), and positions on the owned range grown by two: two ghost rings, because the
// intermediates (resultants, tractions) are computed redundantly on the ring rather than
// exchanged.

namespace cosserat {

namespace {

// Φ, Ψ, Θ^{ab} = c_ab (A^aa A^bb + 2 (A^ab)^2), no summation (docs/equations.md §1).
Sym2 contravariant(const Sym2& c, const Sym2& Ainv) {
  const double A11 = Ainv[0], A12 = Ainv[1], A22 = Ainv[2];
  return {c[0] * (A11 * A11 + 2.0 * A11 * A11), c[1] * (A11 * A22 + 2.0 * A12 * A12),
          c[2] * (A22 * A22 + 2.0 * A22 * A22)};
}

}  // namespace

RestState flat_rest_state(const Material& material, const Vec3& u, const Vec3& v) {
  RestState rest;
  rest.metric = flat_metric(u, v);
  const double det = rest.metric[0] * rest.metric[2] - rest.metric[1] * rest.metric[1];
  rest.inverse_metric = {rest.metric[2] / det, -rest.metric[1] / det, rest.metric[0] / det};
  rest.Phi = contravariant(material.zeta, rest.inverse_metric);
  rest.Psi = contravariant(material.xi, rest.inverse_metric);
  rest.Theta = contravariant(material.phi, rest.inverse_metric);
  return rest;
}

CosseratModel::CosseratModel(const Block& block, double h1, double h2, const RestState& rest,
                             Borders borders)
    : block_(&block),
      h1_(h1),
      h2_(h2),
      rest_(rest),
      symmetric_borders_(borders == Borders::symmetric),
      resultants_(block),
      traction1_(block),
      traction2_(block) {}

namespace {

// N*^{αβ} = 2Φ^{αβ} ε_αβ + Θ^{αβ} κ_αβ and M^{αβ} = 2Ψ^{αβ} κ_αβ + Θ^{αβ} ε_αβ with f = 1 (§1:
// the corrected form of M), each as {11, 12, 22}.
struct Resultants {
  Sym2 N_star, M;
};

inline Resultants constitutive(const RestState& rest, const Sym2& epsilon, const Sym2& kappa) {
  const Sym2 &Phi = rest.Phi, &Psi = rest.Psi, &Theta = rest.Theta;
  return {{2.0 * Phi[0] * epsilon[0] + Theta[0] * kappa[0],
           2.0 * Phi[1] * epsilon[1] + Theta[1] * kappa[1],
           2.0 * Phi[2] * epsilon[2] + Theta[2] * kappa[2]},
          {2.0 * Psi[0] * kappa[0] + Theta[0] * epsilon[0],
           2.0 * Psi[1] * kappa[1] + Theta[1] * epsilon[1],
           2.0 * Psi[2] * kappa[2] + Theta[2] * epsilon[2]}};
}

// §2.3 rules 1–2 on a border node: shear lives on cells, so the far borders carry none; a free
// edge carries no bending moment about itself.
inline void symmetric_border_rules(const geometry::Neighbours& p, Resultants& s) {
  if (!p.right || !p.up) {
    s.N_star[1] = 0.0;
    s.M[1] = 0.0;
  }
  if (!p.left || !p.right) s.M[0] = 0.0;
  if (!p.down || !p.up) s.M[2] = 0.0;
}

// Σ_β Σ_ρ (Γ^α_βρ M^{ρβ} + Γ^β_βρ M^{αρ}), the Γ·M part of N^{3α} (§1), for α = 1 and 2.
inline double shear_christoffel1(const geometry::Christoffel& G, const Sym2& M) {
  return G.G1_11 * M[0] + 2.0 * G.G1_12 * M[1] + G.G1_22 * M[2] + G.trace1() * M[0] +
         G.trace2() * M[1];
}
inline double shear_christoffel2(const geometry::Christoffel& G, const Sym2& M) {
  return G.G2_11 * M[0] + 2.0 * G.G2_12 * M[1] + G.G2_22 * M[2] + G.trace1() * M[1] +
         G.trace2() * M[2];
}

}  // namespace

// Geometry and stress resultants of node (k, l): docs/equations.md §2.1 (with the §2.3 border rules
// when they are on) and the constitutive law of §1 with f = 1.
void CosseratModel::compute_resultants(const Field<Vec3>& R, int k, int l) {
  using namespace geometry;
  const Neighbours p = neighbours(*block_, k, l);
  const Tangents a = tangents(R, k, l, p, h1_, h2_);
  const Vec3 n = unit_normal(R, k, l, p);
  const SecondDerivatives d = second_derivatives(R, k, l, p, h1_, h2_);
  const Metric g = metric(a);
  const Sym2 b = curvature(n, d);
  const Weingarten w = weingarten(g.upper, b);
  const Christoffel G = christoffel(d, reciprocal_basis(a, g.upper));

  Resultants s = constitutive(rest_, membrane_strain(g.lower, rest_.metric), bending_strain(b));
  if (symmetric_borders_ && !p.interior()) symmetric_border_rules(p, s);
  const double N11s = s.N_star[0], N12s = s.N_star[1], N22s = s.N_star[2];
  const double M11 = s.M[0], M12 = s.M[1], M22 = s.M[2];

  NodeResultants& out = resultants_(k, l);
  out.a1 = a.a1;
  out.a2 = a.a2;
  out.normal = n;
  // N^{αβ} = N*^{αβ} − Σ_λ b^α_λ M^{βλ} (§1).
  out.N11 = N11s - (w.w11 * M11 + w.w12 * M12);
  out.N12 = N12s - (w.w11 * M12 + w.w12 * M22);
  out.N21 = N12s - (w.w21 * M11 + w.w22 * M12);
  out.N22 = N22s - (w.w21 * M12 + w.w22 * M22);
  out.M11 = M11;
  out.M12 = M12;
  out.M22 = M22;
  // §2.3 rule 3 keeps Γ·M off the borders, where the substituted second derivatives make Γ
  // meaningless.
  const bool drop_christoffel = symmetric_borders_ && !p.interior();
  out.shear_christoffel1 = drop_christoffel ? 0.0 : shear_christoffel1(G, s.M);
  out.shear_christoffel2 = drop_christoffel ? 0.0 : shear_christoffel2(G, s.M);
  out.christoffel_trace1 = G.trace1();
  out.christoffel_trace2 = G.trace2();
}

// D⁻ of the twisting moment M^{12} on the near border (B1 or B2), where the cell before p is
// missing. The symmetric rules extend §2.3 rule 1 there: the missing cell carries no twisting
// moment, so D⁻ M = (M[p] − 0)/h. docs/equations.md §2.2's D⁺ instead (kept for "published") makes
// the rest-state Jacobian non-symmetric along B1 and B2 (3e-3 relative on a 12 x 12 sheet, against
// 2e-6 with this rule; docs/model.md).
double CosseratModel::near_border_difference(double M_here, double M_next, double h) const {
  return symmetric_borders_ ? M_here / h : (M_next - M_here) / h;
}

// The Γ·M part of the transverse shear on the face between p and p + e_a. Both derivative
// terms of N^{3a} are centred on that face (D⁺_a M^{aa} between the nodes, D⁻_b M^{ab} between
// two cells), so the symmetric rules put Γ·M there too, as the mean of the two nodes. Taken at
// p alone (docs/equations.md §2.2, kept for "published") it lets a sheet folded sharply over a held
// line blow up whatever the step (docs/model.md, "Known limits": 9 of 23 such runs, against
// 1 of 23 with the face value).
double CosseratModel::on_face(double at_node, double at_next_node) const {
  return symmetric_borders_ ? 0.5 * (at_node + at_next_node) : at_node;
}

// Traction on the 1-face, T^1 = N^{11} a_1 + N^{21} a_2 + N^{31} n, with the transverse shear
// N^{31} = D⁺_1 M^{11} + D⁻_2 M^{12} + Γ·M (§2.2; D⁻_1 on the far border, and the near border
// as near_border_difference says).
Vec3 CosseratModel::traction1(int k, int l) const {
  const Block& b = *block_;
  const NodeResultants& p = resultants_(k, l);
  const double dM11 = k < b.m - 1 ? (resultants_(k + 1, l).M11 - p.M11) / h1_
                                  : (p.M11 - resultants_(k - 1, l).M11) / h1_;
  const double dM12 = l > 0 ? (p.M12 - resultants_(k, l - 1).M12) / h2_
                            : near_border_difference(p.M12, resultants_(k, l + 1).M12, h2_);
  const double christoffel =
      k < b.m - 1 ? on_face(p.shear_christoffel1, resultants_(k + 1, l).shear_christoffel1)
                  : p.shear_christoffel1;
  const double N31 = dM11 + dM12 + christoffel;
  return p.N11 * p.a1 + p.N21 * p.a2 + N31 * p.normal;
}

// T^2 = N^{12} a_1 + N^{22} a_2 + N^{32} n, N^{32} = D⁺_2 M^{22} + D⁻_1 M^{21} + Γ·M (§2.2).
Vec3 CosseratModel::traction2(int k, int l) const {
  const Block& b = *block_;
  const NodeResultants& p = resultants_(k, l);
  const double dM22 = l < b.n - 1 ? (resultants_(k, l + 1).M22 - p.M22) / h2_
                                  : (p.M22 - resultants_(k, l - 1).M22) / h2_;
  const double dM21 = k > 0 ? (p.M12 - resultants_(k - 1, l).M12) / h1_
                            : near_border_difference(p.M12, resultants_(k + 1, l).M12, h1_);
  const double christoffel =
      l < b.n - 1 ? on_face(p.shear_christoffel2, resultants_(k, l + 1).shear_christoffel2)
                  : p.shear_christoffel2;
  const double N32 = dM22 + dM21 + christoffel;
  return p.N12 * p.a1 + p.N22 * p.a2 + N32 * p.normal;
}

void CosseratModel::internal_force(const Field<Vec3>& r, Field<Vec3>& force,
                                   Field<Vec3>* normals) {
  const Block& b = *block_;
  // Resultants on the owned range grown by one node (clipped to the grid), tractions where
  // the divergence reads them: T^1 also at k0 − 1, T^2 also at l0 − 1.
  const int gk0 = std::max(b.k0 - 1, 0), gk1 = std::min(b.k1 + 1, b.m);
  const int gl0 = std::max(b.l0 - 1, 0), gl1 = std::min(b.l1 + 1, b.n);
  const int tk0 = std::max(b.k0 - 1, 0), tl0 = std::max(b.l0 - 1, 0);
  const double inv_h1 = 1.0 / h1_, inv_h2 = 1.0 / h2_;

#pragma omp parallel
  {
#pragma omp for schedule(static)
    for (int l = gl0; l < gl1; ++l)
      for (int k = gk0; k < gk1; ++k) compute_resultants(r, k, l);

#pragma omp for schedule(static)
    for (int l = tl0; l < b.l1; ++l)
      for (int k = tk0; k < b.k1; ++k) {
        if (l >= b.l0) traction1_(k, l) = traction1(k, l);
        if (k >= b.k0) traction2_(k, l) = traction2(k, l);
      }

    // Flux-form divergence with traction-free edges plus the Christoffel term (§2.2).
#pragma omp for schedule(static)
    for (int l = b.l0; l < b.l1; ++l) {
      for (int k = b.k0; k < b.k1; ++k) {
        const NodeResultants& p = resultants_(k, l);
        const Vec3 T1 = traction1_(k, l), T2 = traction2_(k, l);
        Vec3 f = p.christoffel_trace1 * T1 + p.christoffel_trace2 * T2;
        if (k < b.m - 1) f += inv_h1 * T1;
        if (k > 0) f -= inv_h1 * traction1_(k - 1, l);
        if (l < b.n - 1) f += inv_h2 * T2;
        if (l > 0) f -= inv_h2 * traction2_(k, l - 1);
        force(k, l) = f;
        if (normals != nullptr) (*normals)(k, l) = p.normal;
      }
    }
  }
}


}  // namespace cosserat
