#include "cosserat/model/model_spec.hpp"

#include <algorithm>
#include <cmath>

namespace cosserat {

CflEstimate rest_step_estimate(const ModelSpec& spec) {
  return cfl_estimate(spec.material, spec.density, spec.h1, spec.h2);
}

// A membrane strain ε = (λ² − 1)/2 along an edge stretched by λ stiffens the edge: the second
// derivative of Φ ε² with respect to λ is Φ (3λ² − 1) (docs/equations.md §2.5 with ε_αα as in
// §2.1), so the membrane wave speed grows by √((3λ² − 1)/2) over the rest sheet's. Bending's
// rate is that of the rest sheet (it does not stiffen with stretch to first order).
double stretched_step_estimate(const ModelSpec& spec, double stretch2) {
  const CflEstimate cfl = rest_step_estimate(spec);
  const double stiffening = std::max(1.0, 0.5 * (3.0 * stretch2 - 1.0));
  return std::min(cfl.membrane_dt / std::sqrt(stiffening), cfl.bending_dt);
}

}  // namespace cosserat
