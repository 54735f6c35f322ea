// docs/equations.md §5 item 8 under mpiexec: P ranks, every split of the grid over them, give the
// forces and the trajectory of one block. Each rank also runs the one-block reference itself
// (on MPI_COMM_SELF; the grids are small) and compares its own nodes with it. The total area is
// summed in integers (QuantizedSum), so the match asserted is bitwise, stronger than that
// item's "to round-off".

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "cosserat/baseline/semi_implicit.hpp"
#include "cosserat/grid/halo.hpp"
#include "cosserat/model/cosserat_energy.hpp"
#include "cosserat/model/cosserat_model.hpp"
#include "cosserat/model/surface_measures.hpp"
#include "cosserat/time/step_loop.hpp"
#include "mpi_support.hpp"
#include "support/layers.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

using testing::explicit_integrators;
using testing::all_splits;
using testing::differing_nodes;
using testing::split_name;
using testing::world_rank;
using testing::world_size;

Scene s2_cape(long steps) {
  return load_scene(COSSERAT_SOURCE_DIR "/scenes/s2_cape.toml",
                    {"time.steps=" + std::to_string(steps)});
}

// The internal force of one evaluation on a block whose owned nodes alone are set: the ghosts
// come from the halo exchange or not at all. Also the total area, through the same ghosts.
struct Evaluation {
  std::unique_ptr<Block> block;  // the fields point to it
  Field<Vec3> force;
  double area;
};

Evaluation evaluate(const Scene& scene, const Decomposition& d, MPI_Comm comm) {
  const int rank = rank_in(comm);
  auto owned = std::make_unique<Block>(d.block(rank, comm));
  const Block& block = *owned;
  Halo halo(d, block, rank);
  Field<Vec3> r(block), f(block);
  for (int l = block.l0; l < block.l1; ++l)
    for (int k = block.k0; k < block.k1; ++k) r(k, l) = testing::deformed(scene, k, l);
  halo.exchange(r);
  const RestState rest = flat_rest_state(scene.material, scene.u, scene.v);
  if (scene.discretisation == Discretisation::energy) {
    CosseratEnergy energy(block, scene.h1(), scene.h2(), rest);
    energy.internal_force(r, f);
  } else {
    CosseratModel model(block, scene.h1(), scene.h2(), rest, scene.borders);
    model.internal_force(r, f);
  }
  const double area = block_area(r, std::ldexp(scene.h1() * scene.h2(), -40)).global_total(comm);
  return {std::move(owned), std::move(f), area};
}

TEST(DecompositionInvariance, ForcesOfOneEvaluationMatchOneBlockNodeByNode) {
  Scene odd = testing::odd_grid_scene(Integrator::verlet);
  odd.discretisation = Discretisation::flux;
  Scene published = odd;
  published.discretisation = Discretisation::flux;
  published.borders = Borders::published;
  Scene energy = odd;
  energy.discretisation = Discretisation::energy;
  energy.title = "odd grid, energy form";
  for (const Scene& scene : {s2_cape(1), odd, published, energy}) {
    const Evaluation reference =
        evaluate(scene, Decomposition::with_parts(scene.m, scene.n, 1, 1), MPI_COMM_SELF);
    for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
      const Evaluation split = evaluate(scene, d, MPI_COMM_WORLD);
      EXPECT_EQ(differing_nodes(split.force, reference.force), 0)
          << scene.title << ", split " << split_name(d);
      EXPECT_EQ(split.area, reference.area) << scene.title << ", split " << split_name(d);
    }
  }
}

