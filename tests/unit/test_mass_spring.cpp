// The mass-spring model (docs/model.md, "The mass-spring model"): its forces against a pair
// worked by hand, its force as the exact gradient of its energy, its dead zone, its internal
// forces cancelling pairwise, its damping blind to rigid motion, the implicit damping solve,
// energy conserved to the scheme's order without damping, length limits and rupture.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cosserat/model/force_model.hpp"
#include "cosserat/model/mass_spring.hpp"
#include "cosserat/time/dynamics.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

ModelSpec spring_spec(double h1, double h2, double particle_mass) {
  ModelSpec spec;
  spec.kind = ModelKind::mass_spring;
  spec.h1 = h1;
  spec.h2 = h2;
  spec.particle_mass = particle_mass;
  spec.springs.structural = {10.0, 2.0};
  spec.springs.shear = {4.0, 0.5};
  spec.springs.bend = {3.0, 0.25};
  return spec;
}

// A row of three particles 1 m apart (h1 = 1): node 1 lifted by 0.5 m, node 2 pulled out by
// 0.2 m, node 1 moving at 1 m/s along y. By hand, with ke = 10 and 3 N/m, kd = 2 N s/m for the
// structural spring, on node 0:
//   structural 0-1: ℓ = √1.25, F = 10 (√1.25 − 1) (1, 0.5, 0)/√1.25 = (1.05572809, 0.52786405, 0)
//   bend 0-2: ℓ = 2.2, F = 3 × 0.2 (1, 0, 0) = (0.6, 0, 0)
//   damping 0-1: 2 ((0, 1, 0)·d̂) d̂ = 2 (0.5/1.25) (1, 0.5, 0) = (0.8, 0.4, 0)
// and node 2 feels the structural spring 1-2 (ℓ = √1.69 = 1.3) and the bend spring pulling it
// back: 10 × 0.3 (−1.2, 0.5, 0)/1.3 + 3 × 0.2 (−1, 0, 0).
TEST(MassSpring, ForcesOfAPairByHand) {
  const ModelSpec spec = spring_spec(1.0, 1.0, 0.5);
  const Block block = Block::whole(3, 1, MPI_COMM_SELF);
  MassSpring model(spec, block);
  Field<Vec3> r(block), v(block), a(block);
  r(0, 0) = {0.0, 0.0, 0.0};
  r(1, 0) = {1.0, 0.5, 0.0};
  r(2, 0) = {2.2, 0.0, 0.0};
  v(1, 0) = {0.0, 1.0, 0.0};
  model.internal_acceleration(r, a);
  const double m = spec.particle_mass;
  EXPECT_NEAR(a(0, 0).x * m, 1.05572809 + 0.6, 1e-8);
  EXPECT_NEAR(a(0, 0).y * m, 0.52786405, 1e-8);
  EXPECT_EQ(a(0, 0).z, 0.0);
  EXPECT_NEAR(a(2, 0).x * m, 10.0 * 0.3 * -1.2 / 1.3 - 0.6, 1e-12);
  EXPECT_NEAR(a(2, 0).y * m, 10.0 * 0.3 * 0.5 / 1.3, 1e-12);
  // Newton's third law, to the bit: the ends of a spring compute ±d.
  EXPECT_EQ(a(0, 0).x + a(1, 0).x + a(2, 0).x, 0.0);

  model.velocity_acceleration(r, v, a);
  EXPECT_NEAR(a(0, 0).x * m, 0.8, 1e-14);
  EXPECT_NEAR(a(0, 0).y * m, 0.4, 1e-14);
  // Node 2: d = r1 − r2 = (−1.2, 0.5, 0), (v1 − v2)·d = 0.5.
  EXPECT_NEAR(a(2, 0).x * m, 2.0 * (0.5 / 1.69) * -1.2, 1e-14);
  EXPECT_NEAR(a(2, 0).y * m, 2.0 * (0.5 / 1.69) * 0.5, 1e-14);
}

