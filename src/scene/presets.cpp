// Material presets (docs/materials.md): fabrics at their real size from KES-F numbers (denim's
// measured; cotton's, wool's and polyester's bending rigidity and weight measured, the rest
// typical values, not measured), the ten fabrics Wang, O'Brien and Ramamoorthi (2011) measured,
// and the published 10 m calibrations under names of their own.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "cosserat/model/material.hpp"
#include "cosserat/model/model_spec.hpp"

namespace cosserat {
namespace {

// φ_αβ as the fraction r of its bound 2√(ζ_αβ ξ_αβ), entry by entry.
Sym2 coupling(const Sym2& zeta, const Sym2& xi, double fraction) {
  Sym2 phi{};
  for (std::size_t i = 0; i < phi.size(); ++i) phi[i] = fraction * 2.0 * std::sqrt(zeta[i] * xi[i]);
  return phi;
}

// A fabric as the Kawabata evaluation system (KES-F) measures it, warp and weft averaged, with
// its areal density. KES-F gives forces in gram-force and lengths in centimetres.
struct KesFabric {
  const char* name;
  double grams_per_square_metre;
  double bending_rigidity;    // B, gf cm²/cm
  double shear_rigidity;      // G, gf/(cm degree)
  double extension_at_500;    // EMT, %: the strain under a tension of 500 gf/cm
  double coupling_fraction;   // φ as a fraction of its bound 2√(ζξ); no instrument measures it
  double thickness_mm;        // typical of the fabric, not measured
};

constexpr double kGramForce = 9.80665e-3;  // N
constexpr double kCentimetre = 1e-2;       // m

// For a flat rest sheet with u ⊥ v, A^{αα} = 1 and A^{12} = 0, so Φ¹¹ = 3ζ₁₁, Φ¹² = ζ₁₂ and
// Ψ¹¹ = 3ξ₁₁ (docs/equations.md §1), and the energy per unit area of a small stretch e, shear
// angle γ and curvature κ is 3ζ₁₁e² + ζ₁₂γ²/2 + 3ξ₁₁κ² (ε₁₁ = e, ε₁₂ = γ/2; the sum over α, β
// counts the 12 term twice). Tension per unit width is then 6ζ₁₁e, shear force per unit width ζ₁₂γ,
// bending moment per unit width 6ξ₁₁κ: ζ₁₁ = K/6, ζ₁₂ = G, ξ = B/6 (tests/unit/
// test_energy_form.cpp, MaterialConstants, checks the three against the energy of the grid).
Preset kes_fabric(const KesFabric& fabric) {
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
  return {fabric.name, fabric.grams_per_square_metre / 1000.0, 1.0, zeta, xi,
          coupling(zeta, xi, fabric.coupling_fraction), fabric.thickness_mm * 1e-3};
}

// A fabric as H. Wang, J. F. O'Brien and R. Ramamoorthi, "Data-driven elastic models for cloth:
// modeling and measurement", ACM Transactions on Graphics 30(4), article 71 (2011) measured it,
// the numbers read from the material files the ARCSim simulator distributes
// (materials/<name>.json): the zero-strain row of the stretching table, in ARCSim's reading
// (its stiffness is twice these), without c12, which the model has no term for; and the
// zero-curvature column of the bending table, one coefficient per hinge direction.
struct WangFabric {
  const char* name;
  double density;     // kg/m²
  double c11;         // stretching row 0, N/m: along u
  double c22;         // along v
  double c33;         // shear
  double bending_0;   // k_e of a hinge along u (bends the cloth along v), N m
  double bending_45;  // hinge at 45°
  double bending_90;  // hinge along v (bends the cloth along u)
  double thickness_mm;  // not in the measurements: typical of the fabric's kind
};

// No instrument measures φ: the fraction of its bound the KES-F presets without a calibration
// take (0.03), inside the calibrations' 0.0025-0.05. It lowers the bending rigidity of a strip
// that is free to stretch by the factor 1 - r² (0.09 %).
constexpr double kWangCouplingFraction = 0.03;

// docs/materials.md, "Measured fabrics: Wang et al. (2011)": u is x¹ and v is x². The stretching
// energy ARCSim takes at small strain, c11 E_uu² + c22 E_vv² + c33 E_uv² (+ 2 c12 E_uu E_vv), is
// the model's 3ζ₁₁ε₁₁² + 3ζ₂₂ε₂₂² + 2ζ₁₂ε₁₂² term by term; a hinge coefficient k_e is a
// bending rigidity B ≈ k_e/4, B = 6ξ along x¹ and x², and at 45° B₄₅ = (B₁ + B₂)/4 + ξ₁₂.
Preset wang_fabric(const WangFabric& fabric) {
  const Sym2 zeta{fabric.c11 / 3.0, fabric.c33 / 2.0, fabric.c22 / 3.0};
  const double rigidity_1 = fabric.bending_90 / 4.0;   // N m, curvature along x¹
  const double rigidity_2 = fabric.bending_0 / 4.0;    // along x²
  const double rigidity_45 = fabric.bending_45 / 4.0;  // along the diagonal
  const Sym2 xi{rigidity_1 / 6.0, rigidity_45 - (rigidity_1 + rigidity_2) / 4.0,
                rigidity_2 / 6.0};
  return {fabric.name, fabric.density, 1.0, zeta, xi,
          coupling(zeta, xi, kWangCouplingFraction), fabric.thickness_mm * 1e-3};
}

// The calibrations name no fabric's thickness: they take a typical woven cloth's, 0.5 mm.
Preset calibration(const char* name, double mass_of_10x10, double zeta, double xi, double phi) {
  return {name, mass_of_10x10, 100.0, {zeta, zeta, zeta}, {xi, xi, xi}, {phi, phi, phi}, 0.5e-3};
}

// φ of a calibration as a fraction of 2√(ζξ): the coupling its fabric is given at real size.
double coupling_fraction(double zeta, double xi, double phi) {
  return phi / (2.0 * std::sqrt(zeta * xi));
}

}  // namespace

const std::vector<Preset>& material_presets() {
  // Sources and the reasons for each number: docs/materials.md. Denim's KES-F numbers come from
  // one published table; cotton's, wool's and polyester's B and weight from another (Matsudaira
  // et al. 2015, fabrics A, B and C), their G and EMT are typical values, not measured; silk and
  // linen are typical values throughout, kept until a measured specimen replaces them. Wool and
  // polyester have no calibration; their coupling is 0.03, inside the calibrations' 0.0025
  // (linen) to 0.05 (silk). The ten after them are Wang, O'Brien and Ramamoorthi's (2011)
  // measurements, as ARCSim's material files give them: density (kg/m²), c11, c22, c33 of the
  // stretching table's row 0 (N/m), k_e of its bending table's column 0 at 0°, 45° and 90° (N m).
  static const std::vector<Preset> presets{
      // Typical values throughout, not measured.
      kes_fabric({"silk", 60.0, 0.03, 0.4, 8.0, coupling_fraction(100.0, 0.01, 0.1), 0.1}),
      // B and weight measured; G and EMT typical values.
      kes_fabric({"cotton", 123.8, 0.118, 1.0, 4.0, coupling_fraction(100.0, 0.02, 0.1), 0.3}),
      // Typical values throughout, not measured.
      kes_fabric({"linen", 180.0, 0.30, 1.5, 3.0, coupling_fraction(100.0, 0.04, 0.01), 0.4}),
      // B and weight measured; G and EMT typical values.
      kes_fabric({"wool", 162.9, 0.067, 0.6, 5.0, 0.03, 0.6}),
      kes_fabric({"polyester", 116.5, 0.077, 0.8, 3.0, 0.03, 0.25}),
      // Measured (KES-F); its density is 11oz-black-denim's.
      kes_fabric({"denim", 324.0, 0.172, 2.18, 5.515, coupling_fraction(100.0, 0.03, 0.1), 0.8}),
      wang_fabric({"11oz-black-denim", 0.324, 205.352, 1013.89, 53.3872, 6.41965e-05,
                   7.33846e-05, 9.69516e-05, 0.8}),
      wang_fabric({"royal-target", 0.22, 2016.55, 2034.98, 104.76, 0.00012541, 0.000107998,
                   0.00012541, 0.45}),
      wang_fabric({"gray-interlock", 0.187, 16.5938, 34.4771, 36.8603, 2.31917e-05, 2.475e-05,
                   1.42676e-05, 0.7}),
      wang_fabric({"ivory-rib-knit", 0.276, 42.871, 65.166, 83.1756, 4.62376e-05, 3.00159e-05,
                   3.22439e-05, 0.9}),
      wang_fabric({"white-dots-on-blk", 0.128, 2002.09, 2027.49, 19.189, 5.17138e-05,
                   4.06595e-05, 3.12828e-05, 0.25}),
      wang_fabric({"pink-ribbon-brown", 0.228, 151.504, 244.831, 30.2502, 0.00011707,
                   8.75098e-05, 5.97743e-05, 0.45}),
      wang_fabric({"tango-red-jet-set", 0.113, 43.0676, 171.425, 14.3147, 1.42938e-05,
                   2.19517e-05, 2.03457e-05, 0.5}),
      wang_fabric({"navy-sparkle-sweat", 0.224, 12.4863, 3.27243, 17.6163, 5.94697e-05,
                   4.00723e-05, 4.5625e-05, 0.9}),
      wang_fabric({"camel-ponte-roma", 0.284, 31.1462, 44.0287, 31.8964, 3.63484e-05,
                   3.30133e-05, 3.71576e-05, 1.0}),
      wang_fabric({"white-swim-solid", 0.204, 47.9712, 104.615, 60.7737, 6.02379e-05,
                   5.88032e-05, 5.10188e-05, 0.6}),
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

const std::vector<SpringPreset>& spring_presets() {
  // Every family alike, as the source had them; lengths in rest lengths.
  auto alike = [](double ke, double kd, double dead_zone, double shortest, double longest) {
    SpringSpec s;
    s.structural = s.shear = s.bend = SpringFamily{ke, kd};
    s.dead_zone = dead_zone;
    s.min_length = shortest;
    s.max_length = longest;
    return s;
  };
  constexpr double kOpen = std::numeric_limits<double>::infinity();
  static const std::vector<SpringPreset> presets{
      {"source-sheet", alike(4.0, 0.8, 0.001, 0.1, 10.0),
       "the source's return-to-equilibrium sheet: 10 g particles 0.225 m apart"},
      {"source-net", alike(100.0, 20.0, 0.0, 0.0, kOpen),
       "the source's net that a thrown cube deforms: 15 g particles 0.225 m apart"},
      {"source-stiff-net", alike(250.0, 50.0, 0.0, 0.0, kOpen),
       "the source's stiffer net: 15 g particles 0.225 m apart"},
      {"source-pressed-sheet", alike(1000.0, 200.0, 0.0, 0.0, kOpen),
       "the source's sheet pressed onto a plane: 10 g particles 0.224 m apart"},
  };
  return presets;
}

std::optional<SpringPreset> find_spring_preset(const std::string& name) {
  for (const SpringPreset& preset : spring_presets())
    if (name == preset.name) return preset;
  return std::nullopt;
}

}  // namespace cosserat