// The check above can fail: without the exchange the forces next to a block border differ.
TEST(DecompositionInvariance, WithoutTheHaloTheBorderForcesDiffer) {
  if (world_size() == 1) GTEST_SKIP() << "one rank has no block borders";
  const Scene scene = testing::odd_grid_scene(Integrator::verlet);
  const Decomposition whole = Decomposition::with_parts(scene.m, scene.n, 1, 1);
  const Evaluation reference = evaluate(scene, whole, MPI_COMM_SELF);
  const Decomposition d = Decomposition::choose(scene.m, scene.n, world_size());
  const Block block = d.block(world_rank(), MPI_COMM_WORLD);
  Field<Vec3> r(block), f(block);
  // Ghosts not exchanged hold stale values: here the flat sheet, wrong but not degenerate (left
  // at zero they would coincide, and the unit normal of a corner triangle of zero area is 0/0,
  // which the debug build's FPE traps stop at).
  const int g = block.ghost;
  for (int l = std::max(block.l0 - g, 0); l < std::min(block.l1 + g, block.n); ++l)
    for (int k = std::max(block.k0 - g, 0); k < std::min(block.k1 + g, block.m); ++k)
      r(k, l) = Vec3{k * scene.h1(), 0.0, l * scene.h2()};
  for (int l = block.l0; l < block.l1; ++l)
    for (int k = block.k0; k < block.k1; ++k) r(k, l) = testing::deformed(scene, k, l);
  CosseratModel model(block, scene.h1(), scene.h2(),
                      flat_rest_state(scene.material, scene.u, scene.v), scene.borders);
  model.internal_force(r, f);
  EXPECT_GT(differing_nodes(f, reference.force), 0);
}

// Runs `scene` for its steps on every split of the world's ranks: positions and velocities
// equal the one-block run's, bitwise.
void expect_every_split_follows_one_block(const Scene& scene) {
  const std::string scheme = integrator_name(scene.integrator);
  Simulation reference(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(reference, scene.steps)) << scheme;
  for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
    Simulation sim(scene, MPI_COMM_WORLD, d, any_scheme);
    const bool stable = testing::advance(sim, scene.steps);
    ASSERT_TRUE(stable) << scheme << ", split " << split_name(d);
    EXPECT_EQ(differing_nodes(sim.positions(), reference.positions()), 0)
        << scheme << ", split " << split_name(d);
    EXPECT_EQ(differing_nodes(sim.velocities(), reference.velocities()), 0)
        << scheme << ", split " << split_name(d);
  }
}

// The whole trajectory, every integrator, every split: positions and velocities after 80 steps
// (through a load window ending and a fix switching on) equal the one-block run's.
TEST(DecompositionInvariance, EveryIntegratorFollowsTheOneBlockTrajectory) {
  for (const Integrator integrator : explicit_integrators())
    expect_every_split_follows_one_block(testing::odd_grid_scene(integrator));
}

// Gusts are a function of position, time and seed alone (docs/model.md "Wind and gusts"): in
// them too every integrator, each reading the wind at its stages' times, follows the one-block
// trajectory bitwise.
TEST(DecompositionInvariance, EveryIntegratorInGustsFollowsTheOneBlockTrajectory) {
  for (const Integrator integrator : explicit_integrators())
    expect_every_split_follows_one_block(testing::gusty_odd_grid_scene(integrator));
}

// The tests above run the default, the energy form, which gathers each node's force from its
// neighbours' gradients in a fixed order; the flux form too gives the same trajectory bitwise
// on every split, for a scheme of each state kind.
TEST(DecompositionInvariance, FluxFormFollowsTheOneBlockTrajectory) {
  for (const Integrator integrator : {Integrator::verlet, Integrator::velocity_verlet}) {
    Scene scene = testing::odd_grid_scene(integrator);
    scene.discretisation = Discretisation::flux;
    expect_every_split_follows_one_block(scene);
  }
}

