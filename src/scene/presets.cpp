// Published material calibrations (shared/spec/SCENES.md, gallery presets).

#include <algorithm>

#include "cosserat/model/material.hpp"

namespace cosserat {

const std::vector<Preset>& material_presets() {
  // mass is the total of a 10 m x 10 m sheet: the scene loader scales it to the sheet's area.
  static const std::vector<Preset> presets{
      {"silk", 78.0, 100.0, 0.01, 0.1},
      {"cotton", 88.0, 100.0, 0.02, 0.1},
      {"denim", 111.0, 100.0, 0.03, 0.1},
      {"canvas", 133.0, 100.0, 0.05, 0.1},
      {"satin", 100.0, 100.0, 0.01, 0.01},
      {"linen", 120.0, 100.0, 0.04, 0.01},
      {"velvet", 110.0, 100.0, 0.025, 0.1},
      {"coated-cotton", 125.0, 200.0, 0.05, 0.01},
      {"sheer-curtain", 70.0, 100.0, 0.005, 0.1},
      {"heavy-curtain", 120.0, 100.0, 0.2, 0.1},
      {"shower-curtain", 90.0, 100.0, 0.05, 0.1},
      {"flag", 90.0, 100.0, 0.01, 0.1},
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
