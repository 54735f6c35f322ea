// Integrator names as written in scene files (shared/spec/MODEL.md §4).

#include <algorithm>
#include <cstddef>

#include "cosserat/scene/scene.hpp"

namespace cosserat {

const std::vector<std::string>& integrator_names() {
  // Indexed by the enum's value: keep the two in the same order.
  static const std::vector<std::string> names{
      "verlet",   "symplectic-euler", "euler",     "midpoint",      "rk4",
      "leapfrog", "velocity-verlet",  "tc-verlet", "verlet-lagged", "semi-implicit",
  };
  return names;
}

std::optional<Integrator> integrator_from_name(const std::string& name) {
  const auto& names = integrator_names();
  const auto found = std::find(names.begin(), names.end(), name);
  if (found == names.end()) return std::nullopt;
  return static_cast<Integrator>(found - names.begin());
}

const std::string& integrator_name(Integrator integrator) {
  return integrator_names().at(static_cast<std::size_t>(integrator));
}

}  // namespace cosserat
