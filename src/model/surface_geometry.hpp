#pragma once
// Per-node geometry of the discrete surface (docs/equations.md §1 quantities, §2.1 stencils), one
// small inline function per quantity, in docs/equations.md's symbols. Private to the model module:
// the force kernels compose these, so the arithmetic of a node is written once.

#include "cosserat/grid/block.hpp"
#include "cosserat/model/material.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat::geometry {

// Which grid neighbours of p exist: the border rules of §2.1 test the global index, never the
// block edge (docs/design.md, principle 1).
struct Neighbours {
  bool left, right, down, up;  // p − e1, p + e1, p − e2, p + e2
  bool interior() const { return left && right && down && up; }
};

inline Neighbours neighbours(const Block& b, int k, int l) {
  return {k > 0, k < b.m - 1, l > 0, l < b.n - 1};
}

// a_α = D⁺_α r, D⁻_α on the far border in that direction (§2.1 rule 1).
struct Tangents {
  Vec3 a1, a2;
};

inline Tangents tangents(const Field<Vec3>& R, int k, int l, const Neighbours& p, double h1,
                         double h2) {
  const Vec3 r = R(k, l);
  return {p.right ? (R(k + 1, l) - r) / h1 : (r - R(k - 1, l)) / h1,
          p.up ? (R(k, l + 1) - r) / h2 : (r - R(k, l - 1)) / h2};
}

// n: the normalised sum of the unit normals of the corner triangles present (§2.1 rule 2).
inline Vec3 unit_normal(const Field<Vec3>& R, int k, int l, const Neighbours& p) {
  const Vec3 r = R(k, l);
  Vec3 sum;
  auto add_corner = [&](const Vec3& e, const Vec3& f) {
    const Vec3 c = cross(e - r, f - r);
    sum += c / norm(c);
  };
  if (p.right && p.up) add_corner(R(k + 1, l), R(k, l + 1));
  if (p.up && p.left) add_corner(R(k, l + 1), R(k - 1, l));
  if (p.left && p.down) add_corner(R(k - 1, l), R(k, l - 1));
  if (p.down && p.right) add_corner(R(k, l - 1), R(k + 1, l));
  return sum / norm(sum);
}

// r_,αβ (§2.1 rule 3): the cross derivative on the nearest cell that exists (X₊₊ inside, X₋₊
// on B3, X₊₋ on B4, X₋₋ at C3); D_αα where both neighbours in α exist, else r_,12.
struct SecondDerivatives {
  Vec3 r11, r12, r22;
};

inline SecondDerivatives second_derivatives(const Field<Vec3>& R, int k, int l,
                                            const Neighbours& p, double h1, double h2) {
  const Vec3 r = R(k, l);
  const int kc = p.right ? k : k - 1;
  const int lc = p.up ? l : l - 1;
  const Vec3 r12 =
      (R(kc + 1, lc + 1) - R(kc + 1, lc) - R(kc, lc + 1) + R(kc, lc)) / (h1 * h2);
  const Vec3 r11 = p.left && p.right ? (R(k + 1, l) - 2.0 * r + R(k - 1, l)) / (h1 * h1) : r12;
  const Vec3 r22 = p.down && p.up ? (R(k, l + 1) - 2.0 * r + R(k, l - 1)) / (h2 * h2) : r12;
  return {r11, r12, r22};
}

// a_αβ = a_α · a_β and its inverse a^{αβ} (§1), each as {11, 12, 22}.
struct Metric {
  Sym2 lower, upper;
};

inline Metric metric(const Tangents& t) {
  const double a11 = dot(t.a1, t.a1), a12 = dot(t.a1, t.a2), a22 = dot(t.a2, t.a2);
  const double inverse_det = 1.0 / (a11 * a22 - a12 * a12);
  return {{a11, a12, a22}, {a22 * inverse_det, -a12 * inverse_det, a11 * inverse_det}};
}

// a^α = a^{αβ} a_β.
struct ReciprocalBasis {
  Vec3 a1, a2;
};

inline ReciprocalBasis reciprocal_basis(const Tangents& t, const Sym2& upper) {
  return {upper[0] * t.a1 + upper[1] * t.a2, upper[1] * t.a1 + upper[2] * t.a2};
}

// b_αβ = n · r_,αβ.
inline Sym2 curvature(const Vec3& n, const SecondDerivatives& d) {
  return {dot(n, d.r11), dot(n, d.r12), dot(n, d.r22)};
}

// b^α_λ = a^{αρ} b_ρλ, as {b¹₁, b¹₂, b²₁, b²₂}.
struct Weingarten {
  double w11, w12, w21, w22;
};

inline Weingarten weingarten(const Sym2& upper, const Sym2& b) {
  return {upper[0] * b[0] + upper[1] * b[1], upper[0] * b[1] + upper[1] * b[2],
          upper[1] * b[0] + upper[2] * b[1], upper[1] * b[1] + upper[2] * b[2]};
}

// ε_αβ = ½ (a_αβ − A_αβ).
inline Sym2 membrane_strain(const Sym2& a, const Sym2& A) {
  return {0.5 * (a[0] - A[0]), 0.5 * (a[1] - A[1]), 0.5 * (a[2] - A[2])};
}

// κ_αβ = −(b_αβ − B_αβ), B = 0 for a flat rest sheet.
inline Sym2 bending_strain(const Sym2& b) { return {-b[0], -b[1], -b[2]}; }

// Γ^λ_αβ = r_,αβ · a^λ, as Γ^λ_11, Γ^λ_12, Γ^λ_22 for λ = 1, 2.
struct Christoffel {
  double G1_11, G2_11, G1_12, G2_12, G1_22, G2_22;
  double trace1() const { return G1_11 + G2_12; }  // Σ_λ Γ^λ_1λ
  double trace2() const { return G1_12 + G2_22; }  // Σ_λ Γ^λ_2λ
};

inline Christoffel christoffel(const SecondDerivatives& d, const ReciprocalBasis& recip) {
  return {dot(d.r11, recip.a1), dot(d.r11, recip.a2), dot(d.r12, recip.a1),
          dot(d.r12, recip.a2), dot(d.r22, recip.a1), dot(d.r22, recip.a2)};
}

}  // namespace cosserat::geometry
