#include "cosserat/model/cosserat_energy.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "dual.hpp"
#include "energy_interior.hpp"
#include "surface_geometry.hpp"

// The interior rows are most of a step's time: they have a wide copy (grid/wide_copy.hpp).

// Reach: E_p reads the 3 × 3 box around p, so the force at q reads the gradients of the nodes
// p within one node of q, which read positions within two nodes of q: the same two ghost rings
// as the flux form (kGhostWidth = 2). The gradients of the ring around the owned range are
// computed redundantly rather than exchanged.

namespace cosserat {

namespace {

using geometry::Neighbours;

// Stencil slot of the node (k + dk, l + dl) around p = (k, l).
constexpr int slot(int dk, int dl) { return 3 * (dl + 1) + (dk + 1); }

// CosseratEnergy::Parts in the scalar the energy is computed in (energy::ScalarOf).
template <class S>
struct PartsOf {
  S node{}, edge1{}, edge2{}, cell{};
};

// Which terms of E_p exist (docs/equations.md §2.5, "Nodal quadrature"): §2.3 rule 1 leaves the
// shear terms (ε₁₂, κ₁₂) out on the far borders, rule 2 leaves κ_αα out at nodes lacking an
// α-neighbour.
struct Terms {
  bool shear, bend11, bend22;
};

inline Terms terms_of(const Neighbours& p) {
  return {p.right && p.up, p.left && p.right, p.down && p.up};
}

// The unit normal n = s/|s| of §2.1 rule 2, s the sum of the unit normals of p's corner
// triangles, with what its gradient needs: computed once per node for both. Each unit goes
// through energy::bounded_unit (docs/equations.md, "Crushed cells"); where nothing is crushed
// the arithmetic is geometry::unit_normal's, so n is the same bits.
template <class V>
struct BasicCornerNormals {
  struct Corner {
    int ek, el, fk, fl;  // the offsets of the corner's two edges' far nodes
    V E, F;              // the edges r_e − r, r_f − r
    energy::BasicUnit<V> normal;
  };
  Corner corner[4];
  int count = 0;
  energy::BasicUnit<V> sum;  // n = sum.unit
  V n;
};

// The positions around (k, l) as corner_normals and trapezoidal_terms read them: at(dk, dl).
inline auto around(const Field<Vec3>& R, int k, int l) {
  return [&R, k, l](int dk, int dl) { return R(k + dk, l + dl); };
}

// `at(dk, dl)` is the position of the node (k + dk, l + dl) around p = (k, l).
template <class V, class At>
BasicCornerNormals<V> corner_normals(const At& at, const Neighbours& p,
                                     const energy::InteriorCoefficients& coefficients) {
  const V r = at(0, 0);
  BasicCornerNormals<V> c;
  auto add = [&](int ek, int el, int fk, int fl) {
    auto& q = c.corner[c.count++];
    q.ek = ek, q.el = el, q.fk = fk, q.fl = fl;
    q.E = at(ek, el) - r;
    q.F = at(fk, fl) - r;
    q.normal = energy::corner(q.E, q.F, coefficients.corner);
  };
  if (p.right && p.up) add(1, 0, 0, 1);
  if (p.up && p.left) add(0, 1, -1, 0);
  if (p.left && p.down) add(-1, 0, 0, -1);
  if (p.down && p.right) add(0, -1, 1, 0);
  V sum{};
  for (int i = 0; i < c.count; ++i) sum += c.corner[i].normal.unit;
  c.sum = energy::bounded_unit(sum, coefficients.sum);
  c.n = c.sum.unit;
  return c;
}

// Adds the gradient that flows back through n, given G_n = ∂E/∂n.
template <class V>
void add_normal_gradient(const BasicCornerNormals<V>& c, const V& G_n, std::array<V, 9>& g) {
  // Back through n = s/g(|s|), then through each corner's unit.
  const V G_s = energy::unit_gradient(c.sum, G_n);
  for (int i = 0; i < c.count; ++i) {
    const auto& q = c.corner[i];
    const energy::BasicCornerGradient<V> d = energy::corner_gradient(q.normal, q.E, q.F, G_s);
    g[slot(q.ek, q.el)] += d.e;
    g[slot(q.fk, q.fl)] += d.f;
    g[slot(0, 0)] -= d.e + d.f;
  }
}

// Below these a corner triangle or cell (as a fraction of its rest |c|) and a node's sum of
// corner units count as crushed (docs/equations.md, "Crushed cells").
constexpr double kCrushedFraction = 0.25, kCrushedSum = 0.5;

bool any_nonzero(const Sym2& c) { return c[0] != 0.0 || c[1] != 0.0 || c[2] != 0.0; }

energy::InteriorCoefficients interior_coefficients(const Sym2& Phi, const Sym2& Psi,
                                                   const Sym2& Theta, const Sym2& A, double h1,
                                                   double h2) {
  const double area = h1 * h2;
  const Sym2 H{h1 * h1, h1 * h2, h2 * h2}, w{1.0, 2.0, 1.0};
  energy::InteriorCoefficients c;
  for (int i = 0; i < 3; ++i) {
    c.e[i] = 1.0 / (2.0 * H[i]);
    c.half_A[i] = 0.5 * A[i];
    c.nu_eps[i] = 2.0 * area * Phi[i] / H[i];
    c.nu_beta[i] = -area * Theta[i] / (H[i] * H[i]);
    c.mu_beta[i] = 2.0 * area * w[i] * Psi[i] / (H[i] * H[i]);
    c.mu_eps[i] = -area * w[i] * Theta[i] / H[i];
  }
  // docs/equations.md, "Crushed cells": a corner triangle's |E × F| is h₁h₂√det A at rest, a
  // cell's |t₁ × t₂| four times that, and a node's |s| up to 4.
  auto crush = [](double delta) {
    return energy::Crush{delta, 1.0 / (delta * delta)};
  };
  const double rest_corner = area * std::sqrt(A[0] * A[2] - A[1] * A[1]);
  c.corner = crush(kCrushedFraction * rest_corner);
  c.cell = crush(4.0 * kCrushedFraction * rest_corner);
  c.sum = crush(kCrushedSum);
  return c;
}

// The trapezoidal quadrature's interior constants (docs/equations.md, "Energy quadrature"):
// the nodal ones but for the shear, whose tangents are the cell's, t_α = 2h_α a_α: ε₁₂ =
// (t₁ · t₂)/(8h₁h₂) − ½A₁₂, so its e and ν (the coefficient of t₂ in ∂E/∂t₁) are a quarter of
// the nodal ones.
energy::InteriorCoefficients trapezoidal_coefficients(const Sym2& Phi, const Sym2& Psi,
                                                      const Sym2& Theta, const Sym2& A,
                                                      double h1, double h2) {
  energy::InteriorCoefficients c = interior_coefficients(Phi, Psi, Theta, A, h1, h2);
  c.e[1] *= 0.25;
  c.nu_eps[1] *= 0.25;
  c.nu_beta[1] *= 0.25;
  return c;
}

}  // namespace

CosseratEnergy::CosseratEnergy(const Block& block, double h1, double h2, const RestState& rest,
                               Quadrature quadrature)
    : block_(&block),
      h1_(h1),
      h2_(h2),
      rest_(rest),
      quadrature_(quadrature),
      interior_{quadrature == Quadrature::trapezoidal
                    ? trapezoidal_coefficients(rest.Phi, rest.Psi, rest.Theta, rest.metric, h1,
                                               h2)
                    : interior_coefficients(rest.Phi, rest.Psi, rest.Theta, rest.metric, h1,
                                            h2)},
      terms_{any_nonzero(rest.Psi) || any_nonzero(rest.Theta), any_nonzero(rest.Theta)},
      wide_(wide_copies_available()) {}

double CosseratEnergy::node_energy(const Field<Vec3>& R, int k, int l, StencilGradient* gradient,
                                   Vec3* normal, Parts* parts) const {
  if (quadrature_ == Quadrature::trapezoidal)
    return trapezoidal_energy(R, k, l, gradient, normal, parts);
  return nodal_energy(R, k, l, gradient, normal);
}

// E_p of the trapezoidal quadrature (docs/equations.md, "Energy quadrature"): with w_k = ½ on
// B1, B3 and 1 elsewhere, w_l likewise, and a = h₁h₂,
//   the edge (k+½, l), weight w_l a:   Φ¹¹ ε₁₁²,   ε₁₁ = ½ (|D⁺₁ r|² − A₁₁) on the edge;
//   the edge (k, l+½), weight w_k a:   Φ²² ε₂₂²;
//   the cell (k+½, l+½), weight a:     2 (Φ¹² ε₁₂² + Ψ¹² κ₁₂² + Θ¹² ε₁₂ κ₁₂), from the cell's
//                                      tangents, its normal and X₊₊;
//   the node, where it has both α-neighbours, weight w_β a (β ≠ α):  Ψ^{αα} κ_αα² +
//                                      Θ^{αα} ε̄_αα κ_αα, κ_αα = −n · D_αα r, ε̄_αα the mean of
//                                      the strains of the node's two α-edges.
template <class V, class At>
auto CosseratEnergy::trapezoidal_terms(const At& at, int k, int l, std::array<V, 9>* gradient,
                                       V* normal, Parts* parts, bool node_terms) const {
  using S = energy::ScalarOf<V>;
  const Neighbours p = geometry::neighbours(*block_, k, l);
  const double h1 = h1_, h2 = h2_, area = h1 * h2;
  const double wk = p.left && p.right ? 1.0 : 0.5, wl = p.down && p.up ? 1.0 : 0.5;
  const bool bend11 = node_terms && p.left && p.right, bend22 = node_terms && p.down && p.up;
  const bool cell = p.right && p.up;
  const Sym2 &Phi = rest_.Phi, &Psi = rest_.Psi, &Theta = rest_.Theta, &A = rest_.metric;
  const V r = at(0, 0);
  if (gradient != nullptr) gradient->fill(V{});
  std::array<V, 9>* G = gradient;
  auto add = [&](int dk, int dl, const V& v) { (*G)[slot(dk, dl)] += v; };
  PartsOf<S> part;

  // The edge strains around p: the forward edges' terms are E_p's own, the backward ones only
  // enter the bending terms' ε̄.
  const V right = p.right ? at(1, 0) - r : V{};
  const V left = p.left ? at(-1, 0) - r : V{};
  const V up = p.up ? at(0, 1) - r : V{}, down = p.down ? at(0, -1) - r : V{};
  auto strain = [](const V& d, double h, double A_i) {
    return 0.5 * (dot(d, d) / (h * h) - A_i);
  };
  const S eps11_f = strain(right, h1, A[0]), eps11_b = strain(left, h1, A[0]);
  const S eps22_f = strain(up, h2, A[2]), eps22_b = strain(down, h2, A[2]);
  // ∂E_p/∂ε of each of the four edge strains, built up term by term.
  S N11_f = 0.0, N11_b = 0.0, N22_f = 0.0, N22_b = 0.0;
  if (p.right) {
    part.edge1 = wl * area * Phi[0] * eps11_f * eps11_f;
    N11_f += 2.0 * wl * area * Phi[0] * eps11_f;
  }
  if (p.up) {
    part.edge2 = wk * area * Phi[2] * eps22_f * eps22_f;
    N22_f += 2.0 * wk * area * Phi[2] * eps22_f;
  }

  const bool needs_normal = (bend11 || bend22) || normal != nullptr;
  BasicCornerNormals<V> corners;
  if (needs_normal) corners = corner_normals<V>(at, p, interior_);
  if (normal != nullptr) *normal = corners.n;
  V G_n{};  // ∂E_p/∂n
  auto bending = [&](bool exists, const V& d, double h, double w, int i, const S& eps_f,
                     const S& eps_b, S& N_f, S& N_b, int dk, int dl) {
    if (!exists) return;
    const V n = corners.n;
    const S kappa = -dot(n, d) / (h * h), eps = 0.5 * (eps_f + eps_b);
    part.node += w * area * (Psi[i] * kappa * kappa + Theta[i] * eps * kappa);
    // What the crushed normal of a crease folded flat loses, w a Ψ λ |d|²/h⁴ with λ = 1 − |n|²
    // (docs/equations.md, "Creases folded flat"; energy::add_lost_bending): λ is 0 elsewhere.
    const S lost = corners.sum.shortfall;
    S squares(0.0);
    if (lost > 0.0) {
      squares = dot(d, d) / (h * h * h * h);
      part.node += w * area * Psi[i] * (lost * squares);
    }
    if (G == nullptr) return;
    const S M = w * area * (2.0 * Psi[i] * kappa + Theta[i] * eps);  // ∂E_p/∂κ
    N_f += 0.5 * w * area * Theta[i] * kappa;
    N_b += 0.5 * w * area * Theta[i] * kappa;
    // κ = −n · d/h²: ∂/∂d = −(M/h²) n, ∂/∂n = −(M/h²) d; d = r(p + e) + r(p − e) − 2 r. The
    // lost bending adds 2 w a Ψ λ d/h⁴ to the first and −2 w a Ψ |d|²/h⁴ n to the second.
    V G_d = (-M / (h * h)) * n;
    G_n += (-M / (h * h)) * d;
    if (lost > 0.0) {
      G_d += ((2.0 * w * area * Psi[i] / (h * h * h * h)) * lost) * d;
      G_n -= (2.0 * w * area * Psi[i] * squares) * n;
    }
    add(dk, dl, G_d);
    add(-dk, -dl, G_d);
    add(0, 0, -2.0 * G_d);
  };
  bending(bend11, right + left, h1, wl, 0, eps11_f, eps11_b, N11_f, N11_b, 1, 0);
  bending(bend22, up + down, h2, wk, 2, eps22_f, eps22_b, N22_f, N22_b, 0, 1);

  if (cell) {
    // The cell's tangents at its centre, times 2h_α, its normal and X₊₊ before its division.
    const V diagonal = at(1, 1) - r;
    const V t1 = right + (diagonal - up), t2 = up + (diagonal - right);
    const V X = (diagonal - right) - up;
    const S eps12 = 0.5 * (dot(t1, t2) / (4.0 * area) - A[1]);
    const auto cell_unit = energy::bounded_unit(cross(t1, t2), interior_.cell);
    const V n = cell_unit.unit;
    const S kappa12 = -dot(n, X) / area;
    part.cell = 2.0 * area *
                (Phi[1] * eps12 * eps12 + Psi[1] * kappa12 * kappa12 + Theta[1] * eps12 * kappa12);
    if (G != nullptr) {
      const S N12 = 2.0 * area * (2.0 * Phi[1] * eps12 + Theta[1] * kappa12);
      const S M12 = 2.0 * area * (2.0 * Psi[1] * kappa12 + Theta[1] * eps12);
      // ε₁₂ = t₁ · t₂/(8a) − ½A₁₂; κ₁₂ = −n · X/a with n = c/g(|c|), c = t₁ × t₂.
      V G_t1 = (N12 / (8.0 * area)) * t2, G_t2 = (N12 / (8.0 * area)) * t1;
      const V G_X = (-M12 / area) * n, G_cn = (-M12 / area) * X;
      const V G_c = energy::unit_gradient(cell_unit, G_cn);
      G_t1 += cross(t2, G_c);
      G_t2 += cross(G_c, t1);
      // t₁ = r(k+1, l) + r(k+1, l+1) − r − r(k, l+1), t₂ = r(k, l+1) + r(k+1, l+1) − r − r(k+1, l).
      add(1, 0, G_t1 - G_t2 - G_X);
      add(1, 1, G_t1 + G_t2 + G_X);
      add(0, 1, G_t2 - G_t1 - G_X);
      add(0, 0, G_X - G_t1 - G_t2);
    }
  }

  if (G != nullptr) {
    // ε = ½ (|d|²/h² − A): ∂/∂d = (N/h²) d, d = r(p ± e) − r.
    auto edge = [&](const S& N, const V& d, double h, int dk, int dl) {
      const V g = (N / (h * h)) * d;
      add(dk, dl, g);
      add(0, 0, -1.0 * g);
    };
    if (p.right) edge(N11_f, right, h1, 1, 0);
    if (p.left) edge(N11_b, left, h1, -1, 0);
    if (p.up) edge(N22_f, up, h2, 0, 1);
    if (p.down) edge(N22_b, down, h2, 0, -1);
    if (bend11 || bend22) add_normal_gradient(corners, G_n, *G);
  }
  if constexpr (std::is_same_v<S, double>)
    if (parts != nullptr) *parts = {part.node, part.edge1, part.edge2, part.cell};
  return ((part.node + part.edge1) + part.edge2) + part.cell;
}


double CosseratEnergy::trapezoidal_energy(const Field<Vec3>& R, int k, int l,
                                          StencilGradient* gradient, Vec3* normal, Parts* parts,
                                          bool node_terms) const {
  return trapezoidal_terms(around(R, k, l), k, l, gradient, normal, parts, node_terms);
}

// The gradient's code run on dual numbers seeded with the 27 coordinates of the box: each
// gradient entry's derivatives are a row of the Hessian. The border nodes' way: an interior node
// takes interior_hessian. The slots the code reads are the ones the Hessian has.
// flatten: every dual operation inlined into one loop nest per operation, not a call each.
[[gnu::flatten]] void CosseratEnergy::stencil_hessian(const Field<Vec3>& R, int k, int l,
                                                      NodeHessian& H) const {
  using Dual = energy::Dual<27>;
  using V = energy::DualVec3<27>;
  bool read[9] = {};
  auto at = [&](int dk, int dl) {
    const int s = slot(dk, dl), first = 3 * s;
    read[s] = true;
    const Vec3 r = R(k + dk, l + dl);
    V v{Dual(r.x), Dual(r.y), Dual(r.z)};
    v.x.d[first] = 1.0, v.y.d[first + 1] = 1.0, v.z.d[first + 2] = 1.0;
    return v;
  };
  std::array<V, 9> G;
  trapezoidal_terms(at, k, l, &G, static_cast<V*>(nullptr), nullptr, true);
  H.count = 0;
  for (int s = 0; s < 9; ++s)
    if (read[s]) H.read[H.count++] = s;
  H.entries.fill(0.0);
  for (int a = 0; a < 9; ++a)
    for (int i = 0; i < 3; ++i) {
      const Dual& g = i == 0 ? G[a].x : (i == 1 ? G[a].y : G[a].z);
      for (int bi = 0; bi < H.count; ++bi) {
        const int b = H.read[bi];
        for (int j = 0; j < 3; ++j)
          H.entries[(3 * a + i) * 27 + 3 * b + j] = g.d[3 * b + j];
      }
    }
}

// An interior node's E_p is the kernel's (energy_interior.hpp), a function of the five
// differences r_q − r_p, and each neighbour q enters one of them alone: seeded with the five
// neighbours and p held, the gradient's derivatives are the Hessian's rows at every slot and its
// columns at the neighbours, 15 directions instead of the 18 of every slot. E_p does not change
// when the box moves as a whole, so each row sums to zero over its slots: p's column is minus the
// others' sum. It takes 5.2-6.2 µs a node on a bent 120² sheet, where stencil_hessian on the 18
// directions of the six slots took 11.8 (benchmarks/results/jacobian-vm-2026-12-05.md); a copy
// compiled for AVX2, as interior_row_wide, measured no faster and was dropped.
template <bool Bending, bool Coupling>
[[gnu::flatten]] void CosseratEnergy::interior_hessian(const Field<Vec3>& R, int k, int l,
                                                       NodeHessian& H) const {
  constexpr int N = 15;
  using Dual = energy::Dual<N>;
  using V = energy::DualVec3<N>;
  auto at = [&](int dk, int dl, int direction) {
    const Vec3 r = R(k + dk, l + dl);
    V v{Dual(r.x), Dual(r.y), Dual(r.z)};
    if (direction >= 0)
      v.x.d[3 * direction] = v.y.d[3 * direction + 1] = v.z.d[3 * direction + 2] = 1.0;
    return v;
  };
  V normal;
  long crushed = 0;
  const energy::BasicInteriorGradient<V> g =
      energy::trapezoidal_gradient<Bending, Coupling, false, true>(
          interior_, at(0, 0, -1), at(1, 0, 0), at(-1, 0, 1), at(0, 1, 2), at(0, -1, 3),
          at(1, 1, 4), normal, crushed);
  // The slots of g's members, and the seed of each slot (p's: none).
  static constexpr int kSlots[6] = {4, 5, 3, 7, 1, 8};
  static constexpr int kSeed[9] = {-1, 3, -1, 1, -1, 0, -1, 2, 4};
  const V* rows[6] = {&g.centre, &g.right, &g.left, &g.up, &g.down, &g.up_right};
  static constexpr int kRead[6] = {1, 3, 4, 5, 7, 8};
  H.count = 6;
  std::copy(std::begin(kRead), std::end(kRead), H.read);
  H.entries.fill(0.0);
  for (int ri = 0; ri < 6; ++ri) {
    const int a = kSlots[ri];
    for (int i = 0; i < 3; ++i) {
      const Dual& gradient = i == 0 ? rows[ri]->x : (i == 1 ? rows[ri]->y : rows[ri]->z);
      double* row = &H.entries[static_cast<std::size_t>((3 * a + i) * 27)];
      double centre[3] = {0.0, 0.0, 0.0};
      for (const int b : kRead) {
        if (kSeed[b] < 0) continue;
        for (int j = 0; j < 3; ++j) {
          row[3 * b + j] = gradient.d[3 * kSeed[b] + j];
          centre[j] -= row[3 * b + j];
        }
      }
      for (int j = 0; j < 3; ++j) row[3 * 4 + j] = centre[j];
    }
  }
}

void CosseratEnergy::node_hessian(const Field<Vec3>& R, int k, int l, NodeHessian& hessian) const {
  if (!geometry::neighbours(*block_, k, l).interior()) {
    stencil_hessian(R, k, l, hessian);
    return;
  }
  if (!terms_.bending)
    interior_hessian<false, false>(R, k, l, hessian);
  else if (!terms_.coupling)
    interior_hessian<true, false>(R, k, l, hessian);
  else
    interior_hessian<true, true>(R, k, l, hessian);
}

// E_p = h₁h₂ Σ_αβ (Φ^{αβ} ε_αβ² + Ψ^{αβ} κ_αβ² + Θ^{αβ} ε_αβ κ_αβ) (docs/equations.md,
// "Nodal quadrature"): the sum over α, β counts the (1, 2) terms twice. Strains as the flux
// form computes them at its nodes.
double CosseratEnergy::nodal_energy(const Field<Vec3>& R, int k, int l, StencilGradient* gradient,
                                    Vec3* normal) const {
  using namespace geometry;
  const Neighbours p = neighbours(*block_, k, l);
  const Terms has = terms_of(p);
  const double h1 = h1_, h2 = h2_;
  const Tangents a = tangents(R, k, l, p, h1, h2);
  const auto corners = corner_normals<Vec3>(around(R, k, l), p, interior_);
  const Vec3 n = corners.n;
  if (normal != nullptr) *normal = n;
  const SecondDerivatives X = second_derivatives(R, k, l, p, h1, h2);
  const Metric g = metric(a);
  const Sym2 epsilon = membrane_strain(g.lower, rest_.metric);
  const Sym2 kappa = bending_strain(curvature(n, X));
  const Sym2 &Phi = rest_.Phi, &Psi = rest_.Psi, &Theta = rest_.Theta;
  const double area = h1 * h2;

  // ∂E_p/∂ε_αβ and ∂E_p/∂κ_αβ, zero for the terms left out.
  const double k11 = has.bend11 ? kappa[0] : 0.0, k22 = has.bend22 ? kappa[2] : 0.0;
  const double N11 = area * (2.0 * Phi[0] * epsilon[0] + Theta[0] * k11);
  const double N22 = area * (2.0 * Phi[2] * epsilon[2] + Theta[2] * k22);
  const double N12 =
      has.shear ? 2.0 * area * (2.0 * Phi[1] * epsilon[1] + Theta[1] * kappa[1]) : 0.0;
  const double M11 = has.bend11 ? area * (2.0 * Psi[0] * k11 + Theta[0] * epsilon[0]) : 0.0;
  const double M22 = has.bend22 ? area * (2.0 * Psi[2] * k22 + Theta[2] * epsilon[2]) : 0.0;
  const double M12 =
      has.shear ? 2.0 * area * (2.0 * Psi[1] * kappa[1] + Theta[1] * epsilon[1]) : 0.0;

  // What the crushed normal of a crease folded flat loses, λ |r_,αα|² with λ = 1 − |n|²
  // (docs/equations.md, "Creases folded flat"): 0 elsewhere.
  const double lost = corners.sum.shortfall;
  double square11 = 0.0, square22 = 0.0;
  if (lost > 0.0) {
    if (has.bend11) square11 = dot(X.r11, X.r11);
    if (has.bend22) square22 = dot(X.r22, X.r22);
  }
  double energy = Phi[0] * epsilon[0] * epsilon[0] + Phi[2] * epsilon[2] * epsilon[2];
  if (has.bend11) energy += Psi[0] * k11 * k11 + Theta[0] * epsilon[0] * k11;
  if (has.bend22) energy += Psi[2] * k22 * k22 + Theta[2] * epsilon[2] * k22;
  if (lost > 0.0) energy += lost * (Psi[0] * square11 + Psi[2] * square22);
  if (has.shear)
    energy += 2.0 * (Phi[1] * epsilon[1] * epsilon[1] + Psi[1] * kappa[1] * kappa[1] +
                     Theta[1] * epsilon[1] * kappa[1]);
  energy *= area;
  if (gradient == nullptr) return energy;

  StencilGradient& G = *gradient;
  G.fill(Vec3{});
  // ε_αβ = ½ (a_α · a_β − A_αβ): ∂/∂a₁ = N¹¹ a₁ + ½ N¹² a₂, ∂/∂a₂ = N²² a₂ + ½ N¹² a₁.
  const Vec3 G_a1 = N11 * a.a1 + (0.5 * N12) * a.a2;
  const Vec3 G_a2 = N22 * a.a2 + (0.5 * N12) * a.a1;
  // a_α = D⁺_α r, D⁻_α on the far border (§2.1 rule 1).
  const int k_plus = p.right ? 1 : 0, l_plus = p.up ? 1 : 0;
  G[slot(k_plus, 0)] += G_a1 / h1;
  G[slot(k_plus - 1, 0)] -= G_a1 / h1;
  G[slot(0, l_plus)] += G_a2 / h2;
  G[slot(0, l_plus - 1)] -= G_a2 / h2;

  // κ_αβ = −n · r_,αβ: ∂/∂r_,αβ = −M n, ∂/∂n = −Σ M r_,αβ. The lost bending adds
  // 2 a Ψ λ r_,αα and, where λ is not zero, −2 a Ψ |r_,αα|² n.
  Vec3 G_n;
  if (lost > 0.0) G_n -= (2.0 * area * (Psi[0] * square11 + Psi[2] * square22)) * n;
  if (has.bend11) {
    Vec3 G_X = (-M11 / (h1 * h1)) * n;
    if (lost > 0.0) G_X += (2.0 * area * Psi[0] * lost / (h1 * h1)) * X.r11;
    G[slot(1, 0)] += G_X;
    G[slot(-1, 0)] += G_X;
    G[slot(0, 0)] -= 2.0 * G_X;
    G_n -= M11 * X.r11;
  }
  if (has.bend22) {
    Vec3 G_X = (-M22 / (h2 * h2)) * n;
    if (lost > 0.0) G_X += (2.0 * area * Psi[2] * lost / (h2 * h2)) * X.r22;
    G[slot(0, 1)] += G_X;
    G[slot(0, -1)] += G_X;
    G[slot(0, 0)] -= 2.0 * G_X;
    G_n -= M22 * X.r22;
  }
  if (has.shear) {
    // The shear terms exist only where the forward cell X₊₊ does (rule 1).
    const Vec3 G_X = (-M12 / (h1 * h2)) * n;
    G[slot(1, 1)] += G_X;
    G[slot(0, 0)] += G_X;
    G[slot(1, 0)] -= G_X;
    G[slot(0, 1)] -= G_X;
    G_n -= M12 * X.r12;
  }
  add_normal_gradient(corners, G_n, G);
  return energy;
}

// The row-fused force (docs/model.md, "Force kernel"): each thread takes a contiguous band of
// owned rows and walks the rows p of its band, one beyond it on each side, in order. For each
// row it computes ∂E_p/∂r into row buffers — interior nodes through energy::interior_gradient,
// eight lanes at a time, the border ring through node_energy — and adds them into the forces of
// the three rows they touch; a row's force is complete once the row above it is done. Every
// node's force is −Σ_p ∂E_p/∂r_q summed in one fixed order (rows of p ascending, then the slots
// in kSlots order), and whether a node is interior depends only on its global index: any
// decomposition and any thread count give the same bits. The buffers are a few rows long, so
// the intermediates stay in cache and never take a field.
namespace {

// The gradient slots, interior ones first (the order of energy::InteriorGradient), then the
// three only border nodes reach: as (dk, dl) from p.
struct SlotOffset {
  int dk, dl;
};
constexpr SlotOffset kSlots[9] = {{0, 0}, {1, 0},  {-1, 0}, {0, 1},  {0, -1},
                                  {1, 1}, {-1, -1}, {1, -1}, {-1, 1}};
constexpr int kInteriorSlots = 6;
constexpr int kLanes = 8;  // lanes of one interior block; a multiple of any vector width used

}  // namespace

void CosseratEnergy::RowScratch::resize(int columns) {
  if (width >= columns) return;
  width = columns;
  const auto w = static_cast<std::size_t>(columns);
  positions.assign(9 * w, 0.0);
  gradient.assign(27 * w, 0.0);
  force.assign(9 * w, 0.0);
  normal.assign(3 * w, 0.0);
}

// Copies row l of the positions into its ring slot as three component arrays, over the columns
// the row's interior nodes read; the columns past the grown range continue the row linearly, so
// the lanes of the last block that lie beyond it compute on a regular sheet (their results are
// never used, and stay finite).
void CosseratEnergy::load_row(const Field<Vec3>& R, int l, int k_base, int k_end,
                              RowScratch& s) const {
  const int slot = l % 3;
  if (s.position_row[slot] == l) return;
  s.position_row[slot] = l;
  const auto w = static_cast<std::size_t>(s.width);
  double* x = s.positions.data() + 3 * slot * w;
  double* y = x + w;
  double* z = y + w;
  const int first = std::max(k_base, 0);
  // Vec3 is three packed doubles, so the row is one interleaved array the loop de-interleaves.
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  const double* source = &R(first, l).x;
  const int offset = first - k_base;
#pragma omp simd
  for (int i = 0; i < k_end - first; ++i) {
    x[offset + i] = source[3 * i];
    y[offset + i] = source[3 * i + 1];
    z[offset + i] = source[3 * i + 2];
  }
  const int last = k_end - 1 - k_base;
  const double dx = x[last] - x[last - 1], dy = y[last] - y[last - 1], dz = z[last] - z[last - 1];
  for (int c = last + 1; c < s.width; ++c) {
    x[c] = x[c - 1] + dx;
    y[c] = y[c - 1] + dy;
    z[c] = z[c - 1] + dz;
  }
}

template <bool Trapezoidal, bool Bending, bool Coupling, bool Normal>
void CosseratEnergy::interior_row(int l, int ka, int kb, int k_base, RowScratch& s) const {
  // A block's lanes as one vectorised loop, each unit through bounded_unit as Bounded says;
  // whether any unit of the block was crushed. What the loop reads is local to it: read
  // through the closure, GCC did not vectorise it.
  const auto lanes = [this, l, &s]<bool Bounded>(int block) {
    const auto w = static_cast<std::size_t>(s.width);
    const double* below = s.positions.data() + 3 * ((l - 1) % 3) * w;
    const double* here = s.positions.data() + 3 * (l % 3) * w;
    const double* above = s.positions.data() + 3 * ((l + 1) % 3) * w;
    double* G = s.gradient.data();
    double* N = s.normal.data();
    const energy::InteriorCoefficients& co = interior_;
    long crushed = 0;
#pragma omp simd reduction(| : crushed)
    for (int lane = 0; lane < kLanes; ++lane) {
      const std::size_t c = static_cast<std::size_t>(block + lane);
      auto at = [&](const double* row, std::size_t i) {
        return Vec3{row[i], row[w + i], row[2 * w + i]};
      };
      Vec3 n;
      const energy::InteriorGradient g =
          Trapezoidal ? energy::trapezoidal_gradient<Bending, Coupling, Normal, Bounded>(
                            co, at(here, c), at(here, c + 1), at(here, c - 1), at(above, c),
                            at(below, c), at(above, c + 1), n, crushed)
                      : energy::interior_gradient<Bending, Coupling, Normal, Bounded>(
                            co, at(here, c), at(here, c + 1), at(here, c - 1), at(above, c),
                            at(below, c), at(above, c + 1), n, crushed);
      // Slot by slot: an array of pointers into g would give each lane's g an address, and
      // the loop would not vectorise.
      auto store = [&](int q, const Vec3& v) {
        G[(3 * q + 0) * w + c] = v.x;
        G[(3 * q + 1) * w + c] = v.y;
        G[(3 * q + 2) * w + c] = v.z;
      };
      store(0, g.centre);
      store(1, g.right);
      store(2, g.left);
      store(3, g.up);
      store(4, g.down);
      store(5, g.up_right);
      if (Normal) {
        N[c] = n.x;
        N[w + c] = n.y;
        N[2 * w + c] = n.z;
      }
    }
    return crushed != 0;
  };
  // Where no unit of a block is crushed, the unbounded units are the bounded ones, bit for
  // bit, and cheaper: the bound taken everywhere cost the kernel 10-18 % (docs/equations.md,
  // "Crushed cells"). A block where one is crushed is done again, bounded.
  for (int block = ka - k_base; block < kb - k_base; block += kLanes)
    if (lanes.template operator()<false>(block)) lanes.template operator()<true>(block);
}

#if COSSERAT_WIDE_COPIES
// "avx2" and not "arch=x86-64-v3", which would allow FMA. flatten inlines interior_row and
// everything it calls, so all of it is compiled for AVX2.
template <bool Trapezoidal, bool Bending, bool Coupling, bool Normal>
[[gnu::target("avx2"), gnu::flatten]] void CosseratEnergy::interior_row_wide(
    int l, int ka, int kb, int k_base, RowScratch& s) const {
  interior_row<Trapezoidal, Bending, Coupling, Normal>(l, ka, kb, k_base, s);
}

#endif

// One border node through node_energy, into the row buffers.
void CosseratEnergy::border_node(const Field<Vec3>& R, int k, int l, int k_base,
                                 RowScratch& s) const {
  StencilGradient g;
  Vec3 n;
  node_energy(R, k, l, &g, &n);
  const auto w = static_cast<std::size_t>(s.width);
  const std::size_t c = static_cast<std::size_t>(k - k_base);
  for (int q = 0; q < 9; ++q) {
    const Vec3 v = g[slot(kSlots[q].dk, kSlots[q].dl)];
    s.gradient[(3 * q + 0) * w + c] = v.x;
    s.gradient[(3 * q + 1) * w + c] = v.y;
    s.gradient[(3 * q + 2) * w + c] = v.z;
  }
  s.normal[c] = n.x;
  s.normal[w + c] = n.y;
  s.normal[2 * w + c] = n.z;
}

template <bool Trapezoidal, bool Bending, bool Coupling, bool Normal>
void CosseratEnergy::band(const Field<Vec3>& R, Field<Vec3>* normals, double scale,
                          const Vec3& offset, bool per_mass, const RowConsumer& consume, int qa,
                          int qb, RowScratch& s) const {
  const Block& b = *block_;
  const int gk0 = std::max(b.k0 - 1, 0), gk1 = std::min(b.k1 + 1, b.m);
  const int k_base = gk0 - 1;  // column 0; the force buffers take p's slots at k − 1
  const int ka = std::max(gk0, 1), kb = std::min(gk1, b.m - 1);  // interior columns
  const auto w = static_cast<std::size_t>(s.width);
  auto force_row = [&](int q) { return s.force.data() + 3 * (q % 3) * w; };
  auto clear = [&](int q) { std::fill_n(force_row(q), 3 * w, 0.0); };
  const bool dual_areas = per_mass && Trapezoidal;
  auto write_out = [&](int q) {
    double* f = force_row(q) + (b.k0 - k_base);
    // Per unit mass, a border node's force is divided by its share ½ or ¼ of the dual area:
    // doubled once on a border row and once in a border column, which is exact.
    const double row_scale = dual_areas && (q == 0 || q == b.n - 1) ? 2.0 * scale : scale;
    auto border_column = [&](int k) {
      const auto i = static_cast<std::size_t>(k - b.k0);
      for (int component = 0; component < 3; ++component) f[component * w + i] *= 2.0;
    };
    if (dual_areas && b.k0 == 0) border_column(0);
    if (dual_areas && b.k1 == b.m) border_column(b.m - 1);
#pragma omp simd
    for (int i = 0; i < b.owned_k(); ++i) {
      f[i] = row_scale * f[i] + offset.x;
      f[w + i] = row_scale * f[w + i] + offset.y;
      f[2 * w + i] = row_scale * f[2 * w + i] + offset.z;
    }
    consume(q, f, f + w, f + 2 * w);
  };

  const int pa = std::max(qa - 1, 0), pb = std::min(qb + 1, b.n);
  s.position_row[0] = s.position_row[1] = s.position_row[2] = -1;  // positions have moved
  for (int q = pa; q < pa + 3; ++q) clear(q);
  for (int l = pa; l < pb; ++l) {
    if (l > pa) clear(l + 1);
    const bool border_row = l == 0 || l == b.n - 1;
    if (border_row) {
      for (int k = gk0; k < gk1; ++k) border_node(R, k, l, k_base, s);
    } else {
      const int k_end = std::min(gk1 + 1, b.m);
      load_row(R, l - 1, k_base, k_end, s);
      load_row(R, l, k_base, k_end, s);
      load_row(R, l + 1, k_base, k_end, s);
      if (ka < kb) {
#if COSSERAT_WIDE_COPIES
        if (wide_)
          interior_row_wide<Trapezoidal, Bending, Coupling, Normal>(l, ka, kb, k_base, s);
        else
#endif
          interior_row<Trapezoidal, Bending, Coupling, Normal>(l, ka, kb, k_base, s);
      }
      if (gk0 == 0) border_node(R, 0, l, k_base, s);
      if (gk1 == b.m) border_node(R, b.m - 1, l, k_base, s);
    }
    if (normals != nullptr && l >= qa && l < qb)
      for (int k = b.k0; k < b.k1; ++k) {
        const std::size_t c = static_cast<std::size_t>(k - k_base);
        (*normals)(k, l) = {s.normal[c], s.normal[w + c], s.normal[2 * w + c]};
      }

    // f_q −= ∂E_p/∂r_q. The interior slots are gathered per force row, each q taking its terms
    // from p = q − (dk, dl) in slot order; the columns just outside the row's range read as
    // zero (p outside the grid, or a q that is not owned).
    const int c0 = gk0 - k_base, c1 = gk1 - k_base;
    for (int q = 0; q < kInteriorSlots; ++q)
      for (int component = 0; component < 3; ++component) {
        double* g = s.gradient.data() + (3 * q + component) * w;
        g[c0 - 1] = 0.0;
        g[c1] = 0.0;
      }
    auto slot_row = [&](int q, int component) {
      return s.gradient.data() + (3 * q + component) * w;
    };
    for (int component = 0; component < 3; ++component) {
      const double *centre = slot_row(0, component), *right = slot_row(1, component),
                   *left = slot_row(2, component), *up = slot_row(3, component),
                   *down = slot_row(4, component), *up_right = slot_row(5, component);
      double* f = force_row(l) + component * w;
#pragma omp simd
      for (int c = c0; c < c1; ++c) f[c] = ((f[c] - centre[c]) - right[c - 1]) - left[c + 1];
      if (l + 1 < b.n) {
        double* f_above = force_row(l + 1) + component * w;
#pragma omp simd
        for (int c = c0; c < c1; ++c) f_above[c] = (f_above[c] - up[c]) - up_right[c - 1];
      }
      if (l > 0) {
        double* f_below = force_row(l - 1) + component * w;
#pragma omp simd
        for (int c = c0; c < c1; ++c) f_below[c] -= down[c];
      }
    }
    // The slots only border nodes reach, scattered from those nodes.
    auto scatter = [&](int q, int c) {
      const int fl = l + kSlots[q].dl;
      if (fl < 0 || fl >= b.n) return;
      for (int component = 0; component < 3; ++component)
        force_row(fl)[component * w + c + kSlots[q].dk] -= slot_row(q, component)[c];
    };
    for (int q = kInteriorSlots; q < 9; ++q) {
      if (border_row) {
        for (int c = c0; c < c1; ++c) scatter(q, c);
      } else {
        if (gk0 == 0) scatter(q, c0);
        if (gk1 == b.m) scatter(q, c1 - 1);
      }
    }
    if (l - 1 >= qa && l - 1 < qb) write_out(l - 1);
  }
  if (pb == b.n && b.n - 1 >= qa && b.n - 1 < qb) write_out(b.n - 1);
}

void CosseratEnergy::internal_force(const Field<Vec3>& r, Field<Vec3>& force,
                                    Field<Vec3>* normals) {
  acceleration_or_force(r, force, normals, 1.0, Vec3{}, false);
}

void CosseratEnergy::acceleration(const Field<Vec3>& r, Field<Vec3>& a, Field<Vec3>* normals,
                                  double inverse_mass, const Vec3& offset) {
  acceleration_or_force(r, a, normals, inverse_mass, offset, true);
}

void CosseratEnergy::acceleration_or_force(const Field<Vec3>& r, Field<Vec3>& out,
                                           Field<Vec3>* normals, double scale,
                                           const Vec3& offset, bool per_mass) {
  const Block& b = *block_;
  all_bands(r, normals, scale, offset, per_mass,
            [&](int l, const double* x, const double* y, const double* z) {
              double* o = &out(b.k0, l).x;  // three packed doubles a node, as load_row reads
#pragma omp simd
              for (int i = 0; i < b.owned_k(); ++i) {
                o[3 * i] = x[i];
                o[3 * i + 1] = y[i];
                o[3 * i + 2] = z[i];
              }
            });
}

void CosseratEnergy::internal_force_rows(const Field<Vec3>& r, double inverse_mass,
                                         const Vec3& offset, const RowConsumer& consume) {
  all_bands(r, nullptr, inverse_mass, offset, true, consume);
}

template <bool Trapezoidal>
void CosseratEnergy::bands_of(const Field<Vec3>& r, Field<Vec3>* normals, double scale,
                              const Vec3& offset, bool per_mass, const RowConsumer& consume,
                              int qa, int qb, RowScratch& s) const {
  const bool bending = terms_.bending, coupling = terms_.coupling;
  if (normals != nullptr) {
    if (!bending)
      band<Trapezoidal, false, false, true>(r, normals, scale, offset, per_mass, consume, qa,
                                            qb, s);
    else if (coupling)
      band<Trapezoidal, true, true, true>(r, normals, scale, offset, per_mass, consume, qa, qb,
                                          s);
    else
      band<Trapezoidal, true, false, true>(r, normals, scale, offset, per_mass, consume, qa,
                                           qb, s);
  } else {
    if (!bending)
      band<Trapezoidal, false, false, false>(r, normals, scale, offset, per_mass, consume, qa,
                                             qb, s);
    else if (coupling)
      band<Trapezoidal, true, true, false>(r, normals, scale, offset, per_mass, consume, qa,
                                           qb, s);
    else
      band<Trapezoidal, true, false, false>(r, normals, scale, offset, per_mass, consume, qa,
                                            qb, s);
  }
}

void CosseratEnergy::all_bands(const Field<Vec3>& r, Field<Vec3>* normals, double scale,
                               const Vec3& offset, bool per_mass, const RowConsumer& consume) {
  const Block& b = *block_;
  const int gk0 = std::max(b.k0 - 1, 0), gk1 = std::min(b.k1 + 1, b.m);
  // Columns from gk0 − 1 to gk1, and the last interior block's lanes past it.
  const int columns = (gk1 - gk0 + 2) + 2 * kLanes;
  const int planned = omp_get_max_threads();
  if (static_cast<int>(scratch_.size()) < planned)
    scratch_.resize(static_cast<std::size_t>(planned));
  const std::vector<long>& first_row = balance_.split(b.owned_l(), planned);
#pragma omp parallel num_threads(planned)
  {
    const int t = omp_get_thread_num();
    const double start = omp_get_wtime();
    // Each thread sizes, and so first touches, its own buffers.
    RowScratch& s = scratch_[static_cast<std::size_t>(t)];
    s.resize(columns);
    // The runtime may give fewer threads than asked for (OMP_DYNAMIC): then an even split.
    const long threads = omp_get_num_threads(), rows = b.owned_l();
    const bool planned_split = threads == planned;
    auto band_start = [&](long i) {
      return b.l0 + static_cast<int>(planned_split ? first_row[static_cast<std::size_t>(i)]
                                                   : rows * i / threads);
    };
    const int qa = band_start(t), qb = band_start(t + 1);
    if (qa < qb) {
      if (quadrature_ == Quadrature::trapezoidal)
        bands_of<true>(r, normals, scale, offset, per_mass, consume, qa, qb, s);
      else
        bands_of<false>(r, normals, scale, offset, per_mass, consume, qa, qb, s);
    }
    if (planned_split) balance_.record(t, omp_get_wtime() - start);
  }
  balance_.rebalance();
}

double CosseratEnergy::block_energy(const Field<Vec3>& r) const {
  const Block& b = *block_;
  std::vector<double> row_energy(static_cast<std::size_t>(b.owned_l()), 0.0);
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l) {
    double sum = 0.0;
    for (int k = b.k0; k < b.k1; ++k) sum += node_energy(r, k, l, nullptr);
    row_energy[static_cast<std::size_t>(l - b.l0)] = sum;
  }
  double total = 0.0;
  for (const double e : row_energy) total += e;
  return total;
}