// A smoothly deformed 6 x 5 sheet on a non-square grid.
Field<Vec3> deformed(const Block& block, double h1, double h2) {
  Field<Vec3> r(block);
  for (int l = 0; l < block.n; ++l)
    for (int k = 0; k < block.m; ++k) {
      const double x = k * h1, z = l * h2;
      r(k, l) = {x * (1.0 + 0.08 * std::sin(1.3 * z)), 0.3 * std::sin(0.9 * x + 0.4 * z),
                 z * (1.0 - 0.05 * std::cos(0.7 * x))};
    }
  return r;
}

// The force is −∇E: every component against a central difference of the stored energy.
TEST(MassSpring, ForceIsTheEnergysGradient) {
  const double h1 = 0.5, h2 = 0.4, m = 0.2;
  const ModelSpec spec = spring_spec(h1, h2, m);
  const Block block = Block::whole(6, 5, MPI_COMM_SELF);
  MassSpring model(spec, block);
  Field<Vec3> r = deformed(block, h1, h2), a(block);
  model.internal_acceleration(r, a);
  const double step = 1e-6;
  double worst = 0.0, largest = 0.0;
  for (int l = 0; l < block.n; ++l)
    for (int k = 0; k < block.m; ++k)
      for (int c = 0; c < 3; ++c) {
        const double keep = r(k, l)[c];
        r(k, l)[c] = keep + step;
        const double up = model.block_energy(r);
        r(k, l)[c] = keep - step;
        const double down = model.block_energy(r);
        r(k, l)[c] = keep;
        const double force = -(up - down) / (2.0 * step);
        worst = std::max(worst, std::abs(force - m * a(k, l)[c]));
        largest = std::max(largest, std::abs(force));
      }
  EXPECT_GT(largest, 0.1);
  EXPECT_LT(worst, 1e-7 * largest);

  // The density sums to the energy over the cells h1 h2 every particle stands for.
  Field<double> density(block);
  model.energy_density(r, density);
  double total = 0.0;
  for (int l = 0; l < block.n; ++l)
    for (int k = 0; k < block.m; ++k) total += density(k, l) * h1 * h2;
  EXPECT_NEAR(total, model.block_energy(r), 1e-12 * total);
}

// Inside the dead zone a spring pulls with nothing; outside it with ke (ℓ − ℓ0), its full
// Hooke force, and the energy is continuous at the zone's edge.
TEST(MassSpring, DeadZone) {
  ModelSpec spec = spring_spec(1.0, 1.0, 1.0);
  spec.springs.bend = {};
  spec.springs.dead_zone = 0.01;
  const Block block = Block::whole(2, 1, MPI_COMM_SELF);
  MassSpring model(spec, block);
  Field<Vec3> r(block), a(block);
  for (const double stretch : {0.005, -0.009, 0.02, -0.03}) {
    r(1, 0) = {1.0 + stretch, 0.0, 0.0};
    model.internal_acceleration(r, a);
    const double expected = std::abs(stretch) < 0.01 ? 0.0 : 10.0 * stretch;
    EXPECT_NEAR(a(0, 0).x, expected, 1e-13) << stretch;
  }
  // Just outside, ½ ke ((ε(1 + δ))² − ε²) ≈ ke ε² δ = 1e-12 J for δ = 1e-9: no jump.
  r(1, 0) = {1.0 + 0.01 * (1.0 + 1e-9), 0.0, 0.0};
  EXPECT_NEAR(model.block_energy(r), 1e-12, 1e-14);
}

// Internal forces cancel pairwise, so they move no momentum; the damping sees relative
// velocities along the springs only, so a rigid motion (translation and rotation) feels none.
TEST(MassSpring, MomentumAndRigidMotion) {
  const double h1 = 0.5, h2 = 0.4;
  const ModelSpec spec = spring_spec(h1, h2, 0.2);
  const Block block = Block::whole(6, 5, MPI_COMM_SELF);
  MassSpring model(spec, block);
  const Field<Vec3> r = deformed(block, h1, h2);
  Field<Vec3> v(block), a(block);
  const Vec3 omega{0.3, -1.1, 0.7}, drift{2.0, -1.0, 0.5};
  for (int l = 0; l < block.n; ++l)
    for (int k = 0; k < block.m; ++k) v(k, l) = drift + cross(omega, r(k, l));
  model.velocity_acceleration(r, v, a);
  double worst = 0.0;
  for (int l = 0; l < block.n; ++l)
    for (int k = 0; k < block.m; ++k) worst = std::max(worst, norm(a(k, l)));
  EXPECT_LT(worst, 1e-13);

  model.internal_acceleration(r, a);
  Vec3 momentum{}, scale{};
  for (int l = 0; l < block.n; ++l)
    for (int k = 0; k < block.m; ++k) {
      momentum += a(k, l);
      scale += Vec3{std::abs(a(k, l).x), std::abs(a(k, l).y), std::abs(a(k, l).z)};
    }
  EXPECT_LT(norm(momentum), 1e-14 * norm(scale));
}

