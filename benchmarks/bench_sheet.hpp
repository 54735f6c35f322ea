#pragma once
// What the step benchmarks share: the flat N x N sheet they step, and their main.

#include "cosserat/scene/scene.hpp"

namespace cosserat::bench {

// The reference sheet (10 m, 10 kg, the S1 material) flat in the xz plane with gravity and
// damping (the step then also reduces the total area), Verlet at a step below the
// bending-wave limit, which scales with h² (about 5e-6 s at 1024²), so the sheet stays stable
// for as many steps as a benchmark takes.
inline Scene flat_sheet(int nodes) {
  Scene s;
  s.name = "bench";
  s.m = s.n = nodes;
  s.size1 = s.size2 = 10.0;
  s.material.mass = 10.0;
  s.material.zeta = {100.0, 100.0, 100.0};
  s.material.xi = {0.3, 0.3, 0.3};
  s.material.phi = {0.001, 0.001, 0.001};
  s.gravity = {0.0, -9.8, 0.0};
  s.damping = 0.2;
  s.integrator = Integrator::verlet;
  const double h = s.size1 / (nodes - 1);
  s.dt = 0.02 * h * h;
  s.steps = 1;
  s.output_every = 1;
  return s;
}

}  // namespace cosserat::bench
