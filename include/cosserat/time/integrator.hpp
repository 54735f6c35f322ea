#pragma once
// The time integrators by name (docs/equations.md §4). Header-only on purpose: the scene loader,
// one module below `time`, checks the name a scene gives before any work (exit 2), and a header
// of names and an enum is vocabulary, not code to link.

#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace cosserat {

enum class Integrator {
  verlet,
  symplectic_euler,
  euler,
  midpoint,
  rk4,
  leapfrog,
  velocity_verlet,
  tc_verlet,
  verlet_lagged,
  semi_implicit,    // the PETSc baseline; only in builds with PETSc
  semi_implicit_2,  // its second-order form (docs/semi-implicit.md)
};

// Names as written in scene files, in the order of the enum.
inline const std::vector<std::string>& integrator_names() {
  static const std::vector<std::string> names{
      "verlet",   "symplectic-euler", "euler",     "midpoint",      "rk4",
      "leapfrog", "velocity-verlet",  "tc-verlet", "verlet-lagged", "semi-implicit",
      "semi-implicit-2",
  };
  return names;
}

inline std::optional<Integrator> integrator_from_name(const std::string& name) {
  const auto& names = integrator_names();
  const auto found = std::find(names.begin(), names.end(), name);
  if (found == names.end()) return std::nullopt;
  return static_cast<Integrator>(found - names.begin());
}

// The PETSc baseline's steps, which solve a linear system each step.
inline bool is_semi_implicit(Integrator integrator) {
  return integrator == Integrator::semi_implicit || integrator == Integrator::semi_implicit_2;
}

inline const std::string& integrator_name(Integrator integrator) {
  return integrator_names().at(static_cast<std::size_t>(integrator));
}

}  // namespace cosserat