// Matched springs (docs/models.md, "Matched springs") store per unit area what the Cosserat sheet
// does, read at an inside node of each model's energy density: a small stretch along x with z
// held, a small shear, and a bend of radius c, the material's bending length. Bent to radius R,
// both store the shortened rows' 3 ζ ε², ε = (λ² − 1)/2 for the chord's λ = 2R sin(h/2R)/h, and
// the Cosserat sheet 3 ξ κ² with its discrete κ = 2(1 − cos(h/R)) R/h² (docs/equations.md §2.1),
// the springs (c/R)² of that: at 2c a quarter (their bending energy goes as κ⁴). The sheet: 21 x
// 21 nodes, 0.2 m square (h = 1 cm), μ = 0.1 kg/m², ζ = 2e4 N/m (stiff enough that the bend
// springs need no cap), ξ for c = 0.1 m, φ = 0 (the springs have no coupling). The springs'
// exact lengths differ from the small-strain forms by about e and (h/R)² relatively.
TEST(MassSpring, MatchedSpringsStoreTheCosseratEnergy) {
  Scene scene = testing::flat_sheet(21, 21);
  scene.size1 = scene.size2 = 0.2;
  const double h = 0.01, c = 0.1, density = 0.1;
  scene.material.mass = density * 0.2 * 0.2;
  scene.material.zeta = {2e4, 2e4, 2e4};
  const double xi = c * c * c * density * 9.80665 / 6.0;
  scene.material.xi = {xi, xi, xi};
  scene.material.phi = {0.0, 0.0, 0.0};
  const auto matched = matched_springs(scene.material, density, h);
  ASSERT_TRUE(matched.has_value());
  EXPECT_NEAR(matched->bending_length, c, 1e-15);
  EXPECT_EQ(matched->bending_share, 1.0);

  const Block block = Block::whole(scene.m, scene.n, MPI_COMM_SELF);
  const auto cosserat = make_force_model(scene.model_spec(), block, 0.04);
  Scene springs = scene;
  springs.model_kind = ModelKind::mass_spring;
  springs.springs = matched->springs;
  const auto spring_model = make_force_model(springs.model_spec(), block, 0.04);

  Field<Vec3> r(block);
  Field<double> density_c(block), density_s(block);
  // The two models' energy per unit area at node (10, 10).
  const auto inside = [&](auto&& position) {
    for (int l = 0; l < scene.n; ++l)
      for (int k = 0; k < scene.m; ++k) r(k, l) = position(k * h, l * h);
    cosserat->energy_density(r, density_c);
    spring_model->energy_density(r, density_s);
    return std::array<double, 2>{density_c(10, 10), density_s(10, 10)};
  };
  const double e = 1e-5;
  const auto stretch = inside([&](double x, double z) { return Vec3{(1.0 + e) * x, 0.0, z}; });
  EXPECT_NEAR(stretch[0], 3.0 * 2e4 * e * e, 2e-5 * stretch[0]);
  EXPECT_NEAR(stretch[1], stretch[0], 2e-5 * stretch[0]);
  const double gamma = 1e-5;
  const auto shear = inside([&](double x, double z) {
    return Vec3{x + 0.5 * gamma * z, 0.0, z + 0.5 * gamma * x};
  });
  EXPECT_NEAR(shear[0], 2e4 * gamma * gamma / 2.0, 1e-4 * shear[0]);
  EXPECT_NEAR(shear[1], shear[0], 1e-4 * shear[0]);
  for (const double radius : {c, 2.0 * c}) {
    SCOPED_TRACE(radius);
    const auto bent = inside([&](double x, double z) {
      return Vec3{radius * std::sin(x / radius), radius * (1.0 - std::cos(x / radius)), z};
    });
    const double chord = 2.0 * radius * std::sin(h / (2.0 * radius)) / h;
    const double shortened = 3.0 * 2e4 * std::pow(0.5 * (chord * chord - 1.0), 2);
    const double kappa = 2.0 * (1.0 - std::cos(h / radius)) * radius / (h * h);
    const double bending = 3.0 * xi * kappa * kappa;
    EXPECT_NEAR(bent[0], shortened + bending, 1e-6 * bent[0]);
    const double springs = shortened + (c / radius) * (c / radius) * bending;
    EXPECT_NEAR(bent[1], springs, 3e-3 * springs);
  }
}

