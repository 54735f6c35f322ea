#pragma once
// Wave speeds of the flat rest sheet and the explicit step they allow
// (docs/stability.md): the CFL estimate beside which `cosserat stable-dt`
// reports the measured limits.

#include "cosserat/model/material.hpp"

namespace cosserat {

struct CflEstimate {
  double longitudinal_speed;  // c_L = sqrt(6 ζ/μ), the largest over the two
                              // directions (m/s)
  double shear_speed;         // c_S = sqrt(ζ₁₂/μ)
  double membrane_dt;         // 1 / sqrt(c_L²/h² + c_S²/h'²), the tighter direction
  double bending_dt;          // h² / (2 sqrt(6 ξ/μ)); infinite for ξ = 0
  double dt;                  // the smaller of the two
};

// For areal density μ (kg/m²) and grid spacings h1, h2 (m).
CflEstimate cfl_estimate(const Material& material, double density, double h1, double h2);

}  // namespace cosserat
