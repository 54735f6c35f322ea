#pragma once
// Material of MODEL.md §1: three symmetric 2x2 coefficient tensors and the mass.

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace cosserat {

// Symmetric 2x2 tensor stored as {t11, t12, t22}.
using Sym2 = std::array<double, 3>;

struct Material {
  double mass = 0.0;  // total kg of the sheet
  Sym2 zeta{};        // metric resistance
  Sym2 xi{};          // curvature resistance
  Sym2 phi{};         // buckling factor (metric-curvature coupling)
};

// A published calibration preset (SCENES.md): mass is for a 10 m x 10 m sheet.
struct Preset {
  std::string name;
  double mass_10x10;
  double zeta;
  double xi;
  double phi;
};

const std::vector<Preset>& material_presets();
std::optional<Preset> find_preset(const std::string& name);

}  // namespace cosserat