// A mass-spring scene of `m` x `n` particles, 1 m apart, 0.1 kg each.
Scene spring_sheet(int m, int n) {
  Scene scene = testing::flat_sheet(m, n);
  scene.size1 = m - 1.0;
  scene.size2 = n - 1.0;
  scene.model_kind = ModelKind::mass_spring;
  scene.material.mass = 0.1 * m * n;
  scene.springs.structural = {50.0, 5.0};
  scene.springs.shear = {10.0, 2.0};
  scene.springs.bend = {5.0, 1.0};
  return scene;
}

// The implicit damping solve (Dynamics::solve_velocity_terms) meets its equation
// (1 + c) w − s K(w) = g to its tolerance on a deformed sheet whose damping is stiff
// (s × bound = 6.4), and keeps a held component's velocity.
TEST(MassSpring, DampingSolveMeetsItsEquation) {
  Scene scene = spring_sheet(7, 6);
  const Block block = Block::whole(scene.m, scene.n, MPI_COMM_SELF);
  Dynamics dynamics(scene, block, testing::rest_positions(scene, block));
  ASSERT_TRUE(dynamics.has_velocity_force());
  const Field<Vec3> r = deformed(block, 1.0, 1.0);
  Field<Vec3> g(block), w(block), k_of_w(block);
  for (int l = 0; l < block.n; ++l)
    for (int k = 0; k < block.m; ++k) g(k, l) = {std::sin(k + 2.0 * l), std::cos(3.0 * k - l), 0.5};
  const double c = 0.1, s = 0.01;
  const std::vector<Constraints::NodeState> held = {{2, 3, 0b101, {}, {}, {}}};
  w(2, 3) = {7.0, 0.0, -7.0};
  dynamics.solve_velocity_terms(r, nullptr, c, 0.0, s, g, held, w);
  EXPECT_EQ(w(2, 3).x, 7.0);
  EXPECT_EQ(w(2, 3).z, -7.0);
  dynamics.velocity_acceleration(r, w, k_of_w);
  double worst = 0.0, largest = 0.0;
  for (int l = 0; l < block.n; ++l)
    for (int k = 0; k < block.m; ++k) {
      Vec3 residual = (1.0 + c) * w(k, l) - s * k_of_w(k, l) - g(k, l);
      if (k == 2 && l == 3) residual.x = residual.z = 0.0;
      worst = std::max(worst, norm(residual));
      largest = std::max(largest, norm(s * k_of_w(k, l)));
    }
  EXPECT_GT(largest, 0.1);
  EXPECT_LT(worst, 1e-8);
}

// Without damping, velocity Verlet keeps the total energy of a released sheet to O(Δt²): the
// drift from the energy at release falls fourfold when the step halves. A 0.5 N pull on a
// corner for the first 0.2 s stretches the sheet; then it vibrates freely.
double energy_wander(double dt) {
  Scene scene = spring_sheet(5, 4);
  scene.springs.structural.kd = scene.springs.shear.kd = scene.springs.bend.kd = 0.0;
  scene.integrator = Integrator::velocity_verlet;
  scene.dt = dt;
  Load pull;
  pull.nodes.nodes = {{4, 3}};
  pull.force = {0.5, 0.3, 0.2};
  pull.window.end_time = 0.2 - 0.5 * dt;
  scene.loads.push_back(pull);
  Simulation sim(scene, MPI_COMM_SELF);
  auto total = [&] { return sim.elastic_energy() + sim.diagnostics().kinetic_energy; };
  EXPECT_TRUE(testing::advance(sim, std::lround(0.2 / dt)));
  const double released = total();
  EXPECT_GT(released, 1e-3);
  double wander = 0.0;
  while (sim.time() < 2.0) {
    EXPECT_TRUE(testing::advance(sim, 1));
    wander = std::max(wander, std::abs(total() - released));
  }
  return wander / released;
}

