#pragma once
// Helpers of the tests under mpiexec: the ranks of MPI_COMM_WORLD, the splits of a grid over
// them, a scene whose loads and fixes straddle block borders, and node-by-node comparison of a
// distributed field with the same field of a one-block run.

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cosserat/grid/decomposition.hpp"
#include "cosserat/model/wave_speed.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/simulation.hpp"
#include "support/sheets.hpp"

namespace cosserat::testing {

inline int world_rank() { return rank_in(MPI_COMM_WORLD); }
inline int world_size() { return size_of(MPI_COMM_WORLD); }

// The explicit schemes, whose trajectories are the same bitwise for any split. The
// semi-implicit ones agree to their linear solver's tolerance (test_semi_implicit.cpp).
inline std::vector<Integrator> explicit_integrators() {
  std::vector<Integrator> all;
  for (const std::string& name : integrator_names()) {
    const Integrator integrator = *integrator_from_name(name);
    if (!is_semi_implicit(integrator)) all.push_back(integrator);
  }
  return all;
}

// Every parts_k x parts_l = ranks split that fits the grid, the automatic choice first.
inline std::vector<Decomposition> all_splits(int m, int n, int ranks) {
  std::vector<Decomposition> splits{Decomposition::choose(m, n, ranks)};
  for (int parts_k = 1; parts_k <= ranks; ++parts_k) {
    if (ranks % parts_k != 0) continue;
    const int parts_l = ranks / parts_k;
    if (parts_k == splits.front().parts_k()) continue;
    try {
      splits.push_back(Decomposition::with_parts(m, n, parts_k, parts_l));
    } catch (const DecompositionError&) {
      // This split does not fit the grid; the others still test it.
    }
  }
  return splits;
}

// 37 x 23, odd in both directions, so every split is uneven. Two corners held from the start;
// a band fixed in y only from step 30; two nodes moved in x and z by a fix from step 20 to 55
// and then held in x where they got to (a restart at half the 80 steps lands while they move);
// a load on a disk for steps 0-50; fluid and damping, so that the total area enters every step.
// The band, the disk and the fixed corners straddle the block borders of every split of 2 to 6
// ranks.
inline Scene odd_grid_scene(Integrator integrator) {
  Scene scene = parse_scene(R"(
title = "odd grid"
[grid]
nodes = [37, 23]
size = [9.0, 5.5]
origin = [0.0, 0.0, 0.0]
u = [1.0, 0.0, 0.0]
v = [0.0, 0.0, 1.0]
[material]
mass = 10.0
zeta = 100.0
xi = 0.3
phi = 0.05
[environment]
gravity = [0.0, -9.8, 0.0]
damping = 0.2
fluid = { viscosity = 0.5, velocity = [1.0, 0.0, 0.5] }
[time]
integrator = "verlet"
dt = 0.001
steps = 80
output_every = 20
[[fix]]
nodes = [[0, 0], [36, 0]]
[[fix]]
region = { rect = [10, 8, 26, 13] }
axes = "y"
start = 30
[[fix]]
nodes = [[18, 22], [5, 3]]
axes = "xz"
velocity = [0.5, 0.0, -0.3]
start = 20
end = 55
[[fix]]
nodes = [[18, 22], [5, 3]]
axes = "x"
start = 55
[[fix]]
nodes = [[30, 18], [31, 18]]
angular_velocity = [0.0, 3.0, 0.0]
center = [7.25, 0.0, 4.5]
start = 25
end = 70
[[load]]
region = { disk = { center = [18, 11], radius = 6 } }
force = [0.0, 2.0, 0.3]
start = 0
end = 50
)",
                            "odd_grid.toml");
  scene.integrator = integrator;
  return scene;
}

// The odd grid of particles and springs (docs/model.md, "The mass-spring model"), 11.8 g each,
// every family damped: the load tears the springs around its disk (rupture at 1.04 rest
// lengths, across the block borders of every split) and the lower length limit (0.98 rest
// lengths) holds the compressed ones, so both act in the 80 steps.
inline Scene mass_spring_odd_grid_scene(Integrator integrator) {
  Scene scene = odd_grid_scene(integrator);
  scene.model_kind = ModelKind::mass_spring;
  scene.springs.structural = {200.0, 0.5};
  scene.springs.shear = {50.0, 0.2};
  scene.springs.bend = {20.0, 0.1};
  scene.springs.dead_zone = 0.001;
  scene.springs.min_length = 0.98;
  scene.springs.max_length = 1.1;
  scene.springs.rupture_length = 1.04;
  return scene;
}

