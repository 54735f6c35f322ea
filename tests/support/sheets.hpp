#pragma once
// Scenes built in code for tests: a flat sheet with the reference sheet's defaults
// (docs/scenes.md), to be varied.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cosserat/scene/scene.hpp"
#include "cosserat/time/simulation.hpp"
#include "cosserat/time/step_loop.hpp"

namespace cosserat::testing {

// An observer of nothing: a step loop's own choices alone.
class Silent : public StepObserver {
 public:
  void frame() override {}
  void checkpoint(const LoopCarry&) override {}
  void progress(long) override {}
};

// m x n sheet, 10 m x 10 m in the xz plane, the reference sheet's material (docs/scenes.md), no
// terms at all.
inline Scene flat_sheet(int m, int n) {
  Scene s;
  s.name = "test";
  s.m = m;
  s.n = n;
  s.size1 = 10.0;
  s.size2 = 10.0;
  s.u = {1.0, 0.0, 0.0};
  s.v = {0.0, 0.0, 1.0};
  s.material.mass = 10.0;
  s.material.zeta = {100.0, 100.0, 100.0};
  s.material.xi = {0.3, 0.3, 0.3};
  s.material.phi = {0.001, 0.001, 0.001};
  s.dt = 1e-3;
  s.steps = 0;
  s.output_every = 1;
  return s;
}

// The scene text of a 2 m sheet, 24 x 24, whose step bending sets (ξ = 1 on a fine grid): there
// the CFL estimate is 1/0.61 of Verlet's measured limit (`cosserat stable-dt`: 2.97e-4 s
// against 4.88e-4 s), so adaptive steps at safety 1 overshoot and roll back. Grid, material
// and environment; the caller adds [time], fixes and loads.
inline std::string bending_sheet_text() {
  return R"(
[grid]
nodes = [24, 24]
size = [2.0, 2.0]
origin = [0.0, 0.0, 0.0]
u = [1.0, 0.0, 0.0]
v = [0.0, 0.0, 1.0]
[material]
mass = 0.4
zeta = 100.0
xi = 1.0
phi = 0.001
[environment]
gravity = [0.0, -9.8, 0.0]
damping = 0.2
)";
}

// The scene's flat rest grid, origin + k h1 u + l h2 v, at every node of `block`'s range that
// is on the grid (ghosts included).
inline Field<Vec3> rest_positions(const Scene& s, const Block& block) {
  Field<Vec3> r(block);
  for (int l = 0; l < s.n; ++l)
    for (int k = 0; k < s.m; ++k) r(k, l) = s.origin + (k * s.h1()) * s.u + (l * s.h2()) * s.v;
  return r;
}

inline Fix fix_nodes(std::vector<NodeIndex> nodes) {
  Fix f;
  f.nodes.nodes = std::move(nodes);
  return f;
}

// A smoothly but strongly deformed sheet: stretched, bent and twisted, well away from rest.
inline Vec3 deformed(const Scene& s, int k, int l) {
  const double x = k * s.h1(), z = l * s.h2();
  return {1.05 * x + 0.1 * std::sin(z), 0.8 * std::sin(0.4 * x) * std::cos(0.3 * z) + 0.02 * x * z,
          0.97 * z + 0.05 * std::cos(x)};
}

// Every scheme of the build: the semi-implicit ones exist only with PETSc.
inline std::vector<Integrator> every_scheme() {
  std::vector<Integrator> schemes;
  for (const std::string& name : integrator_names()) {
    const Integrator scheme = *integrator_from_name(name);
#if !defined(COSSERAT_HAVE_PETSC)
    if (is_semi_implicit(scheme)) continue;
#endif
    schemes.push_back(scheme);
  }
  return schemes;
}

// GoogleTest parameter name of a scheme: its scene name with '_' for '-'.
inline std::string scheme_test_name(const ::testing::TestParamInfo<Integrator>& info) {
  std::string name = integrator_name(info.param);
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}

// Runs `steps` steps; fails the test (returns false) on instability.
inline bool advance(Simulation& sim, long steps) {
  for (long i = 0; i < steps; ++i)
    if (sim.step()) return false;
  return true;
}

}  // namespace cosserat::testing
