// The cantilever test of textile standards on every preset measured by Wang, O'Brien and
// Ramamoorthi (2011): a strip clamped at one end, overhanging by twice its bending length,
// comes to rest under its own weight, and the bending length read from the angle of the chord
// to its tip is the preset's c = (B / (μ₀ g))^(1/3) (docs/materials.md, "The cantilever
// check").

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "cosserat/model/wave_speed.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

constexpr double kGravity = 9.81;  // m/s², as docs/materials.md's bending lengths take it

// The rest shape of an inextensible strip of constant bending rigidity under its own weight,
// clamped horizontal at s = 0 and free at s = l: B ψ'' = −w (l − s) cos ψ with ψ(0) = 0 and
// ψ'(l) = 0, ψ the slope below the horizontal. In s/l it is ψ'' = −λ (1 − t) cos ψ with
// λ = (l/c)³ alone (docs/materials.md, "The cantilever check").
struct Elastica {
  double lambda;

  struct State {
    double slope, curvature, x, y;  // ψ, dψ/dt, and the position in units of l
  };

  State derivative(double t, const State& s) const {
    return {s.curvature, -lambda * (1.0 - t) * std::cos(s.slope), std::cos(s.slope),
            std::sin(s.slope)};
  }

  // Classic RK4 from the clamp to the tip, given the curvature at the clamp.
  State tip(double clamp_curvature) const {
    constexpr int kSteps = 400;
    constexpr double dt = 1.0 / kSteps;
    State s{0.0, clamp_curvature, 0.0, 0.0};
    const auto add = [](const State& a, const State& b, double f) {
      return State{a.slope + f * b.slope, a.curvature + f * b.curvature, a.x + f * b.x,
                   a.y + f * b.y};
    };
    for (int i = 0; i < kSteps; ++i) {
      const double t = i * dt;
      const State k1 = derivative(t, s);
      const State k2 = derivative(t + dt / 2, add(s, k1, dt / 2));
      const State k3 = derivative(t + dt / 2, add(s, k2, dt / 2));
      const State k4 = derivative(t + dt, add(s, k3, dt));
      s = add(s, add(add(k1, k4, 1.0), add(k2, k3, 1.0), 2.0), dt / 6);
    }
    return s;
  }

  // Shooting on the clamp curvature ψ'(0): the tip's curvature ψ'(1) is negative at ψ'(0) = 0
  // and not below zero at ψ'(0) = λ/2, since ψ'(1) = ψ'(0) − λ ∫ (1 − t) cos ψ dt.
  double chord_angle() const {
    double low = 0.0, high = lambda / 2.0;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (low + high);
      (tip(mid).curvature < 0.0 ? low : high) = mid;
    }
    const State end = tip(0.5 * (low + high));
    return std::atan2(end.y, end.x);
  }
};

// The bending length of a strip of overhang l whose chord makes the angle θ, by the elastica:
// θ rises with l/c, so bisect on ln(l/c).
double elastica_bending_length(double chord_angle, double overhang) {
  // l/c between 0.5 and 5: a strip outside that is far off its bending length anyway.
  double low = std::log(0.5), high = std::log(5.0);
  for (int i = 0; i < 50; ++i) {
    const double mid = 0.5 * (low + high);
    (Elastica{std::exp(3.0 * mid)}.chord_angle() < chord_angle ? low : high) = mid;
  }
  return overhang / std::exp(0.5 * (low + high));
}

// Peirce's (1930) closed form of the same, as the standards print it.
double peirce_bending_length(double chord_angle, double overhang) {
  return overhang * std::cbrt(std::cos(chord_angle / 2.0) / (8.0 * std::tan(chord_angle)));
}

// Bending length of a preset along x¹ (axis 0) or x² (axis 1): B = 6ξ_αα.
double preset_bending_length(const Preset& preset, int axis) {
  const double rigidity = 6.0 * preset.xi[axis == 0 ? 0 : 2];
  return std::cbrt(rigidity / (preset.mass / preset.area * kGravity));
}

struct Cantilever {
  double bending_length;  // m, read from the chord by the elastica
  double peirce_length;   // m, by Peirce's closed form
  double chord_angle;     // rad, below the horizontal
};

