#pragma once
// Material of docs/equations.md §1: three symmetric 2x2 coefficient tensors and the mass.

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace cosserat {

// Symmetric 2x2 tensor stored as {t11, t12, t22}.
using Sym2 = std::array<double, 3>;

struct Material {
  double mass = 0.0;  // total kg of the sheet
  Sym2 zeta{};        // metric resistance, N/m (J/m²)
  Sym2 xi{};          // curvature resistance, N m (J)
  Sym2 phi{};         // buckling factor (metric-curvature coupling), N
  // m: how far apart self-contact keeps the cloth's layers (docs/contact.md, "Self-contact");
  // 0 where neither the scene nor its preset gives one.
  double thickness = 0.0;
};

// A named material (docs/materials.md): the three tensors and the mass of a sheet of `area`
// square metres, whose areal density a scene keeps at any size. Measured fabrics are given per
// square metre; the published calibrations per 10 m x 10 m sheet, as published, so that a scene
// using one gets the mass M·A/100 it always got, to the bit.
struct Preset {
  std::string name;
  double mass;  // kg
  double area;  // m²
  Sym2 zeta;    // N/m
  Sym2 xi;      // N m
  Sym2 phi;     // N
  double thickness;  // m, typical of the fabric, not measured (docs/materials.md)
};

const std::vector<Preset>& material_presets();
std::optional<Preset> find_preset(const std::string& name);

}  // namespace cosserat