TEST(MassSpring, EnergyConservedToSecondOrder) {
  const double coarse = energy_wander(4e-3), fine = energy_wander(2e-3);
  EXPECT_LT(coarse, 0.05);
  EXPECT_GT(coarse / fine, 3.5);
  EXPECT_LT(coarse / fine, 4.5);
}


// Why the return-to-equilibrium sheets stop short (docs/models.md, "Return to equilibrium"):
// a flat sheet of springs at their rest lengths has no stiffness across itself to first order.
// Its centre lifted by w stretches its springs by about w²/2ℓ0, so the force that pulls it back
// goes as w³: eight times as much at 2w. In its plane the same sheet is linear (twice the force
// at 2w), and pushed in its plane and let go it returns to within 1e-6 m, where pushed across it
// by the same force for the same time it is still centimetres away after as long. A 7 x 7
// sheet, border held, 1 m springs and 0.1 kg particles; the push 0.5 N for 0.5 s, then 2.5 s.
double centre_force(Vec3 lift) {
  const Scene scene = spring_sheet(7, 7);
  const Block block = Block::whole(scene.m, scene.n, MPI_COMM_SELF);
  const auto model = make_force_model(scene.model_spec(), block, 36.0);
  Field<Vec3> r(block), a(block);
  for (int l = 0; l < scene.n; ++l)
    for (int k = 0; k < scene.m; ++k) r(k, l) = {1.0 * k, 0.0, 1.0 * l};
  r(3, 3) += lift;
  model->internal_acceleration(r, a);
  return norm(a(3, 3));
}

double distance_after_push(Vec3 force) {
  Scene scene = spring_sheet(7, 7);
  scene.damping = 1.0;
  scene.dt = 0.01;  // about a quarter of the step estimate (docs/model.md, "Its step")
  Fix border;
  std::vector<NodeIndex>& held = border.nodes.nodes;
  for (int i = 0; i < 7; ++i) held.insert(held.end(), {{i, 0}, {i, 6}});
  for (int i = 1; i < 6; ++i) held.insert(held.end(), {{0, i}, {6, i}});
  scene.fixes.push_back(border);
  Load push;
  push.nodes.nodes = {{3, 3}};
  push.force = force;
  push.window.end_time = 0.5 - 0.5 * scene.dt;
  scene.loads.push_back(push);
  Simulation sim(scene, MPI_COMM_SELF);
  EXPECT_TRUE(testing::advance(sim, 300));
  return norm(sim.positions()(3, 3) - Vec3{3.0, 0.0, 3.0});
}

TEST(MassSpring, AFlatSheetHasNoStiffnessAcrossItself) {
  const double w = 1e-3;
  EXPECT_NEAR(centre_force({0.0, 2.0 * w, 0.0}) / centre_force({0.0, w, 0.0}), 8.0, 0.01);
  EXPECT_NEAR(centre_force({2.0 * w, 0.0, 0.0}) / centre_force({w, 0.0, 0.0}), 2.0, 0.01);
  const double in_plane = distance_after_push({0.5, 0.0, 0.0});
  const double across = distance_after_push({0.0, 0.5, 0.0});
  std::printf("[equilibrium] 3 s after the push: %.3g m pushed in the plane, %.3g m across\n",
              in_plane, across);
  EXPECT_LT(in_plane, 1e-6);
  EXPECT_GT(across, 1e-3);
}

// The longest and shortest unbroken spring of the run's current state, in rest lengths, and
// how many springs broke.
struct SpringLengths {
  double longest = 0.0, shortest = 1e300;
  int broken = 0;
};

