#include "cosserat/model/cosserat_energy.hpp"

#include <algorithm>
#include <vector>

#include "surface_geometry.hpp"

// Reach: E_p reads the 3 × 3 box around p, so the force at q reads the gradients of the nodes
// p within one node of q, which read positions within two nodes of q: the same two ghost rings
// as the flux form (kGhostWidth = 2). The gradients of the ring around the owned range are
// computed redundantly rather than exchanged.

namespace cosserat {

namespace {

using geometry::Neighbours;

// Stencil slot of the node (k + dk, l + dl) around p = (k, l).
constexpr int slot(int dk, int dl) { return 3 * (dl + 1) + (dk + 1); }

// Which terms of E_p exist (MODEL.md §2.5): §2.3 rule 1 leaves the shear terms (ε₁₂, κ₁₂) out
// on the far borders, rule 2 leaves κ_αα out at nodes lacking an α-neighbour.
struct Terms {
  bool shear, bend11, bend22;
};

inline Terms terms_of(const Neighbours& p) {
  return {p.right && p.up, p.left && p.right, p.down && p.up};
}

// The unit normal n = s/|s| of §2.1 rule 2, s the sum of the unit normals of p's corner
// triangles, with what its gradient needs: computed once per node for both. The arithmetic is
// geometry::unit_normal's, so n is the same bits.
struct CornerNormals {
  struct Corner {
    int ek, el, fk, fl;  // the offsets of the corner's two edges' far nodes
    Vec3 E, F;           // the edges r_e − r, r_f − r
    Vec3 unit;           // (E × F)/|E × F|
    double length;       // |E × F|
  };
  Corner corner[4];
  int count = 0;
  double sum_length = 0.0;  // |s|
  Vec3 n;
};

CornerNormals corner_normals(const Field<Vec3>& R, int k, int l, const Neighbours& p) {
  const Vec3 r = R(k, l);
  CornerNormals c;
  auto add = [&](int ek, int el, int fk, int fl) {
    CornerNormals::Corner& q = c.corner[c.count++];
    q = {ek, el, fk, fl, R(k + ek, l + el) - r, R(k + fk, l + fl) - r, {}, 0.0};
    const Vec3 cross_product = cross(q.E, q.F);
    q.length = norm(cross_product);
    q.unit = cross_product / q.length;
  };
  if (p.right && p.up) add(1, 0, 0, 1);
  if (p.up && p.left) add(0, 1, -1, 0);
  if (p.left && p.down) add(-1, 0, 0, -1);
  if (p.down && p.right) add(0, -1, 1, 0);
  Vec3 sum;
  for (int i = 0; i < c.count; ++i) sum += c.corner[i].unit;
  c.sum_length = norm(sum);
  c.n = sum / c.sum_length;
  return c;
}

// Adds the gradient that flows back through n, given G_n = ∂E/∂n.
void add_normal_gradient(const CornerNormals& c, const Vec3& G_n,
                         CosseratEnergy::StencilGradient& g) {
  // d(s/|s|) projects out n and divides by |s|; the same for each corner's c/|c|.
  const Vec3 G_s = (G_n - dot(G_n, c.n) * c.n) / c.sum_length;
  for (int i = 0; i < c.count; ++i) {
    const CornerNormals::Corner& q = c.corner[i];
    const Vec3 G_c = (G_s - dot(G_s, q.unit) * q.unit) / q.length;
    // c = E × F: G_c · (δE × F) = δE · (F × G_c), G_c · (E × δF) = δF · (G_c × E).
    const Vec3 G_E = cross(q.F, G_c), G_F = cross(G_c, q.E);
    g[slot(q.ek, q.el)] += G_E;
    g[slot(q.fk, q.fl)] += G_F;
    g[slot(0, 0)] -= G_E + G_F;
  }
}

}  // namespace

CosseratEnergy::CosseratEnergy(const Block& block, double h1, double h2, const RestState& rest)
    : block_(&block), h1_(h1), h2_(h2), rest_(rest) {}

// E_p = h₁h₂ Σ_αβ (Φ^{αβ} ε_αβ² + Ψ^{αβ} κ_αβ² + Θ^{αβ} ε_αβ κ_αβ) (MODEL.md §2.5): the sum
// over α, β counts the (1, 2) terms twice. Strains as §2.1 computes them.
double CosseratEnergy::node_energy(const Field<Vec3>& R, int k, int l, StencilGradient* gradient,
                                   Vec3* normal) const {
  using namespace geometry;
  const Neighbours p = neighbours(*block_, k, l);
  const Terms has = terms_of(p);
  const double h1 = h1_, h2 = h2_;
  const Tangents a = tangents(R, k, l, p, h1, h2);
  const CornerNormals corners = corner_normals(R, k, l, p);
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

  double energy = Phi[0] * epsilon[0] * epsilon[0] + Phi[2] * epsilon[2] * epsilon[2];
  if (has.bend11) energy += Psi[0] * k11 * k11 + Theta[0] * epsilon[0] * k11;
  if (has.bend22) energy += Psi[2] * k22 * k22 + Theta[2] * epsilon[2] * k22;
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

  // κ_αβ = −n · r_,αβ: ∂/∂r_,αβ = −M n, ∂/∂n = −Σ M r_,αβ.
  Vec3 G_n;
  if (has.bend11) {
    const Vec3 G_X = (-M11 / (h1 * h1)) * n;
    G[slot(1, 0)] += G_X;
    G[slot(-1, 0)] += G_X;
    G[slot(0, 0)] -= 2.0 * G_X;
    G_n -= M11 * X.r11;
  }
  if (has.bend22) {
    const Vec3 G_X = (-M22 / (h2 * h2)) * n;
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

void CosseratEnergy::internal_force(const Field<Vec3>& r, Field<Vec3>& force,
                                    Field<Vec3>* normals) {
  const Block& b = *block_;
  // A flux-form run asks only for the energy, and never carries this field.
  if (!has_gradient_field_) {
    gradient_ = Field<StencilGradient>(b);
    has_gradient_field_ = true;
  }
  // Gradients on the owned range grown by one node, clipped to the grid.
  const int gk0 = std::max(b.k0 - 1, 0), gk1 = std::min(b.k1 + 1, b.m);
  const int gl0 = std::max(b.l0 - 1, 0), gl1 = std::min(b.l1 + 1, b.n);
#pragma omp parallel
  {
#pragma omp for schedule(static)
    for (int l = gl0; l < gl1; ++l)
      for (int k = gk0; k < gk1; ++k) {
        Vec3 n;
        node_energy(r, k, l, &gradient_(k, l), &n);
        if (normals != nullptr && b.owns(k, l)) (*normals)(k, l) = n;
      }

    // f_q = −Σ_p ∂E_p/∂r_q over the nodes p around q, in one fixed order.
#pragma omp for schedule(static)
    for (int l = b.l0; l < b.l1; ++l)
      for (int k = b.k0; k < b.k1; ++k) {
        Vec3 f;
        for (int dl = -1; dl <= 1; ++dl)
          for (int dk = -1; dk <= 1; ++dk) {
            const int pk = k + dk, pl = l + dl;
            if (pk < 0 || pk >= b.m || pl < 0 || pl >= b.n) continue;
            f -= gradient_(pk, pl)[slot(-dk, -dl)];
          }
        force(k, l) = f;
      }
  }
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

}  // namespace cosserat