// The mass-spring model on every split, for a scheme of each path the springs' damping takes
// (the centred solve of verlet and of leapfrog, the explicit stages of velocity-verlet and
// rk4, the lagged velocity of verlet-lagged): its forces read the neighbours' velocities
// through the halo, its damping solve iterates without global sums, and its springs break
// where the block owning their first node says, for every block alike.
TEST(DecompositionInvariance, MassSpringFollowsTheOneBlockTrajectory) {
  {
    // The scene tears, and its lower length limit acts: without it the run goes elsewhere.
    const Scene scene = testing::mass_spring_odd_grid_scene(Integrator::verlet);
    Simulation reference(scene, MPI_COMM_SELF);
    ASSERT_TRUE(testing::advance(reference, scene.steps));
    Field<double> bits(reference.block());
    reference.node_field(OutputField::broken_springs, bits);
    int broken = 0;
    for (int l = 0; l < scene.n; ++l)
      for (int k = 0; k < scene.m; ++k) broken += bits(k, l) != 0.0 ? 1 : 0;
    EXPECT_GT(broken, 10);
    Scene unlimited = scene;
    unlimited.springs.min_length = 0.0;
    Simulation free(unlimited, MPI_COMM_SELF);
    ASSERT_TRUE(testing::advance(free, scene.steps));
    EXPECT_GT(differing_nodes(free.positions(), reference.positions()), 0);
  }
  for (const Integrator integrator :
       {Integrator::verlet, Integrator::leapfrog, Integrator::velocity_verlet, Integrator::rk4,
        Integrator::verlet_lagged})
    expect_every_split_follows_one_block(testing::mass_spring_odd_grid_scene(integrator));
}

// Runs `scene` on every split with one and three threads per rank and hands each run, with
// the one-block run at the reference's thread count (OMP_NUM_THREADS) and a label, to
// `expect`.
template <class Expect>
void for_every_split_and_thread_count(const Scene& scene, Expect&& expect) {
  Simulation reference(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(reference, scene.steps));
  const int default_threads = omp_get_max_threads();
  for (const int threads : {1, 3})
    for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
      omp_set_num_threads(threads);
      Simulation sim(scene, MPI_COMM_WORLD, d, any_scheme);
      const bool stable = testing::advance(sim, scene.steps);
      omp_set_num_threads(default_threads);
      ASSERT_TRUE(stable);
      expect(sim, reference,
             "split " + split_name(d) + ", " + std::to_string(threads) + " threads");
    }
}

// S2 as shipped (a corner held, damping), with one and three threads per rank against the
// reference's count.
TEST(DecompositionInvariance, S2CapeFollowsTheOneBlockTrajectory) {
  for_every_split_and_thread_count(
      s2_cape(300), [](Simulation& sim, Simulation& reference, const std::string& run) {
        EXPECT_EQ(differing_nodes(sim.positions(), reference.positions()), 0) << run;
        const Diagnostics a = sim.diagnostics(), b = reference.diagnostics();
        EXPECT_EQ(a.area_ratio, b.area_ratio);
        EXPECT_NEAR(a.kinetic_energy, b.kinetic_energy, 1e-12 * b.kinetic_energy);
      });
}

// The gallery's gusting flag as shipped, its first 0.1 s (1000 steps), with one and three
// threads per rank against the reference's count.
TEST(DecompositionInvariance, GustingFlagFollowsTheOneBlockTrajectory) {
  const Scene scene = load_scene(COSSERAT_SOURCE_DIR "/scenes/gallery/flag_gusts.toml",
                                 {"time.duration=0.1"});
  ASSERT_TRUE(scene.fluid && scene.fluid->gusts && scene.fluid->gusts->amplitude > 0.0);
  for_every_split_and_thread_count(
      scene, [](Simulation& sim, Simulation& reference, const std::string& run) {
        EXPECT_EQ(differing_nodes(sim.positions(), reference.positions()), 0) << run;
        EXPECT_EQ(differing_nodes(sim.velocities(), reference.velocities()), 0) << run;
      });
}

// Runs until the stability check stops the run, at most `steps` steps.
std::optional<Instability> run_until_unstable(Simulation& sim, long steps) {
  for (long s = 0; s < steps; ++s)
    if (auto failure = sim.step()) return failure;
  return std::nullopt;
}

