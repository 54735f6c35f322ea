#include "cosserat/model/wave_speed.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cosserat {

// Linearising docs/equations.md §1 about the flat rest sheet (A_αβ = δ_αβ): Φ¹¹ = 3ζ₁₁,
// Φ¹² = ζ₁₂, so an in-plane displacement u obeys μ ü₁ = 6ζ₁₁ u₁,₁₁ + ζ₁₂ u₁,₂₂
// + …, and a normal one μ ẅ = −6ξ₁₁ w,₁₁₁₁ − …. On the grid the highest mode
// has wave number π/h, where the compact second difference is 4/h² and the
// fourth 16/h⁴; central differences are stable while ω Δt ≤ 2
// (docs/stability.md).
CflEstimate cfl_estimate(const Material& m, double density, double h1, double h2) {
  const double h[2] = {h1, h2};
  CflEstimate e{};
  e.membrane_dt = std::numeric_limits<double>::infinity();
  e.bending_dt = std::numeric_limits<double>::infinity();
  // Sym2 is {t11, t12, t22}.
  const double zeta_aa[2] = {m.zeta[0], m.zeta[2]};
  const double xi_aa[2] = {m.xi[0], m.xi[2]};
  e.shear_speed = std::sqrt(std::max(m.zeta[1], 0.0) / density);
  for (int a = 0; a < 2; ++a) {
    const int b = 1 - a;
    const double longitudinal = std::sqrt(6.0 * zeta_aa[a] / density);
    e.longitudinal_speed = std::max(e.longitudinal_speed, longitudinal);
    const double rate2 =
        longitudinal * longitudinal / (h[a] * h[a]) + e.shear_speed * e.shear_speed / (h[b] * h[b]);
    e.membrane_dt = std::min(e.membrane_dt, 1.0 / std::sqrt(rate2));
    if (xi_aa[a] > 0.0) {
      e.bending_dt =
          std::min(e.bending_dt, h[a] * h[a] / (2.0 * std::sqrt(6.0 * xi_aa[a] / density)));
    }
  }
  e.dt = std::min(e.membrane_dt, e.bending_dt);
  return e;
}

}  // namespace cosserat
