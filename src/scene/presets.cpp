// Material presets (docs/materials.md): fabrics at their real size from KES-F numbers (denim's
// measured; cotton's, wool's and polyester's bending rigidity and weight measured, the rest
// typical values), and the published 10 m calibrations under names of their own.

#include <algorithm>
#include <cmath>
#include <numbers>

#include "cosserat/model/material.hpp"

namespace cosserat {
namespace {

// A fabric as the Kawabata evaluation system (KES-F) measures it, warp and weft averaged, with
// its areal density. KES-F gives forces in gram-force and lengths in centimetres.
struct FabricMeasurement {
  const char* name;
  double grams_per_square_metre;
  double bending_rigidity;    // B, gf cm²/cm
  double shear_rigidity;      // G, gf/(cm degree)
  double extension_at_500;    // EMT, %: the strain under a tension of 500 gf/cm
  double coupling_fraction;   // φ as a fraction of its bound 2√(ζξ); no instrument measures it
};

constexpr double kGramForce = 9.80665e-3;  // N
constexpr double kCentimetre = 1e-2;       // m

// For a flat rest sheet with u ⊥ v, A^{αα} = 1 and A^{12} = 0, so Φ¹¹ = 3ζ₁₁, Φ¹² = ζ₁₂ and
// Ψ¹¹ = 3ξ₁₁ (MODEL.md §1), and the energy per unit area of a small stretch e, shear angle γ
// and curvature κ is 3ζ₁₁e² + ζ₁₂γ²/2 + 3ξ₁₁κ² (ε₁₁ = e, ε₁₂ = γ/2; the sum over α, β counts
// the 12 term twice). Tension per unit width is then 6ζ₁₁e, shear force per unit width ζ₁₂γ,
// bending moment per unit width 6ξ₁₁κ: ζ₁₁ = K/6, ζ₁₂ = G, ξ = B/6 (tests/unit/
// test_energy_form.cpp, MaterialConstants, checks the three against the energy of the grid).
Preset measured_fabric(const FabricMeasurement& fabric) {
  const double bending = fabric.bending_rigidity * kGramForce * kCentimetre;  // N m
  const double shear =
      fabric.shear_rigidity * kGramForce / kCentimetre * (180.0 / std::numbers::pi);  // N/m
  // The secant stiffness up to 500 gf/cm, far above the tensions a hanging sheet carries: it
  // sets the membrane wave speed, and so the stable step, more than the shape.
  const double tensile =
      500.0 * kGramForce / kCentimetre / (fabric.extension_at_500 / 100.0);  // N/m
  const Sym2 zeta{tensile / 6.0, shear, tensile / 6.0};
  const double curvature = bending / 6.0;
  const Sym2 xi{curvature, curvature, curvature};
  Sym2 phi{};
  for (std::size_t i = 0; i < phi.size(); ++i)
    phi[i] = fabric.coupling_fraction * 2.0 * std::sqrt(zeta[i] * xi[i]);
  return {fabric.name, fabric.grams_per_square_metre / 1000.0, 1.0, zeta, xi, phi};
}

Preset calibration(const char* name, double mass_of_10x10, double zeta, double xi, double phi) {
  return {name, mass_of_10x10, 100.0, {zeta, zeta, zeta}, {xi, xi, xi}, {phi, phi, phi}};
}

// φ of a calibration as a fraction of 2√(ζξ): the coupling its fabric is given at real size.
double coupling_fraction(double zeta, double xi, double phi) {
  return phi / (2.0 * std::sqrt(zeta * xi));
}

}  // namespace

const std::vector<Preset>& material_presets() {
  // Sources and the reasons for each number: docs/materials.md. Denim's KES-F numbers come from
  // one published table; cotton's, wool's and polyester's B and weight from another (Matsudaira
  // et al. 2015, fabrics A, B and C), their G and EMT are typical values; silk and linen are
  // typical values throughout, unverified, kept until a measured specimen replaces them. Wool
  // and polyester have no calibration; their coupling is 0.03, inside the calibrations' 0.0025
  // (linen) to 0.05 (silk).
  static const std::vector<Preset> presets{
      measured_fabric({"silk", 60.0, 0.03, 0.4, 8.0, coupling_fraction(100.0, 0.01, 0.1)}),
      measured_fabric({"cotton", 123.8, 0.118, 1.0, 4.0, coupling_fraction(100.0, 0.02, 0.1)}),
      measured_fabric({"linen", 180.0, 0.30, 1.5, 3.0, coupling_fraction(100.0, 0.04, 0.01)}),
      measured_fabric({"wool", 162.9, 0.067, 0.6, 5.0, 0.03}),
      measured_fabric({"polyester", 116.5, 0.077, 0.8, 3.0, 0.03}),
      measured_fabric({"denim", 324.0, 0.172, 2.18, 5.515, coupling_fraction(100.0, 0.03, 0.1)}),
      calibration("silk-10m", 78.0, 100.0, 0.01, 0.1),
      calibration("cotton-10m", 88.0, 100.0, 0.02, 0.1),
      calibration("denim-10m", 111.0, 100.0, 0.03, 0.1),
      calibration("canvas-10m", 133.0, 100.0, 0.05, 0.1),
      calibration("satin-10m", 100.0, 100.0, 0.01, 0.01),
      calibration("linen-10m", 120.0, 100.0, 0.04, 0.01),
      calibration("velvet-10m", 110.0, 100.0, 0.025, 0.1),
      calibration("coated-cotton-10m", 125.0, 200.0, 0.05, 0.01),
      calibration("sheer-curtain-10m", 70.0, 100.0, 0.005, 0.1),
      calibration("heavy-curtain-10m", 120.0, 100.0, 0.2, 0.1),
      calibration("shower-curtain-10m", 90.0, 100.0, 0.05, 0.1),
      calibration("flag-10m", 90.0, 100.0, 0.01, 0.1),
  };
  return presets;
}

std::optional<Preset> find_preset(const std::string& name) {
  const auto& presets = material_presets();
  const auto found = std::find_if(presets.begin(), presets.end(),
                                  [&](const Preset& preset) { return preset.name == name; });
  if (found == presets.end()) return std::nullopt;
  return *found;
}

}  // namespace cosserat