// S2 at a step past its stable one becomes unstable: the check stops every split and thread
// count at the step and node it stops the one-block run, the first failing node in (l, k) order
// whichever rank and thread holds it. For Verlet, whose row walk tests most edges while the rows
// are in cache, at 0.0065 s (the rest sheet's CFL estimate is 0.0063 s; node [1, 0] at step
// 147 when written); for RK4, whose check tests them all in a pass of its own, at 0.009 s (node
// [4, 0] at step 287).
TEST(DecompositionInvariance, AnUnstableRunStopsAtTheSameStepAndNodeOnEverySplit) {
  for (const auto& [integrator, dt] :
       {std::pair{Integrator::verlet, 0.0065}, std::pair{Integrator::rk4, 0.009}}) {
    Scene scene = s2_cape(500);
    scene.integrator = integrator;
    scene.dt = dt;
    const long steps = scene.steps;
    Simulation reference(scene, MPI_COMM_SELF, any_scheme);
    const std::optional<Instability> expected = run_until_unstable(reference, steps);
    ASSERT_TRUE(expected.has_value()) << integrator_name(integrator);
    const int default_threads = omp_get_max_threads();
    for (const int threads : {1, 3})
      for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
        omp_set_num_threads(threads);
        Simulation sim(scene, MPI_COMM_WORLD, d, any_scheme);
        const std::optional<Instability> failure = run_until_unstable(sim, steps);
        omp_set_num_threads(default_threads);
        const std::string run = integrator_name(integrator) + ", split " + split_name(d) + ", " +
                                std::to_string(threads) + " threads";
        ASSERT_TRUE(failure.has_value()) << run;
        EXPECT_EQ(failure->step, expected->step) << run;
        EXPECT_EQ(failure->k, expected->k) << run;
        EXPECT_EQ(failure->l, expected->l) << run;
        EXPECT_EQ(failure->not_finite, expected->not_finite) << run;
        EXPECT_EQ(sim.step_index(), expected->step - 1) << run;
      }
  }
}

// Adaptive steps choose each step from global maxima: the same steps, the same roll-back and the
// same trajectory, bitwise, on every split, for a scheme of each state kind; in gusts too, read
// at the times of steps of every size.
TEST(DecompositionInvariance, AdaptiveStepsAndTheirRollBacksFollowTheOneBlockRun) {
  for (const Integrator integrator : {Integrator::verlet, Integrator::rk4}) {
    for (const Scene& scene : {testing::rolling_back_scene(integrator),
                               testing::gusty_rolling_back_scene(integrator)}) {
      const std::string what = integrator_name(integrator) + (scene.fluid ? " in gusts" : "");
      Simulation reference(scene, MPI_COMM_SELF, any_scheme);
      testing::Silent silent;
      const StepLoopResult expected = run_step_loop(reference, scene, {}, silent);
      ASSERT_FALSE(expected.failure) << what;
      ASSERT_TRUE(expected.adaptive);
      EXPECT_GE(expected.adaptive->rollbacks, 1) << what;
      for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
        Simulation sim(scene, MPI_COMM_WORLD, d, any_scheme);
        const StepLoopResult result = run_step_loop(sim, scene, {}, silent);
        ASSERT_FALSE(result.failure);
        EXPECT_EQ(sim.step_index(), reference.step_index()) << what << ", " << split_name(d);
        EXPECT_EQ(result.adaptive->rollbacks, expected.adaptive->rollbacks) << split_name(d);
        EXPECT_EQ(result.adaptive->smallest_dt, expected.adaptive->smallest_dt) << split_name(d);
        EXPECT_EQ(differing_nodes(sim.positions(), reference.positions()), 0)
            << what << ", split " << split_name(d);
      }
    }
  }
}