// The odd grid in gusts that change over 20 ms and 1.5 m (docs/model.md "Wind and gusts"), so
// that a node's wind depends on where it is and on the time each stage reads it at.
inline Scene gusty_odd_grid_scene(Integrator integrator) {
  Scene scene = odd_grid_scene(integrator);
  scene.fluid->gusts = Gusts{2.0, 0.02, 1.5, 17};
  return scene;
}

// The odd grid for the semi-implicit baseline: at twice the explicit limit, so that the Jacobian
// carries the step, for 40 steps, with solves tight enough (rtol 1e-12) that the splits agree to
// far below 1e-9 m.
inline Scene semi_implicit_odd_grid_scene(Integrator integrator = Integrator::semi_implicit) {
  Scene scene = odd_grid_scene(integrator);
  scene.dt = 2.0 * cfl_estimate(scene.material, scene.areal_density(), scene.h1(), scene.h2()).dt;
  scene.steps = 40;
  scene.solver.rtol = 1e-12;
  return scene;
}

// Adaptive steps that roll back: the bending sheet (support/sheets.hpp) at safety 1, so that the
// monitor trips and the run goes back (tests/unit/test_adaptive_steps.cpp); a load on a disk
// straddling the block borders for its first 0.05 s, two corners held, and the middle of the
// far edge lifted by a moving fix from 0.02 s to 0.15 s.
inline Scene rolling_back_scene(Integrator integrator) {
  Scene scene = parse_scene(bending_sheet_text() + R"(
[time]
duration = 0.2
output_dt = 0.1
dt = { adaptive = true, safety = 1.0 }
[[fix]]
nodes = [[0, 0], [23, 0]]
[[fix]]
nodes = [[12, 23]]
axes = "y"
velocity = [0.0, 0.2, 0.0]
start_time = 0.02
end_time = 0.15
[[load]]
region = { disk = { center = [12, 11], radius = 5 } }
force = [0.0, 0.05, 0.01]
end_time = 0.05
)",
                            "rolling_back.toml");
  scene.integrator = integrator;
  return scene;
}

// The rolling-back scene for 0.1 s in random steps (docs/stability.md, "Random steps") of a
// tenth to four tenths of its rest sheet's CFL step, seed 11: stable, so nothing rolls back,
// and every step a length of its own (about 800 of them).
inline Scene random_steps_scene(Integrator integrator) {
  Scene scene = rolling_back_scene(integrator);
  scene.duration = 0.1;
  const double cfl = rest_step_estimate(scene.model_spec()).dt;
  AdaptiveStep& steps = *scene.adaptive;
  steps.random = true;
  steps.seed = 11;
  steps.min = 0.1 * cfl;
  steps.max = 0.4 * cfl;
  scene.dt = steps.max;
  scene.steps = static_cast<long>(std::ceil(scene.duration / steps.min));
  return scene;
}

// The rolling-back scene in a gusting wind of 2 m/s across the sheet.
inline Scene gusty_rolling_back_scene(Integrator integrator) {
  Scene scene = rolling_back_scene(integrator);
  scene.fluid = Fluid{0.05, {0.0, 2.0, 0.0}, Gusts{1.0, 0.05, 0.5, 4}};
  return scene;
}

// Contact with a free body (docs/contact.md, "Parallel runs, restarts and output"): a 13 x 11 sheet
// held at two corners, a free box thrown down onto it off-centre and spinning, a fixed sphere under
// the sheet whose cells it presses into, and a floor; 160 steps of 1 ms, long enough for both
// solids to touch the sheet across the block borders of every split.
// A soft, light sheet of m x n nodes and size1 x size2 m in the plane y = origin.y, under
// gravity along −y: what the contact scenes below drop onto their solids.
inline Scene soft_sheet(int m, int n, double size1, double size2, const Vec3& origin) {
  Scene scene = flat_sheet(m, n);
  scene.size1 = size1;
  scene.size2 = size2;
  scene.origin = origin;
  scene.material.mass = 0.25;
  scene.material.zeta = {20.0, 0.0, 20.0};
  scene.material.xi = {1e-3, 0.0, 1e-3};
  scene.material.phi = {0.0, 0.0, 0.0};
  scene.gravity = {0.0, -9.81, 0.0};
  return scene;
}

