#pragma once
// A sheet folded into two layers, for the self-contact tests (docs/contact.md,
// "Self-contact"): scenes start flat, so the fold is written into the scheme's state.

#include <algorithm>
#include <cstddef>
#include <string>

#include "cosserat/contact/geometry.hpp"
#include "cosserat/time/simulation.hpp"
#include "support/sheets.hpp"

namespace cosserat::testing {

// A 0.5 m x 1 m sheet of 11 x 20 nodes (h = 0.05 m along both axes), soft, self-contact on
// with the thickness given; no gravity unless the caller adds it. Verlet, 2e-5 s steps.
inline Scene layered_sheet(double thickness) {
  Scene s = flat_sheet(11, 20);
  s.size1 = 0.5;
  s.size2 = 0.95;
  s.material.mass = 0.1;
  s.material.zeta = {20.0, 20.0, 20.0};
  s.material.xi = {1e-4, 1e-4, 1e-4};
  s.material.phi = {0.0, 0.0, 0.0};
  s.material.thickness = thickness;
  s.self_contact = SelfContactSpec{thickness, 0.3};
  s.dt = 2e-5;
  return s;
}

// The layered sheet under gravity in 1e-4 s steps, over a floor: the plane y = 0 with an offset
// of 1 mm (where fold(sim, s, 1e-3, ...) lays the bottom layer) and `friction`.
inline Scene layers_over_a_floor(double thickness, double friction) {
  Scene s = layered_sheet(thickness);
  s.dt = 1e-4;
  s.gravity = {0.0, -9.81, 0.0};
  SolidSpec floor;
  floor.name = "floor";
  floor.shape.kind = ShapeKind::plane;
  floor.pose.orientation = rotation_between({0.0, 0.0, 1.0}, {0.0, 1.0, 0.0});
  floor.thickness = 1e-3;
  floor.friction = friction;
  s.solids.push_back(floor);
  return s;
}

// Where node (k, l) lies when the sheet is folded at its middle rows: rows below n/2 lie flat
// at height `base`, the rest `gap` above them, back over them, the fold one vertical edge.
inline Vec3 folded(const Scene& s, int k, int l, double base, double gap) {
  const double h1 = s.h1(), h2 = s.h2();
  const int half = s.n / 2;
  if (l < half) return {k * h1, base, l * h2};
  return {k * h1, base + gap, (s.n - 1 - l) * h2};
}

// The top layer's row over bottom row l.
inline int row_above(const Scene& s, int l) { return s.n - 1 - l; }

// Writes the folded state into the run on its block, ghosts included: the top layer (rows from
// n/2 + 1) moving at `top_velocity`, the bottom one (rows below n/2) at `bottom_velocity`, the
// fold's top row at rest. The Verlet family carries r⁻, the velocity schemes v;
// velocity-verlet's stored acceleration stays that of the flat sheet, the same on every
// decomposition.
inline void fold(Simulation& sim, const Scene& s, double base, double gap, const Vec3& top_velocity,
                 const Vec3& bottom_velocity = {}) {
  Stepper& stepper = sim.stepper();
  const auto fields = stepper.state_fields();
  Field<Vec3>& r = *fields.at(0).field;
  Field<Vec3>& second = *fields.at(1).field;
  const bool carries_velocity = std::string(fields.at(1).name) == "velocities";
  const Block& b = sim.block();
  for (int l = std::max(0, b.l0 - b.ghost); l < std::min(s.n, b.l1 + b.ghost); ++l)
    for (int k = std::max(0, b.k0 - b.ghost); k < std::min(s.m, b.k1 + b.ghost); ++k) {
      r(k, l) = folded(s, k, l, base, gap);
      const Vec3 v = l > s.n / 2 ? top_velocity : l < s.n / 2 ? bottom_velocity : Vec3{};
      second(k, l) = carries_velocity ? v : r(k, l) - s.dt * v;
    }
  stepper.resume(0);
}

}  // namespace cosserat::testing