// Random steps are the seed's on every split: the same steps and the same trajectory, bitwise,
// for a scheme of each state kind.
TEST(DecompositionInvariance, RandomStepsFollowTheOneBlockRun) {
  for (const Integrator integrator : {Integrator::verlet, Integrator::rk4}) {
    const Scene scene = testing::random_steps_scene(integrator);
    const std::string what = integrator_name(integrator);
    Simulation reference(scene, MPI_COMM_SELF, any_scheme);
    testing::Silent silent;
    const StepLoopResult expected = run_step_loop(reference, scene, {}, silent);
    ASSERT_FALSE(expected.failure) << what;
    ASSERT_TRUE(expected.adaptive);
    EXPECT_LT(expected.adaptive->smallest_dt, expected.adaptive->largest_dt) << what;
    for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
      Simulation sim(scene, MPI_COMM_WORLD, d, any_scheme);
      const StepLoopResult result = run_step_loop(sim, scene, {}, silent);
      ASSERT_FALSE(result.failure);
      EXPECT_EQ(sim.step_index(), reference.step_index()) << what << ", " << split_name(d);
      EXPECT_EQ(result.adaptive->smallest_dt, expected.adaptive->smallest_dt) << split_name(d);
      EXPECT_EQ(differing_nodes(sim.positions(), reference.positions()), 0)
          << what << ", split " << split_name(d);
    }
  }
}

// Contact with a free body (docs/contact.md, "Parallel runs, restarts and output"): contacts on
// owned nodes and cells, the body's impulse sums in one global order, so the cloth and the body
// follow the one-block run bitwise on every split, for a scheme of each state kind.
TEST(DecompositionInvariance, ContactWithAFreeBodyFollowsTheOneBlockRun) {
  for (const Integrator integrator : {Integrator::verlet, Integrator::velocity_verlet}) {
    const Scene scene = testing::free_body_scene(integrator);
    Simulation reference(scene, MPI_COMM_SELF, any_scheme);
    ASSERT_TRUE(testing::advance(reference, scene.steps));
    ASSERT_GT(reference.contact_summary().max_contacts, 0);
    const std::vector<double> body = reference.contact()->state_vector();
    for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
      Simulation sim(scene, MPI_COMM_WORLD, d, any_scheme);
      ASSERT_TRUE(testing::advance(sim, scene.steps));
      EXPECT_EQ(differing_nodes(sim.positions(), reference.positions()), 0)
          << integrator_name(integrator) << ", split " << split_name(d);
      EXPECT_EQ(differing_nodes(sim.velocities(), reference.velocities()), 0)
          << integrator_name(integrator) << ", split " << split_name(d);
      EXPECT_EQ(sim.contact()->state_vector(), body)
          << integrator_name(integrator) << ", split " << split_name(d);
      EXPECT_EQ(sim.contact_summary().max_contacts, reference.contact_summary().max_contacts);
      EXPECT_EQ(sim.contact_summary().max_penetration,
                reference.contact_summary().max_penetration);
    }
  }
}

// A contact scene's run on every split against the one-block run, bitwise: positions,
// velocities and the most nodes in contact.
void expect_every_split_follows_the_one_block_run(const Scene& scene) {
  Simulation reference(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(reference, scene.steps));
  ASSERT_GT(reference.contact_summary().max_contacts, 0);
  for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
    Simulation sim(scene, MPI_COMM_WORLD, d, any_scheme);
    ASSERT_TRUE(testing::advance(sim, scene.steps));
    EXPECT_EQ(differing_nodes(sim.positions(), reference.positions()), 0)
        << "split " << split_name(d);
    EXPECT_EQ(differing_nodes(sim.velocities(), reference.velocities()), 0)
        << "split " << split_name(d);
    EXPECT_EQ(sim.contact_summary().max_contacts, reference.contact_summary().max_contacts);
  }
}

// The contact broad phase visits only tiles of nodes a solid can reach, tiles that follow the
// blocks: with six solids, two moving, each reaching part of the sheet, every split still
// follows the one-block run bitwise. In velocity-verlet too, whose cell pass reads its
// neighbours' scheme offsets across the blocks' borders (docs/contact.md, "Velocities").
TEST(DecompositionInvariance, ContactBroadPhaseFollowsTheOneBlockRun) {
  for (const Integrator integrator : {Integrator::verlet, Integrator::velocity_verlet}) {
    SCOPED_TRACE(integrator_name(integrator));
    Scene scene = testing::many_solids_scene();
    scene.integrator = integrator;
    expect_every_split_follows_the_one_block_run(scene);
  }
}

