#pragma once
// ∂E_p/∂r of MODEL.md §2.5 for an interior node p — all four neighbours present, so every term
// of E_p exists (§2.3 rules 1–2 leave nothing out), the tangents are forward differences and
// the cross derivative is X₊₊ — written without a branch so that a loop over a row of such
// nodes vectorises. node_energy in cosserat_energy.cpp is the general form (any node, with
// the energy itself); this is its interior case, and a unit test holds the two together.
//
// An interior node's energy reads only its five-point cross and the node (k+1, l+1), so its
// gradient has six nonzero stencil slots; the other three of node_energy's nine are zero.

#include <cmath>

#include "cosserat/grid/vec3.hpp"
#include "cosserat/model/cosserat_energy.hpp"

namespace cosserat::energy {

// The six nonzero slots of an interior node's gradient, ∂E_p/∂r_q for q = p + (dk, dl).
struct InteriorGradient {
  Vec3 centre, right, left, up, down, up_right;  // (0,0) (1,0) (−1,0) (0,1) (0,−1) (1,1)
};

// One corner triangle of §2.1 rule 2: edges E, F from p, c = E × F, its length and unit.
struct Corner {
  Vec3 unit;
  double length;
};

[[gnu::always_inline]] inline Corner corner(const Vec3& E, const Vec3& F) {
  const Vec3 c = cross(E, F);
  const double length = std::sqrt(dot(c, c));
  return {c * (1.0 / length), length};
}

// Back through a corner's c/|c| and c = E × F: adds ∂/∂r of G_s · (c/|c|) to the slots of its
// edges' far nodes (e, f) and of p.
[[gnu::always_inline]] inline void add_corner_gradient(const Corner& q, const Vec3& E,
                                                       const Vec3& F, const Vec3& G_s, Vec3& e,
                                                       Vec3& f, Vec3& centre) {
  const Vec3 G_c = (G_s - dot(G_s, q.unit) * q.unit) * (1.0 / q.length);
  // G_c · (δE × F) = δE · (F × G_c), G_c · (E × δF) = δF · (G_c × E).
  const Vec3 G_E = cross(F, G_c), G_F = cross(G_c, E);
  e += G_E;
  f += G_F;
  centre -= G_E + G_F;
}

// Positions of p = (k, l), its neighbours and (k+1, l+1); the unit normal n of p comes back in
// `normal` when the bending terms or the caller (Normal: the fluid term reads it) need it.
template <bool Bending, bool Coupling, bool Normal>
[[gnu::always_inline]] inline InteriorGradient interior_gradient(
    const InteriorCoefficients& c, const Vec3& r, const Vec3& r_right, const Vec3& r_left,
    const Vec3& r_up, const Vec3& r_down, const Vec3& r_up_right, Vec3& normal) {
  InteriorGradient g;
  // §2.1 rule 1: a_α = D⁺_α r.
  const Vec3 right = r_right - r, up = r_up - r;
  const Vec3 a1 = right * c.inv_h1, a2 = up * c.inv_h2;
  const double eps11 = 0.5 * (dot(a1, a1) - c.A[0]);
  const double eps12 = 0.5 * (dot(a1, a2) - c.A[1]);
  const double eps22 = 0.5 * (dot(a2, a2) - c.A[2]);

  // ∂E_p/∂ε_αβ (the (1,2) terms count twice in Σ_αβ).
  double N11 = 2.0 * c.Phi[0] * eps11, N22 = 2.0 * c.Phi[2] * eps22;
  double N12 = 2.0 * (2.0 * c.Phi[1] * eps12);

  if (Bending || Normal) {
    // §2.1 rule 2: n = s/|s|, s the sum of the four corner triangles' unit normals.
    const Vec3 left = r_left - r, down = r_down - r;
    const Corner q0 = corner(right, up), q1 = corner(up, left), q2 = corner(left, down),
                 q3 = corner(down, right);
    const Vec3 s = ((q0.unit + q1.unit) + q2.unit) + q3.unit;
    const double s_length = std::sqrt(dot(s, s));
    const Vec3 n = s * (1.0 / s_length);
    normal = n;

    if (Bending) {
      // §2.1 rule 3: r_,αα = D_αα r, r_,12 = X₊₊; κ_αβ = −n · r_,αβ.
      const Vec3 r11 = (right + left) * c.inv_h11;
      const Vec3 r22 = (up + down) * c.inv_h22;
      const Vec3 r12 = ((r_up_right - r_right) - up) * c.inv_h12;
      const double k11 = -dot(n, r11), k12 = -dot(n, r12), k22 = -dot(n, r22);

      double M11 = 2.0 * c.Psi[0] * k11, M22 = 2.0 * c.Psi[2] * k22;
      double M12 = 2.0 * (2.0 * c.Psi[1] * k12);
      if (Coupling) {
        N11 += c.Theta[0] * k11;
        N22 += c.Theta[2] * k22;
        N12 += 2.0 * (c.Theta[1] * k12);
        M11 += c.Theta[0] * eps11;
        M22 += c.Theta[2] * eps22;
        M12 += 2.0 * (c.Theta[1] * eps12);
      }
      M11 *= c.area;
      M22 *= c.area;
      M12 *= c.area;

      // κ_αβ = −n · r_,αβ: ∂/∂r_,αβ = −M n, ∂/∂n = −Σ M r_,αβ.
      const Vec3 G_X11 = (-M11 * c.inv_h11) * n;
      const Vec3 G_X22 = (-M22 * c.inv_h22) * n;
      const Vec3 G_X12 = (-M12 * c.inv_h12) * n;
      g.right = G_X11 - G_X12;
      g.left = G_X11;
      g.up = G_X22 - G_X12;
      g.down = G_X22;
      g.up_right = G_X12;
      g.centre = G_X12 - 2.0 * (G_X11 + G_X22);
      const Vec3 G_n = -((M11 * r11 + M22 * r22) + M12 * r12);

      // Back through n = s/|s|, then through each corner's unit normal.
      const Vec3 G_s = (G_n - dot(G_n, n) * n) * (1.0 / s_length);
      add_corner_gradient(q0, right, up, G_s, g.right, g.up, g.centre);
      add_corner_gradient(q1, up, left, G_s, g.up, g.left, g.centre);
      add_corner_gradient(q2, left, down, G_s, g.left, g.down, g.centre);
      add_corner_gradient(q3, down, right, G_s, g.down, g.right, g.centre);
    }
  }

  // ε_αβ = ½ (a_α · a_β − A_αβ): ∂/∂a₁ = N¹¹ a₁ + ½ N¹² a₂, ∂/∂a₂ = N²² a₂ + ½ N¹² a₁, and
  // a_α = D⁺_α r.
  N11 *= c.area;
  N22 *= c.area;
  N12 *= c.area;
  const Vec3 G_a1 = (N11 * a1 + (0.5 * N12) * a2) * c.inv_h1;
  const Vec3 G_a2 = (N22 * a2 + (0.5 * N12) * a1) * c.inv_h2;
  g.right += G_a1;
  g.up += G_a2;
  g.centre -= G_a1 + G_a2;
  return g;
}

}  // namespace cosserat::energy