inline Scene free_body_scene(Integrator integrator) {
  Scene scene = soft_sheet(13, 11, 1.2, 1.0, {-0.6, 0.0, -0.5});
  scene.integrator = integrator;
  scene.steps = 160;
  scene.fixes.push_back(fix_nodes({{0, 0}, {12, 10}}));
  SolidSpec box;
  box.name = "box";
  box.shape.kind = ShapeKind::box;
  box.shape.half_extents = {0.12, 0.08, 0.1};
  box.pose = {{0.07, 0.2, -0.03}, from_axis_angle({1.0, 2.0, 0.5}, 0.4)};
  box.motion = SolidMotion::free;
  box.body.mass = 0.3;
  box.body.initial_velocity = {0.1, -1.5, 0.05};
  box.body.initial_angular_velocity = {0.5, -1.0, 2.0};
  box.body.drag = 0.05;
  box.friction = 0.4;
  box.restitution = 0.3;
  box.thickness = 2e-3;
  scene.solids.push_back(box);
  SolidSpec ball;
  ball.name = "ball";
  ball.shape.kind = ShapeKind::sphere;
  ball.shape.radius = 0.04;
  ball.pose.position = {-0.25, -0.06, 0.2};
  ball.thickness = 2e-3;
  scene.solids.push_back(ball);
  return scene;
}

// A sheet falling onto six solids of every bounded kind and a floor, two of them moving, each
// reaching only part of the sheet: the contact broad phase (docs/contact.md, "Cost") clears
// tiles of nodes by their bounds, and its tiles follow the blocks, so a tile cleared wrongly
// would show as a difference between splits.
inline Scene many_solids_scene() {
  Scene scene = soft_sheet(29, 23, 1.4, 1.1, {-0.7, 0.1, -0.55});
  scene.integrator = Integrator::verlet;
  scene.dt = 5e-4;
  scene.steps = 400;
  const auto solid = [&](ShapeKind kind, const Vec3& centre) {
    SolidSpec s;
    s.name = "solid " + std::to_string(scene.solids.size());
    s.shape.kind = kind;
    s.pose.position = centre;
    s.friction = 0.3;
    s.thickness = 3e-3;
    return s;
  };
  SolidSpec floor = solid(ShapeKind::plane, {0.0, -0.05, 0.0});
  floor.pose.orientation = rotation_between({0.0, 0.0, 1.0}, {0.0, 1.0, 0.0});
  scene.solids.push_back(floor);
  SolidSpec ball = solid(ShapeKind::sphere, {-0.45, 0.0, -0.3});
  ball.shape.radius = 0.08;
  ball.motion = SolidMotion::kinematic;
  ball.path.velocity = {1.2, 0.2, 0.4};
  scene.solids.push_back(ball);
  SolidSpec box = solid(ShapeKind::box, {0.3, 0.0, 0.25});
  box.shape.half_extents = {0.1, 0.04, 0.06};
  box.pose.orientation = from_axis_angle({0.3, 1.0, 0.2}, 0.7);
  box.motion = SolidMotion::kinematic;
  box.path.angular_velocity = {0.0, 4.0, 1.0};
  scene.solids.push_back(box);
  SolidSpec cylinder = solid(ShapeKind::cylinder, {-0.2, -0.02, 0.3});
  cylinder.shape.radius = 0.07;
  cylinder.shape.half_length = 0.05;
  cylinder.pose.orientation = rotation_between({0.0, 0.0, 1.0}, {0.0, 1.0, 0.0});
  scene.solids.push_back(cylinder);
  SolidSpec capsule = solid(ShapeKind::capsule, {0.1, -0.01, -0.2});
  capsule.shape.radius = 0.015;
  capsule.shape.half_length = 0.35;
  capsule.pose.orientation = rotation_between({0.0, 0.0, 1.0}, {1.0, 0.0, 0.3});
  scene.solids.push_back(capsule);
  SolidSpec far = solid(ShapeKind::box, {0.0, 2.0, 0.0});
  far.shape.half_extents = {0.2, 0.2, 0.2};
  scene.solids.push_back(far);
  return scene;
}

// Number of owned nodes, over all ranks, where `field` differs in any bit from `reference`,
// a field of the whole grid.
inline long differing_nodes(const Field<Vec3>& field, const Field<Vec3>& reference) {
  const Block& b = field.block();
  const Block& whole = reference.block();
  if (whole.owned_k() != whole.m || whole.owned_l() != whole.n) return -1;
  long local = 0;
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const Vec3 p = field(k, l), q = reference(k, l);
      if (!(p.x == q.x && p.y == q.y && p.z == q.z)) ++local;
    }
  long total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return total;
}

// Largest distance, over all ranks' owned nodes, between `field` and `reference`, a field of
// the whole grid.
inline double largest_difference(const Field<Vec3>& field, const Field<Vec3>& reference) {
  const Block& b = field.block();
  double local = 0.0;
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) local = std::max(local, norm(field(k, l) - reference(k, l)));
  double largest = 0.0;
  MPI_Allreduce(&local, &largest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return largest;
}

inline std::string split_name(const Decomposition& d) {
  return std::to_string(d.parts_k()) + " x " + std::to_string(d.parts_l());
}

}  // namespace cosserat::testing
