#include "cosserat/model/cosserat_model.hpp"

#include <algorithm>

// Reach of the stencil (MODEL.md §2.4), which sizes the ghost layer (kGhostWidth = 2):
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

// Φ, Ψ, Θ^{ab} = c_ab (A^aa A^bb + 2 (A^ab)^2), no summation (MODEL.md §1).
Sym2 contravariant(const Sym2& c, const Sym2& Ainv) {
  const double A11 = Ainv[0], A12 = Ainv[1], A22 = Ainv[2];
  return {c[0] * (A11 * A11 + 2.0 * A11 * A11), c[1] * (A11 * A22 + 2.0 * A12 * A12),
          c[2] * (A22 * A22 + 2.0 * A22 * A22)};
}

}  // namespace

RestState flat_rest_state(const Material& material, const Vec3& u, const Vec3& v) {
  RestState rest;
  rest.metric = {dot(u, u), dot(u, v), dot(v, v)};
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

// Geometry and stress resultants of node (k, l): MODEL.md §2.1 (with the §2.3 border rules
// when they are on) and the constitutive law of §1 with f = 1.
void CosseratModel::compute_resultants(const Field<Vec3>& R, int k, int l) {
  const Block& b = *block_;
  const bool has_left = k > 0, has_right = k < b.m - 1;
  const bool has_down = l > 0, has_up = l < b.n - 1;
  const double h1 = h1_, h2 = h2_;
  const Vec3 r = R(k, l);

  // Tangents: forward differences, backward on the far border (§2.1 rule 1).
  const Vec3 a1 = has_right ? (R(k + 1, l) - r) / h1 : (r - R(k - 1, l)) / h1;
  const Vec3 a2 = has_up ? (R(k, l + 1) - r) / h2 : (r - R(k, l - 1)) / h2;

  // Normal: normalised sum of the unit normals of the corner triangles present (§2.1 rule 2).
  Vec3 normal_sum;
  auto add_corner = [&](const Vec3& e, const Vec3& f) {
    const Vec3 c = cross(e - r, f - r);
    normal_sum += c / norm(c);
  };
  if (has_right && has_up) add_corner(R(k + 1, l), R(k, l + 1));
  if (has_up && has_left) add_corner(R(k, l + 1), R(k - 1, l));
  if (has_left && has_down) add_corner(R(k - 1, l), R(k, l - 1));
  if (has_down && has_right) add_corner(R(k, l - 1), R(k + 1, l));
  const Vec3 n = normal_sum / norm(normal_sum);

  // Cross derivative on the nearest cell that exists: X++ inside, X-+ on B3, X+- on B4, X-- at
  // C3 (§2.1 rule 3).
  const int kc = has_right ? k : k - 1;
  const int lc = has_up ? l : l - 1;
  const Vec3 r12 =
      (R(kc + 1, lc + 1) - R(kc + 1, lc) - R(kc, lc + 1) + R(kc, lc)) / (h1 * h2);
  const Vec3 r11 =
      has_left && has_right ? (R(k + 1, l) - 2.0 * r + R(k - 1, l)) / (h1 * h1) : r12;
  const Vec3 r22 = has_down && has_up ? (R(k, l + 1) - 2.0 * r + R(k, l - 1)) / (h2 * h2) : r12;

  // Metric, its inverse and the reciprocal basis (§1).
  const double g11 = dot(a1, a1), g12 = dot(a1, a2), g22 = dot(a2, a2);
  const double inv_det = 1.0 / (g11 * g22 - g12 * g12);
  const double gi11 = g22 * inv_det, gi12 = -g12 * inv_det, gi22 = g11 * inv_det;
  const Vec3 recip1 = gi11 * a1 + gi12 * a2;
  const Vec3 recip2 = gi12 * a1 + gi22 * a2;

  // Curvature b_ab and Weingarten map b^a_λ = a^{aρ} b_ρλ.
  const double b11 = dot(n, r11), b12 = dot(n, r12), b22 = dot(n, r22);
  const double w11 = gi11 * b11 + gi12 * b12, w12 = gi11 * b12 + gi12 * b22;
  const double w21 = gi12 * b11 + gi22 * b12, w22 = gi12 * b12 + gi22 * b22;

  // Strains: ε = ½(a − A), κ = −(b − B) with B = 0 for a flat rest sheet.
  const Sym2& A = rest_.metric;
  const double e11 = 0.5 * (g11 - A[0]), e12 = 0.5 * (g12 - A[1]), e22 = 0.5 * (g22 - A[2]);
  const double c11 = -b11, c12 = -b12, c22 = -b22;

  // Resultants N* and M (§1: M = 2Ψκ + Θε, the corrected form).
  const Sym2 &Phi = rest_.Phi, &Psi = rest_.Psi, &Theta = rest_.Theta;
  double Ns11 = 2.0 * Phi[0] * e11 + Theta[0] * c11;
  double Ns12 = 2.0 * Phi[1] * e12 + Theta[1] * c12;
  double Ns22 = 2.0 * Phi[2] * e22 + Theta[2] * c22;
  double M11 = 2.0 * Psi[0] * c11 + Theta[0] * e11;
  double M12 = 2.0 * Psi[1] * c12 + Theta[1] * e12;
  double M22 = 2.0 * Psi[2] * c22 + Theta[2] * e22;

  // Christoffel symbols Γ^λ_ab = r_,ab · a^λ and their traces C_a = Σ_λ Γ^λ_aλ.
  const double G1_11 = dot(r11, recip1), G2_11 = dot(r11, recip2);
  const double G1_12 = dot(r12, recip1), G2_12 = dot(r12, recip2);
  const double G1_22 = dot(r22, recip1), G2_22 = dot(r22, recip2);
  const double trace1 = G1_11 + G2_12, trace2 = G1_12 + G2_22;

  const bool on_border = !(has_left && has_right && has_down && has_up);
  if (symmetric_borders_) {
    // §2.3 rule 1: shear lives on cells; the far borders have none.
    if (!has_right || !has_up) {
      Ns12 = 0.0;
      M12 = 0.0;
    }
    // §2.3 rule 2: a free edge carries no bending moment about itself.
    if (!has_left || !has_right) M11 = 0.0;
    if (!has_down || !has_up) M22 = 0.0;
  }

  NodeResultants& out = resultants_(k, l);
  out.a1 = a1;
  out.a2 = a2;
  out.normal = n;
  // N^{ab} = N*^{ab} − Σ_λ b^a_λ M^{bλ} (§1).
  out.N11 = Ns11 - (w11 * M11 + w12 * M12);
  out.N12 = Ns12 - (w11 * M12 + w12 * M22);
  out.N21 = Ns12 - (w21 * M11 + w22 * M12);
  out.N22 = Ns22 - (w21 * M12 + w22 * M22);
  out.M11 = M11;
  out.M12 = M12;
  out.M22 = M22;
  // Σ_b Σ_ρ (Γ^a_bρ M^{ρb} + Γ^b_bρ M^{aρ}) of N^{3a} (§1); §2.3 rule 3 keeps it off the
  // borders, where the substituted second derivatives make Γ meaningless.
  if (symmetric_borders_ && on_border) {
    out.shear_christoffel1 = 0.0;
    out.shear_christoffel2 = 0.0;
  } else {
    out.shear_christoffel1 =
        G1_11 * M11 + 2.0 * G1_12 * M12 + G1_22 * M22 + trace1 * M11 + trace2 * M12;
    out.shear_christoffel2 =
        G2_11 * M11 + 2.0 * G2_12 * M12 + G2_22 * M22 + trace1 * M12 + trace2 * M22;
  }
  out.christoffel_trace1 = trace1;
  out.christoffel_trace2 = trace2;
}

// D⁻ of the twisting moment M^{12} on the near border (B1 or B2), where the cell before p is
// missing. The symmetric rules extend §2.3 rule 1 there: the missing cell carries no twisting
// moment, so D⁻ M = (M[p] − 0)/h. MODEL.md §2.2's D⁺ instead (kept for "published") makes the
// rest-state Jacobian non-symmetric along B1 and B2 (3e-3 relative on a 12 x 12 sheet, against
// 2e-6 with this rule; docs/model.md).
double CosseratModel::near_border_difference(double M_here, double M_next, double h) const {
  return symmetric_borders_ ? M_here / h : (M_next - M_here) / h;
}

// The Γ·M part of the transverse shear on the face between p and p + e_a. Both derivative
// terms of N^{3a} are centred on that face (D⁺_a M^{aa} between the nodes, D⁻_b M^{ab} between
// two cells), so the symmetric rules put Γ·M there too, as the mean of the two nodes. Taken at
// p alone (MODEL.md §2.2, kept for "published") it lets a sheet folded sharply over a held
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

void CosseratModel::internal_force(const Field<Vec3>& r, Field<Vec3>& force) {
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
      }
    }
  }
}

QuantizedSum block_area(const Field<Vec3>& r, double quantum) {
  const Block& b = r.block();
  const int kend = std::min(b.k1, b.m - 1), lend = std::min(b.l1, b.n - 1);
  std::vector<QuantizedSum> row_area(static_cast<std::size_t>(std::max(lend - b.l0, 0)),
                                     QuantizedSum(quantum));
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < lend; ++l) {
    QuantizedSum sum(quantum);
    for (int k = b.k0; k < kend; ++k) {
      const Vec3 p = r(k, l), q = r(k + 1, l), s = r(k + 1, l + 1), t = r(k, l + 1);
      sum.add(0.5 * (norm(cross(q - p, s - p)) + norm(cross(s - p, t - p))));
    }
    row_area[static_cast<std::size_t>(l - b.l0)] = sum;
  }
  QuantizedSum area(quantum);
  for (const QuantizedSum& a : row_area) area.add(a);
  return area;
}

}  // namespace cosserat