// With one plane and no other solid the walk settles the nodes on it alone, and writes their
// r⁻ itself (docs/contact.md, "r⁻ written in the walk"): a sheet landing on a tilted floor
// that some of its nodes slide down and others stick to follows the one-block run bitwise on
// every split.
TEST(DecompositionInvariance, ContactOnOneFloorFollowsTheOneBlockRun) {
  Scene scene = testing::soft_sheet(13, 11, 1.2, 1.0, {-0.6, 0.05, -0.5});
  scene.integrator = Integrator::verlet;
  scene.steps = 250;
  SolidSpec floor;
  floor.name = "floor";
  floor.shape.kind = ShapeKind::plane;
  const Vec3 up{0.25, 1.0, 0.0};
  floor.pose.orientation = rotation_between({0.0, 0.0, 1.0}, up / norm(up));
  floor.friction = 0.22;
  floor.thickness = 2e-3;
  scene.solids.push_back(floor);
  expect_every_split_follows_the_one_block_run(scene);
}

// testing::layered_sheet with `rows` rows at its spacing, on a floor, under gravity, 1e-4 s steps.
Scene layers_on_a_floor(int rows, Integrator integrator, long steps) {
  Scene scene = testing::layers_over_a_floor(2e-3, 0.3);
  scene.n = rows;
  scene.size2 = 0.05 * (rows - 1);
  scene.integrator = integrator;
  scene.steps = steps;
  return scene;
}

// The top layer fired onto the bottom one, on one block and then on every split of the world's
// ranks: the same bits, pairs and closest distance. Whether on some split this rank held fewer
// nodes than the grid has.
bool expect_fired_layers_follow_the_one_block_run(const Scene& scene) {
  const Vec3 fired{0.3, -20.0, 0.2};
  Simulation reference(scene, MPI_COMM_SELF, any_scheme);
  testing::fold(reference, scene, 1e-3, 0.02, fired);
  EXPECT_TRUE(testing::advance(reference, scene.steps));
  EXPECT_GT(reference.self_contact_summary()->max_pairs, 0);
  const auto nodes = static_cast<std::size_t>(scene.m) * static_cast<std::size_t>(scene.n);
  EXPECT_EQ(reference.self_contact()->nodes_held(), nodes);
  bool fewer = false;
  for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
    Simulation sim(scene, MPI_COMM_WORLD, d, any_scheme);
    testing::fold(sim, scene, 1e-3, 0.02, fired);
    EXPECT_TRUE(testing::advance(sim, scene.steps));
    EXPECT_EQ(differing_nodes(sim.positions(), reference.positions()), 0)
        << "split " << split_name(d);
    EXPECT_EQ(differing_nodes(sim.velocities(), reference.velocities()), 0)
        << "split " << split_name(d);
    EXPECT_EQ(sim.self_contact_summary()->max_pairs, reference.self_contact_summary()->max_pairs);
    EXPECT_EQ(sim.self_contact_summary()->closest, reference.self_contact_summary()->closest);
    fewer = fewer || sim.self_contact()->nodes_held() < nodes;
  }
  return fewer;
}

// Self-contact (docs/contact.md, "Self-contact", "Parallel runs and restarts"): a layer fired
// onto another lying on a floor, with the pairs across every block border, follows the
// one-block run bitwise on every split, in a scheme of each state kind.
TEST(DecompositionInvariance, SelfContactFollowsTheOneBlockRun) {
  for (const Integrator integrator : {Integrator::verlet, Integrator::velocity_verlet}) {
    SCOPED_TRACE(integrator_name(integrator));
    expect_fired_layers_follow_the_one_block_run(layers_on_a_floor(20, integrator, 80));
  }
}

