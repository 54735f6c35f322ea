#include "cosserat/model/model_spec.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cosserat {

namespace {

// docs/model.md, "Its step": a plane wave on the rest grid moves a node against its springs
// with ω² m ≤ 4 ke for the structural pair (x and y springs are orthogonal), 4 ke for the
// bend pair, and 4 ke (1 + |cos β|) for the two diagonals at angle β to each other; central
// differences are stable while ω Δt ≤ 2.
CflEstimate spring_step_estimate(const ModelSpec& spec) {
  const SpringSpec& s = spec.springs;
  const double h1 = spec.h1, h2 = spec.h2;
  const double diagonal_cos = std::abs(h1 * h1 - h2 * h2) / (h1 * h1 + h2 * h2);
  const double stiffness =
      4.0 * (s.structural.ke + s.bend.ke + s.shear.ke * (1.0 + diagonal_cos));
  const double m = spec.particle_mass;
  CflEstimate e{};
  e.longitudinal_speed = std::max(h1, h2) * std::sqrt(s.structural.ke / m);
  e.shear_speed = std::sqrt(h1 * h1 + h2 * h2) * std::sqrt(s.shear.ke / m);
  e.membrane_dt =
      stiffness > 0.0 ? 2.0 / std::sqrt(stiffness / m) : std::numeric_limits<double>::infinity();
  e.bending_dt = std::numeric_limits<double>::infinity();
  e.dt = e.membrane_dt;
  return e;
}

}  // namespace

// docs/models.md, "Matched springs". Per unit area of square cells, a small strain ε stores
// ½ ke_st (ε₁₁² + ε₂₂²) in the structural springs, ke_sh ((ε₁₁ + ε₂₂)²/2 + 2 ε₁₂²) in the two
// diagonals and 2 ke_b (ε₁₁² + ε₂₂²) in the bend springs; the Cosserat sheet 3 ζ (ε₁₁² + ε₂₂²)
// + 2 ζ₁₂ ε₁₂² (docs/materials.md, "What ζ, ξ and φ measure"). So ke_sh = ζ₁₂ and ke_st + 4 ke_b
// = 6 ζ − ζ₁₂. Bent to curvature κ across the rows, a chord of n spacings shortens by
// n³ h³ κ²/24: the structural and shear springs then store what the Cosserat sheet's shortened
// edges do, and the bend springs 30 ke_b h⁴ κ⁴/576 more, which is its 3 ξ κ² at κ = 1/c for
// ke_b = 57.6 ξ c²/h⁴.
std::optional<MatchedSprings> matched_springs(const Material& material, double density,
                                              double h) {
  constexpr double kStandardGravity = 9.80665;  // m/s², the bending length's (docs/materials.md)
  const double zeta = 0.5 * (material.zeta[0] + material.zeta[2]);
  const double shear = material.zeta[1];
  const double xi = 0.5 * (material.xi[0] + material.xi[2]);
  const double tension = 6.0 * zeta - shear;  // ke_st + 4 ke_b
  if (!(tension > 0.0)) return std::nullopt;
  MatchedSprings m;
  double bend = 0.0;
  if (xi > 0.0) {
    m.bending_length = std::cbrt(6.0 * xi / (density * kStandardGravity));
    const double c2 = m.bending_length * m.bending_length;
    const double matching = 57.6 * xi * c2 / (h * h * h * h);
    bend = std::min(matching, tension / 8.0);
    m.bending_share = bend / matching;
  }
  m.springs.structural.ke = tension - 4.0 * bend;
  m.springs.shear.ke = shear;
  m.springs.bend.ke = bend;
  return m;
}

CflEstimate rest_step_estimate(const ModelSpec& spec) {
  if (spec.kind == ModelKind::mass_spring) return spring_step_estimate(spec);
  return cfl_estimate(spec.material, spec.density, spec.h1, spec.h2);
}

// A membrane strain ε = (λ² − 1)/2 along an edge stretched by λ stiffens the edge: the second
// derivative of Φ ε² with respect to λ is Φ (3λ² − 1) (docs/equations.md §2.5 with ε_αα as in
// §2.1), so the membrane wave speed grows by √((3λ² − 1)/2) over the rest sheet's. Bending's
// rate is that of the rest sheet (it does not stiffen with stretch to first order). A spring
// keeps ke along itself and gains the tension's ke (1 − 1/λ) across (docs/model.md, "Its
// step").
double stretched_step_estimate(const ModelSpec& spec, double stretch2) {
  const CflEstimate cfl = rest_step_estimate(spec);
  if (spec.kind == ModelKind::mass_spring)
    return cfl.dt / std::sqrt(2.0 - 1.0 / std::sqrt(std::max(1.0, stretch2)));
  const double stiffening = std::max(1.0, 0.5 * (3.0 * stretch2 - 1.0));
  return std::min(cfl.membrane_dt / std::sqrt(stiffening), cfl.bending_dt);
}

}  // namespace cosserat