void CosseratEnergy::energy_density(const Field<Vec3>& r, Field<double>& density) const {
  const Block& b = *block_;
  const double area = h1_ * h2_;
  if (quadrature_ == Quadrature::nodal) {
#pragma omp parallel for schedule(static)
    for (int l = b.l0; l < b.l1; ++l)
      for (int k = b.k0; k < b.k1; ++k) density(k, l) = node_energy(r, k, l, nullptr) / area;
    return;
  }
  const NodeMass share = node_mass(1.0);
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      // The node's own terms, half of each of its edges, a quarter of each of its cells; the
      // edges and cells behind it are the forward ones of the nodes behind.
      auto parts = [&](int dk, int dl) {
        Parts p;
        if (k + dk >= 0 && l + dl >= 0)
          trapezoidal_energy(r, k + dk, l + dl, nullptr, nullptr, &p, dk == 0 && dl == 0);
        return p;
      };
      const Parts here = parts(0, 0), left = parts(-1, 0), down = parts(0, -1),
                  down_left = parts(-1, -1);
      const double e = here.node + 0.5 * ((here.edge1 + left.edge1) + (here.edge2 + down.edge2)) +
                       0.25 * (((here.cell + left.cell) + down.cell) + down_left.cell);
      density(k, l) = e / (share.weight(k, l) * area);
    }
}

}  // namespace cosserat