SpringLengths spring_lengths(Simulation& sim, const Scene& scene) {
  const Block& b = sim.block();
  Field<double> bits(b);
  sim.node_field(OutputField::broken_springs, bits);
  const int offsets[6][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}, {2, 0}, {0, 2}};
  const double h1 = scene.h1(), h2 = scene.h2(), diagonal = std::hypot(h1, h2);
  const double rests[6] = {h1, h2, diagonal, diagonal, 2.0 * h1, 2.0 * h2};
  SpringLengths lengths;
  for (int l = 0; l < b.n; ++l)
    for (int k = 0; k < b.m; ++k)
      for (int s = 0; s < 6; ++s) {
        const int k2 = k + offsets[s][0], l2 = l + offsets[s][1];
        if (k2 >= b.m || l2 < 0 || l2 >= b.n) continue;
        if ((static_cast<int>(bits(k, l)) >> s) & 1) {
          ++lengths.broken;
          continue;
        }
        const double ratio = norm(sim.positions()(k2, l2) - sim.positions()(k, l)) / rests[s];
        lengths.longest = std::max(lengths.longest, ratio);
        lengths.shortest = std::min(lengths.shortest, ratio);
      }
  return lengths;
}


// A 2 m net held along two edges, a disk in its middle pulled down hard: without limits its
// springs stretch to 1.6 rest lengths; with max_length 1.2 no spring ends a step longer than
// that, a corrected node keeping the velocity its move implies; with rupture at 1.15 the disk
// tears out and the springs that broke stay broken.
Scene pulled_net() {
  Scene scene = spring_sheet(21, 21);
  scene.size1 = scene.size2 = 2.0;
  scene.material.mass = 0.015 * 21 * 21;
  scene.springs.structural = {100.0, 0.5};
  scene.springs.shear = {20.0, 0.1};
  scene.springs.bend = {5.0, 0.05};
  scene.gravity = {0.0, -9.8, 0.0};
  Fix edges;
  for (int k = 0; k < 21; ++k) edges.nodes.nodes.push_back({k, 0});
  for (int k = 0; k < 21; ++k) edges.nodes.nodes.push_back({k, 20});
  scene.fixes.push_back(edges);
  Load pull;
  for (int l = 8; l <= 12; ++l)
    for (int k = 8; k <= 12; ++k) pull.nodes.nodes.push_back({k, l});
  pull.force = {0.0, 0.0, -3.0};
  scene.loads.push_back(pull);
  scene.dt = 1e-3;
  return scene;
}

TEST(MassSpring, LengthLimitsAndRupture) {
  for (const Integrator integrator : {Integrator::verlet, Integrator::velocity_verlet}) {
    const std::string scheme = integrator_name(integrator);
    Scene scene = pulled_net();
    scene.integrator = integrator;
    auto run = [&](long steps) {
      Simulation sim(scene, MPI_COMM_SELF);
      EXPECT_TRUE(testing::advance(sim, steps)) << scheme;
      return spring_lengths(sim, scene);
    };
    const SpringLengths free = run(140);
    EXPECT_GT(free.longest, 1.5) << scheme;
    EXPECT_LT(free.shortest, 0.5) << scheme;
    EXPECT_EQ(free.broken, 0) << scheme;

    // Eight passes of mean corrections leave at most 0.5 % of a limit (measured: 0.3 %).
    scene.springs.max_length = 1.2;
    scene.springs.min_length = 0.6;
    const SpringLengths held = run(140);
    EXPECT_LT(held.longest, 1.2 * 1.005) << scheme;
    EXPECT_GT(held.shortest, 0.6 * 0.995) << scheme;
    EXPECT_EQ(held.broken, 0) << scheme;

    scene.springs.rupture_length = 1.15;
    const SpringLengths tearing = run(100), torn = run(140);
    EXPECT_GT(tearing.broken, 50) << scheme;
    EXPECT_GE(torn.broken, tearing.broken) << scheme;
    EXPECT_LT(torn.longest, 1.15) << scheme;
  }
}

}  // namespace
}  // namespace cosserat