// A strip 20 m long folded into two 10 m layers: each rank holds only its own nodes and those of
// other ranks within the response's reach of them (about 2.4 m here, and 3.5 m sent), and the
// pairs join blocks that are not neighbours in the grid (a row of the top layer lies over the
// row of the bottom one n − 1 − l away). Every split follows the one-block run bitwise, and on
// three or more ranks split along the strip some rank holds fewer nodes than the grid has
// (checked: with each rank sent every node, the last expectation fails).
TEST(DecompositionInvariance, SelfContactExchangesOnlyTheNodesWithinReach) {
  const Scene scene = layers_on_a_floor(400, Integrator::verlet, 60);
  int fewer = expect_fired_layers_follow_the_one_block_run(scene) ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &fewer, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (world_size() >= 3) {
    EXPECT_EQ(fewer, 1) << "every rank held every node";
  }
}

// The same with the top layer turned 20° about the vertical through the sheet's middle, so that
// its edges cross the bottom layer's edges at an angle and hold them as pairs of edges across the
// block borders: with the border's edges alone (checked: with the edge pairs left out this run's
// positions differ from the one with them), and with every edge, where pairs of edges inside
// the layers act too (the two rules' positions differ).
TEST(DecompositionInvariance, SelfContactOfEdgesFollowsTheOneBlockRun) {
  std::vector<Field<Vec3>> references;
  for (const bool every_edge : {false, true}) {
    SCOPED_TRACE(every_edge ? "every edge" : "the border's edges");
    Scene scene = testing::layered_sheet(2e-3);
    scene.self_contact->every_edge = every_edge;
    scene.dt = 1e-4;
    scene.steps = 80;
    const Vec3 fired{0.3, -20.0, 0.2};
    const double angle = 20.0 * std::acos(-1.0) / 180.0;
    const Vec3 middle{0.5 * scene.size1, 0.0, 0.25 * scene.size2};
    // Turns the top layer's positions and previous positions, ghosts included, about the vertical.
    auto turn_top = [&](Simulation& sim) {
      const auto fields = sim.stepper().state_fields();
      const Block& b = sim.block();
      for (const int f : {0, 1})
        for (int l = std::max(scene.n / 2, b.l0 - b.ghost); l < std::min(scene.n, b.l1 + b.ghost);
             ++l)
          for (int k = std::max(0, b.k0 - b.ghost); k < std::min(scene.m, b.k1 + b.ghost); ++k) {
            Vec3& x = (*fields.at(static_cast<std::size_t>(f)).field)(k, l);
            const Vec3 d = x - middle;
            x = middle + Vec3{std::cos(angle) * d.x + std::sin(angle) * d.z, d.y,
                              -std::sin(angle) * d.x + std::cos(angle) * d.z};
          }
      sim.stepper().resume(0);
    };
    Simulation reference(scene, MPI_COMM_SELF, any_scheme);
    testing::fold(reference, scene, 0.0, 0.02, fired);
    turn_top(reference);
    ASSERT_TRUE(testing::advance(reference, scene.steps));
    ASSERT_GT(reference.self_contact_summary()->max_pairs, 0);
    for (const Decomposition& d : all_splits(scene.m, scene.n, world_size())) {
      Simulation sim(scene, MPI_COMM_WORLD, d, any_scheme);
      testing::fold(sim, scene, 0.0, 0.02, fired);
      turn_top(sim);
      ASSERT_TRUE(testing::advance(sim, scene.steps));
      EXPECT_EQ(differing_nodes(sim.positions(), reference.positions()), 0)
          << "split " << split_name(d);
      EXPECT_EQ(sim.self_contact_summary()->max_pairs, reference.self_contact_summary()->max_pairs);
    }
    references.push_back(reference.positions());
  }
  EXPECT_GT(differing_nodes(references[0], references[1]), 0);
}

}  // namespace
}  // namespace cosserat