// A strip of the preset along x¹ (axis 0) or x² (axis 1), three nodes across, horizontal, its
// first two rows held: a clamp, whose discrete bending hinge lies midway between the two rows
// (the curvature of the second row's nodes, counted over a whole cell, turns the strip from
// half a cell before them). Each node carries the mass of its dual area, the last node half a
// cell's, so the strip ends at its last node (docs/model.md, "Energy quadrature"). The overhang
// l = 2c runs from midway between the held rows to that end, (cells + ½) h, and the chord to
// the last node. Damped at twice the rate of the lowest bending mode, ω₁ = 1.875² √(B/(μ₀ l⁴)) =
// 0.879 √(g/c), with steps of 0.8 of the CFL estimate's membrane step or 0.5 of its bending
// step, the smaller (Verlet's measured limits are 0.88-0.94 and 0.60 of them, docs/stability.md;
// the membrane sets it but for the softest knits at 32 cells), for 15/ω₁: by then its kinetic
// energy is below 1e-9 of its peak. (A run stopped as soon as the energy first falls that low
// can stop at a turning point, where the strip still moves: 0.03 % off c.)
Cantilever hang(const std::string& name, int axis, int cells) {
  const Preset preset = *find_preset(name);
  const double c = preset_bending_length(preset, axis);
  const double overhang = 2.0 * c;
  const double h = overhang / (cells + 0.5);
  const int along = cells + 2;
  const double density = preset.mass / preset.area;

  Scene scene = testing::flat_sheet(axis == 0 ? along : 3, axis == 0 ? 3 : along);
  scene.size1 = (scene.m - 1) * h;
  scene.size2 = (scene.n - 1) * h;
  scene.material = {density * scene.size1 * scene.size2, preset.zeta, preset.xi, preset.phi};
  scene.gravity = {0.0, -kGravity, 0.0};
  const double lowest_mode =
      1.875 * 1.875 * std::sqrt(kGravity * c * c * c) / (overhang * overhang);
  scene.damping = 2.0 * lowest_mode * density;
  const CflEstimate cfl = cfl_estimate(scene.material, density, h, h);
  scene.dt = std::min(0.8 * cfl.membrane_dt, 0.5 * cfl.bending_dt);
  Fix clamp;
  for (int row = 0; row < 2; ++row)
    for (int across = 0; across < 3; ++across)
      clamp.nodes.nodes.push_back(axis == 0 ? NodeIndex{row, across} : NodeIndex{across, row});
  scene.fixes.push_back(clamp);
  scene.steps = static_cast<long>(std::ceil(15.0 / lowest_mode / scene.dt));

  Simulation sim(scene, MPI_COMM_SELF);
  double peak = 0.0;
  while (sim.step_index() < scene.steps) {
    if (sim.step()) {
      ADD_FAILURE() << name << " along x" << axis + 1 << ": unstable at step "
                    << sim.step_index();
      break;
    }
    if (sim.step_index() % 100 == 0) peak = std::max(peak, sim.diagnostics().kinetic_energy);
  }
  EXPECT_LT(sim.diagnostics().kinetic_energy, 1e-9 * peak)
      << name << " along x" << axis + 1 << ": not at rest";

  const auto node = [&](int i) {
    return axis == 0 ? sim.positions()(i, 1) : sim.positions()(1, i);
  };
  const Vec3 edge = 0.5 * (node(0) + node(1));
  const Vec3 end = node(along - 1);
  const double out = axis == 0 ? end.x - edge.x : end.z - edge.z;
  const double angle = std::atan2(edge.y - end.y, out);
  return {elastica_bending_length(angle, overhang), peirce_bending_length(angle, overhang), angle};
}

constexpr const char* kMeasuredFabrics[] = {
    "11oz-black-denim",  "royal-target",      "gray-interlock",    "ivory-rib-knit",
    "white-dots-on-blk", "pink-ribbon-brown", "tango-red-jet-set", "navy-sparkle-sweat",
    "camel-ponte-roma",  "white-swim-solid"};

// Every measured fabric along both axes, on a grid of `cells` cells over the overhang, within
// `tolerance` of its preset's bending length.
void check_every_fabric(int cells, double tolerance) {
  for (const char* name : kMeasuredFabrics)
    for (int axis = 0; axis < 2; ++axis) {
      const double c = preset_bending_length(*find_preset(name), axis);
      const Cantilever strip = hang(name, axis, cells);
      std::printf("[cantilever] %-18s along x%d, %d cells: c %.3f cm, from the chord %.3f cm "
                  "(%+.2f %%), by Peirce's formula %.3f cm (%+.2f %%), chord %.2f deg\n",
                  name, axis + 1, cells, 100 * c, 100 * strip.bending_length,
                  100 * (strip.bending_length / c - 1), 100 * strip.peirce_length,
                  100 * (strip.peirce_length / c - 1), strip.chord_angle * 180 / std::numbers::pi);
      EXPECT_NEAR(strip.bending_length / c, 1.0, tolerance) << name << " along x" << axis + 1;
    }
}

// 8 cells over l = 2c, 4.5 nodes per bending length: −0.06 to +0.05 % off c, against −0.17 to
// −0.00 % at 16 cells and −0.23 to −0.01 % at 32, where all but navy-sparkle-sweat are within
// 0.05 % (that one stretches by 1.3 % along x²; docs/materials.md, "The cantilever check";
// measured 2026-12-02 with the trapezoidal quadrature). The tolerance, 0.5 %, is more than twice
// the largest of these: 1.5 % of B or of μ₀, 0.35° of the chord.
TEST(BendingLength, MeasuredFabricsDroopAsTheirPresetsSay) {
  // The elastica overhanging by twice its bending length: the standards' 41.5°.
  EXPECT_NEAR(Elastica{8.0}.chord_angle() * 180 / std::numbers::pi, 41.49, 0.005);
  check_every_fabric(8, 5e-3);
}

// The same at 16 and 32 cells, the convergence check behind the tolerance above (43 s; by hand,
// with --gtest_also_run_disabled_tests).
TEST(BendingLength, DISABLED_ConvergesWithTheGrid) {
  for (int cells : {16, 32}) check_every_fabric(cells, 5e-3);
}

}  // namespace
}  // namespace cosserat
