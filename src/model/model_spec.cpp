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
