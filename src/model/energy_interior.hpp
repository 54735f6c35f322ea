#pragma once
// ∂E_p/∂r of docs/equations.md §2.5 ("Nodal quadrature") for an interior node p — all four
// neighbours present, so every term of E_p exists (§2.3 rules 1–2 leave nothing out), the tangents
// are forward differences and the cross derivative is X₊₊ — written without a branch so that a loop
// over a row of such nodes vectorises. node_energy in cosserat_energy.cpp is the general form (any
// node, with the energy itself); this is its interior case, and a unit test holds the two together.
//
// An interior node's energy reads only its five-point cross and the node (k+1, l+1), so its
// gradient has six nonzero stencil slots; the other three of node_energy's nine are zero.

#include <cmath>
#include <utility>

#include "cosserat/grid/vec3.hpp"
#include "cosserat/model/cosserat_energy.hpp"

namespace cosserat::energy {

// The six nonzero slots of an interior node's gradient, ∂E_p/∂r_q for q = p + (dk, dl).
template <class V>
struct BasicInteriorGradient {
  V centre, right, left, up, down, up_right;  // (0,0) (1,0) (−1,0) (0,1) (0,−1) (1,1)
};
using InteriorGradient = BasicInteriorGradient<Vec3>;

// A vector c made a unit one, u = c/g, with g = |c| except where the triangle or cell c spans
// is crushed, |c| < δ (docs/equations.md, "Crushed cells"): there g = δ (3/8 + ¾y − ⅛y²),
// y = |c|²/δ², which meets |c| at δ with two matching derivatives and stays ≥ 3δ/8, so u
// shrinks to zero with the triangle instead of turning at a rate 1/|c| and the stiffness of the
// terms that read it stays bounded. Above δ the bits are those of c/|c|.
// V is Vec3, or the DualVec3 that differentiates the gradient for the Hessian (dual.hpp).
template <class V>
using ScalarOf = decltype(dot(std::declval<V>(), std::declval<V>()));

template <class V>
struct BasicUnit {
  V unit;
  ScalarOf<V> inverse;    // 1/g
  ScalarOf<V> rho;        // g g′(|c|)/|c|: 1 where c is not crushed
  ScalarOf<V> shortfall;  // 1 − |u|² = 1 − y/(g/δ)²: 0 where c is not crushed
};
using Unit = BasicUnit<Vec3>;

// Unbounded, u is c/|c| whether crushed or not, and `crushed` says whether c was: the kernel
// takes that form for a block of nodes where none is, and there the bits are the same, without
// the blend's arithmetic and selects (interior_row).
template <bool Bounded, class V>
[[gnu::always_inline]] inline BasicUnit<V> bounded_unit(const V& c, const Crush& crush,
                                                        long& crushed) {
  using S = ScalarOf<V>;
  using std::sqrt;
  const S length2 = dot(c, c);
  const S y = length2 * crush.inverse_delta2;
  const bool below = y < 1.0;
  if constexpr (!Bounded) {
    crushed |= below ? 1 : 0;
    const S inverse = 1.0 / sqrt(length2);
    return {c * inverse, inverse, S(1.0), S(0.0)};
  }
  const S blend = 0.375 + y * (0.75 - 0.125 * y);
  const S inverse = 1.0 / (below ? crush.delta * blend : sqrt(length2));
  return {c * inverse, inverse, below ? 0.5 * blend * (3.0 - y) : S(1.0),
          below ? 1.0 - y / (blend * blend) : S(0.0)};
}

template <class V>
[[gnu::always_inline]] inline BasicUnit<V> bounded_unit(const V& c, const Crush& crush) {
  long crushed = 0;
  return bounded_unit<true>(c, crush, crushed);
}

// Back through u = c/g: ∂/∂c of G_u · u.
template <class V>
[[gnu::always_inline]] inline V unit_gradient(const BasicUnit<V>& u, const V& G_u) {
  return (G_u - (u.rho * dot(G_u, u.unit)) * u.unit) * u.inverse;
}

// One corner triangle of §2.1 rule 2: edges E, F from p and the unit of c = E × F.
template <bool Bounded, class V>
[[gnu::always_inline]] inline BasicUnit<V> corner(const V& E, const V& F, const Crush& crush,
                                                  long& crushed) {
  return bounded_unit<Bounded>(cross(E, F), crush, crushed);
}

template <class V>
[[gnu::always_inline]] inline BasicUnit<V> corner(const V& E, const V& F, const Crush& crush) {
  long crushed = 0;
  return corner<true>(E, F, crush, crushed);
}

// Back through a corner's unit and c = E × F: ∂/∂r of G_s · u at its edges' far nodes; at p it
// is minus their sum.
template <class V>
struct BasicCornerGradient {
  V e, f;
};
using CornerGradient = BasicCornerGradient<Vec3>;

template <class V>
[[gnu::always_inline]] inline BasicCornerGradient<V> corner_gradient(const BasicUnit<V>& q,
                                                                     const V& E, const V& F,
                                                                     const V& G_s) {
  const V G_c = unit_gradient(q, G_s);
  // G_c · (δE × F) = δE · (F × G_c), G_c · (E × δF) = δF · (G_c × E).
  return {cross(F, G_c), cross(G_c, E)};
}

// The bending a node's crushed normal loses (docs/equations.md, "Creases folded flat"): where
// the sum s of its corner units is crushed, n = s/g(|s|) falls short of a unit by the shortfall
// λ = 1 − |n|², and ½ μ λ |Δ|² joins each ½ μ β² = ½ μ (n · Δ)², so that a crease folded flat,
// whose corner units cancel, keeps the bending ½ μ |Δ|² of its second difference rather than
// losing it as it closes. Adds its ∂/∂Δ_i = μ_i λ Δ_i and ∂/∂n = −Σ μ_i |Δ_i|² n, the latter
// only where λ is not zero: there |n| = 1 and λ does not vary, though the rounding of n would
// make the term a few ulps, which would change the bits of a sheet with nothing folded flat.
template <class S, class V>
[[gnu::always_inline]] inline void add_lost_bending(const InteriorCoefficients& c, const S& lost,
                                                    const V& n, const V& d11, const V& d22,
                                                    V& G_X11, V& G_X22, V& G_n) {
  const S m11 = c.mu_beta[0] * lost, m22 = c.mu_beta[2] * lost;
  G_X11 += m11 * d11;
  G_X22 += m22 * d22;
  const S squares = c.mu_beta[0] * dot(d11, d11) + c.mu_beta[2] * dot(d22, d22);
  G_n -= (lost > 0.0 ? squares : S(0.0)) * n;
}

// Positions of p = (k, l), its neighbours and (k+1, l+1); the unit normal n of p comes back in
// `normal` when the bending terms or the caller (Normal: the fluid term reads it) need it. The
// symbols are InteriorCoefficients'. Unbounded (Bounded false), every unit is c/|c| and
// `crushed` is set where one was crushed (bounded_unit).
template <bool Bending, bool Coupling, bool Normal, bool Bounded>
[[gnu::always_inline]] inline InteriorGradient interior_gradient(
    const InteriorCoefficients& c, const Vec3& r, const Vec3& r_right, const Vec3& r_left,
    const Vec3& r_up, const Vec3& r_down, const Vec3& r_up_right, Vec3& normal, long& crushed) {
  // ∂E_p/∂r at the five slots other than p, built up term by term.
  Vec3 g_right, g_left, g_up, g_down, g_up_right;
  // §2.1 rule 1: a_α = D_α / h_α, so ε_αβ = ½ (a_α · a_β − A_αβ) = e_αβ D_α · D_β − ½A_αβ.
  const Vec3 right = r_right - r, up = r_up - r;
  const double eps11 = c.e[0] * dot(right, right) - c.half_A[0];
  const double eps12 = c.e[1] * dot(right, up) - c.half_A[1];
  const double eps22 = c.e[2] * dot(up, up) - c.half_A[2];
  double nu11 = c.nu_eps[0] * eps11, nu12 = c.nu_eps[1] * eps12, nu22 = c.nu_eps[2] * eps22;

  if (Bending || Normal) {
    // §2.1 rule 2: n = s/|s|, s the sum of the four corner triangles' unit normals (each
    // through bounded_unit).
    const Vec3 left = r_left - r, down = r_down - r;
    const Unit q0 = corner<Bounded>(right, up, c.corner, crushed),
               q1 = corner<Bounded>(up, left, c.corner, crushed),
               q2 = corner<Bounded>(left, down, c.corner, crushed),
               q3 = corner<Bounded>(down, right, c.corner, crushed);
    const Unit sum =
        bounded_unit<Bounded>(((q0.unit + q1.unit) + q2.unit) + q3.unit, c.sum, crushed);
    const Vec3 n = sum.unit;
    normal = n;

    if (Bending) {
      // §2.1 rule 3: H r_,αα = D_α + D_−α, h₁h₂ r_,12 = X₊₊ before its division; κ = −β/H.
      const Vec3 d11 = right + left, d22 = up + down, d12 = (r_up_right - r_right) - up;
      const double beta11 = dot(n, d11), beta12 = dot(n, d12), beta22 = dot(n, d22);
      double mu11 = c.mu_beta[0] * beta11, mu12 = c.mu_beta[1] * beta12,
             mu22 = c.mu_beta[2] * beta22;
      if (Coupling) {
        nu11 += c.nu_beta[0] * beta11;
        nu12 += c.nu_beta[1] * beta12;
        nu22 += c.nu_beta[2] * beta22;
        mu11 += c.mu_eps[0] * eps11;
        mu12 += c.mu_eps[1] * eps12;
        mu22 += c.mu_eps[2] * eps22;
      }
      // β_i = n · Δ_i: ∂/∂Δ_i = μ_i n, ∂/∂n = Σ μ_i Δ_i.
      Vec3 G_X11 = mu11 * n, G_X22 = mu22 * n;
      const Vec3 G_X12 = mu12 * n;
      Vec3 G_n = (mu11 * d11 + mu22 * d22) + mu12 * d12;
      if constexpr (Bounded) add_lost_bending(c, sum.shortfall, n, d11, d22, G_X11, G_X22, G_n);
      g_right = G_X11 - G_X12;
      g_left = G_X11;
      g_up = G_X22 - G_X12;
      g_down = G_X22;
      g_up_right = G_X12;

      // Back through n = s/g(|s|), then through each corner's unit normal.
      const Vec3 G_s = unit_gradient(sum, G_n);
      const CornerGradient g0 = corner_gradient(q0, right, up, G_s),
                           g1 = corner_gradient(q1, up, left, G_s),
                           g2 = corner_gradient(q2, left, down, G_s),
                           g3 = corner_gradient(q3, down, right, G_s);
      g_right += g0.e;
      g_up += g0.f;
      g_up += g1.e;
      g_left += g1.f;
      g_left += g2.e;
      g_down += g2.f;
      g_down += g3.e;
      g_right += g3.f;
    }
  }

  // ∂/∂D₁ = ν₁₁ D₁ + ν₁₂ D₂, ∂/∂D₂ = ν₂₂ D₂ + ν₁₂ D₁.
  g_right += nu11 * right + nu12 * up;
  g_up += nu22 * up + nu12 * right;
  // E_p moves with nothing but differences of positions, so its gradient sums to zero: p's slot
  // is minus the others (and the forces it makes conserve momentum to round-off).
  const Vec3 g_centre = -((((g_right + g_left) + g_up) + g_down) + g_up_right);
  return {g_centre, g_right, g_left, g_up, g_down, g_up_right};
}

// The same for the trapezoidal quadrature (docs/equations.md, "Energy quadrature"): an
// interior node's E_p is its bending terms, the stretch of its two forward edges and the cell
// (k+½, l+½), all of weight 1; it reads the same six nodes. The coefficients are
// trapezoidal_coefficients' (cosserat_energy.cpp), and trapezoidal_energy is the general form.
// V is Vec3 for the force, or the DualVec3 of CosseratEnergy::interior_hessian.
template <bool Bending, bool Coupling, bool Normal, bool Bounded, class V>
[[gnu::always_inline]] inline BasicInteriorGradient<V> trapezoidal_gradient(
    const InteriorCoefficients& c, const V& r, const V& r_right, const V& r_left, const V& r_up,
    const V& r_down, const V& r_up_right, V& normal, long& crushed) {
  using S = ScalarOf<V>;
  V g_right, g_left, g_up, g_down, g_up_right;
  const V right = r_right - r, up = r_up - r, diagonal = r_up_right - r;
  const S eps11 = c.e[0] * dot(right, right) - c.half_A[0];
  const S eps22 = c.e[2] * dot(up, up) - c.half_A[2];
  // The cell's tangents at its centre, times 2h_α: ε₁₂ = e₁₂ t₁ · t₂ − ½A₁₂.
  const V t1 = right + (diagonal - up), t2 = up + (diagonal - right);
  const S eps12 = c.e[1] * dot(t1, t2) - c.half_A[1];
  // The coefficients of the forward edges in ∂E/∂D_α and of t₂, t₁ in ∂E/∂t₁, ∂E/∂t₂.
  S nu11 = c.nu_eps[0] * eps11, nu12 = c.nu_eps[1] * eps12, nu22 = c.nu_eps[2] * eps22;

  if (Bending || Normal) {
    const V left = r_left - r, down = r_down - r;
    const BasicUnit<V> q0 = corner<Bounded>(right, up, c.corner, crushed),
                       q1 = corner<Bounded>(up, left, c.corner, crushed),
                       q2 = corner<Bounded>(left, down, c.corner, crushed),
                       q3 = corner<Bounded>(down, right, c.corner, crushed);
    const BasicUnit<V> sum =
        bounded_unit<Bounded>(((q0.unit + q1.unit) + q2.unit) + q3.unit, c.sum, crushed);
    const V n = sum.unit;
    normal = n;

    if (Bending) {
      const V d11 = right + left, d22 = up + down;
      const S beta11 = dot(n, d11), beta22 = dot(n, d22);
      S mu11 = c.mu_beta[0] * beta11, mu22 = c.mu_beta[2] * beta22;
      // The backward edges' coefficients, for the coupling's ε̄ alone.
      S nu11_b = 0.0, nu22_b = 0.0;
      if (Coupling) {
        const S eps11_b = c.e[0] * dot(left, left) - c.half_A[0];
        const S eps22_b = c.e[2] * dot(down, down) - c.half_A[2];
        mu11 += c.mu_eps[0] * (0.5 * (eps11 + eps11_b));
        mu22 += c.mu_eps[2] * (0.5 * (eps22 + eps22_b));
        nu11_b = 0.5 * c.nu_beta[0] * beta11;
        nu22_b = 0.5 * c.nu_beta[2] * beta22;
        nu11 += nu11_b;
        nu22 += nu22_b;
      }
      V G_X11 = mu11 * n, G_X22 = mu22 * n;
      V G_n = mu11 * d11 + mu22 * d22;
      if constexpr (Bounded) add_lost_bending(c, sum.shortfall, n, d11, d22, G_X11, G_X22, G_n);
      g_right = G_X11;
      g_left = G_X11 + nu11_b * left;
      g_up = G_X22;
      g_down = G_X22 + nu22_b * down;
      const V G_s = unit_gradient(sum, G_n);
      const BasicCornerGradient<V> g0 = corner_gradient(q0, right, up, G_s),
                                   g1 = corner_gradient(q1, up, left, G_s),
                                   g2 = corner_gradient(q2, left, down, G_s),
                                   g3 = corner_gradient(q3, down, right, G_s);
      g_right += g0.e;
      g_up += g0.f;
      g_up += g1.e;
      g_left += g1.f;
      g_left += g2.e;
      g_down += g2.f;
      g_down += g3.e;
      g_right += g3.f;

      // The cell's twist: κ₁₂ = −n_c · X/(h₁h₂), n_c = t₁ × t₂ normalised.
      const V X = (diagonal - right) - up;
      const BasicUnit<V> cell = bounded_unit<Bounded>(cross(t1, t2), c.cell, crushed);
      const S beta12 = dot(cell.unit, X);
      S mu12 = c.mu_beta[1] * beta12;
      if (Coupling) {
        nu12 += c.nu_beta[1] * beta12;
        mu12 += c.mu_eps[1] * eps12;
      }
      const V G_X = mu12 * cell.unit;
      const BasicCornerGradient<V> gc = corner_gradient(cell, t1, t2, mu12 * X);
      // t₁ = r(k+1, l) + r(k+1, l+1) − r − r(k, l+1), t₂ = r(k, l+1) + r(k+1, l+1) − r −
      // r(k+1, l), X = r(k+1, l+1) − r(k+1, l) − r(k, l+1) + r.
      g_right += (gc.e - gc.f) - G_X;
      g_up += (gc.f - gc.e) - G_X;
      g_up_right = (gc.e + gc.f) + G_X;
    }
  }

  g_right += nu11 * right + nu12 * (t2 - t1);
  g_up += nu22 * up + nu12 * (t1 - t2);
  g_up_right += nu12 * (t1 + t2);
  const V g_centre = -((((g_right + g_left) + g_up) + g_down) + g_up_right);
  return {g_centre, g_right, g_left, g_up, g_down, g_up_right};
}

}  // namespace cosserat::energy
