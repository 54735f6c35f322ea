// Checkpoint, restart and collective output under mpiexec. A restart continues bitwise: on the
// same ranks with another split, and on one rank from a checkpoint written by P. The output of
// P ranks reads back equal to the output of one.

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cosserat/baseline/semi_implicit.hpp"
#include "cosserat/io/checkpoint.hpp"
#include "cosserat/io/frame_writer.hpp"
#include "cosserat/io/output_fields.hpp"
#include "cosserat/time/step_loop.hpp"
#include "mpi_support.hpp"
#include "support/dataset_bytes.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

namespace fs = std::filesystem;
using testing::explicit_integrators;
using testing::dataset_bytes;
using testing::all_splits;
using testing::differing_nodes;
using testing::world_rank;
using testing::world_size;

// A folder every rank sees, made by rank 0 and removed when the test ends.
class SharedFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    long pid = getpid();
    MPI_Bcast(&pid, 1, MPI_LONG, 0, MPI_COMM_WORLD);
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    folder_ = fs::temp_directory_path() /
              ("cosserat_mpi_" + std::to_string(pid) + "_" + test->name());
    if (world_rank() == 0) fs::create_directories(folder_);
    MPI_Barrier(MPI_COMM_WORLD);
  }
  void TearDown() override {
    MPI_Barrier(MPI_COMM_WORLD);
    if (world_rank() == 0) fs::remove_all(folder_);
  }

  fs::path folder_;
};

// Checkpoint at half the scene's steps on all ranks, then continue from the file.
class Restart : public SharedFolder {
 protected:
  std::string checkpoint() const { return (folder_ / "run.checkpoint.h5").string(); }

  // Runs `scene` on all ranks, split as the driver splits it, to half its steps and writes the
  // checkpoint.
  void checkpoint_at_half(const Scene& scene) const {
    Simulation first(scene, MPI_COMM_WORLD, any_scheme);
    ASSERT_TRUE(testing::advance(first, scene.steps / 2));
    write_checkpoint(checkpoint(), first, scene, "test");
  }

  // Reads the checkpoint into `sim` (any split, any communicator) and runs it to the end.
  void continue_to_end(Simulation& sim, const Scene& scene) const {
    EXPECT_EQ(read_checkpoint(checkpoint(), sim, scene), scene.steps / 2);
    ASSERT_TRUE(testing::advance(sim, scene.steps - scene.steps / 2));
    EXPECT_EQ(sim.step_index(), scene.steps);
  }

  // Checkpoints `scene` at half its steps on all ranks, continues on another split and, on
  // every rank alone, on one block: both end bitwise where one uninterrupted block ends.
  void expect_restarts_bitwise(const Scene& scene) const {
    const std::string scheme = integrator_name(scene.integrator);
    const auto splits = all_splits(scene.m, scene.n, world_size());
    Simulation uninterrupted(scene, MPI_COMM_SELF, any_scheme);  // one block: the comparisons' reference
    ASSERT_TRUE(testing::advance(uninterrupted, scene.steps));

    checkpoint_at_half(scene);
    Simulation other_split(scene, MPI_COMM_WORLD, splits.back(), any_scheme);
    continue_to_end(other_split, scene);
    EXPECT_EQ(differing_nodes(other_split.positions(), uninterrupted.positions()), 0)
        << scheme << ", split " << testing::split_name(splits.back());
    EXPECT_EQ(differing_nodes(other_split.velocities(), uninterrupted.velocities()), 0)
        << scheme;

    // Every rank restarts the whole grid alone from the file the P ranks wrote.
    Simulation one_rank(scene, MPI_COMM_SELF, any_scheme);
    continue_to_end(one_rank, scene);
    EXPECT_EQ(differing_nodes(one_rank.positions(), uninterrupted.positions()), 0)
        << scheme << " restarted on one rank";
    EXPECT_EQ(differing_nodes(one_rank.velocities(), uninterrupted.velocities()), 0)
        << scheme << " restarted on one rank";
    MPI_Barrier(MPI_COMM_WORLD);  // every rank has read it before the next run replaces it
  }
};

TEST_F(Restart, ContinuesBitwiseOnAnotherSplitAndOnOneRank) {
  for (const Integrator integrator : explicit_integrators())
    expect_restarts_bitwise(testing::odd_grid_scene(integrator));  // 80 steps
}

// The gusts are a function of position, time and seed: the checkpoint holds nothing for them,
// and a restart reads them at the same times, bitwise.
TEST_F(Restart, InGustsContinuesBitwiseOnAnotherSplitAndOnOneRank) {
  for (const Integrator integrator : explicit_integrators())
    expect_restarts_bitwise(testing::gusty_odd_grid_scene(integrator));
}

// The mass-spring model's broken springs are part of the checkpoint (the model's step state):
// springs torn before the checkpoint stay torn after it, on any split.
TEST_F(Restart, MassSpringContinuesBitwiseOnAnotherSplitAndOnOneRank) {
  {
    const Scene scene = testing::mass_spring_odd_grid_scene(Integrator::verlet);
    Simulation half(scene, MPI_COMM_SELF);
    ASSERT_TRUE(testing::advance(half, scene.steps / 2));
    Field<double> bits(half.block());
    half.node_field(OutputField::broken_springs, bits);
    int broken = 0;
    for (int l = 0; l < scene.n; ++l)
      for (int k = 0; k < scene.m; ++k) broken += bits(k, l) != 0.0 ? 1 : 0;
    EXPECT_GT(broken, 0) << "nothing torn by the checkpoint";
  }
  for (const Integrator integrator : {Integrator::verlet, Integrator::velocity_verlet})
    expect_restarts_bitwise(testing::mass_spring_odd_grid_scene(integrator));
}

#if defined(COSSERAT_HAVE_PETSC)
// The semi-implicit baseline keeps the Verlet family's state (rⁿ, rⁿ⁻¹) and builds its
// Jacobian from rⁿ on every step that is a multiple of time.solver.jacobian_every, so a restart
// at such a step continues it too; to the linear solver's tolerance, not bitwise, since block
// Jacobi preconditions each split differently (test_semi_implicit.cpp). The second-order step
// keeps its Jacobian for four steps and is checkpointed at step 20.
TEST_F(Restart, SemiImplicitContinuesOnAnotherSplitAndOnOneRank) {
  Scene reused = testing::semi_implicit_odd_grid_scene(Integrator::semi_implicit_2);
  reused.solver.jacobian_every = 4;
  for (const Scene& scene : {testing::semi_implicit_odd_grid_scene(), reused}) {
    const std::string name = integrator_name(scene.integrator);
    const auto splits = all_splits(scene.m, scene.n, world_size());
    Simulation uninterrupted(scene, MPI_COMM_SELF, any_scheme);
    ASSERT_TRUE(testing::advance(uninterrupted, scene.steps));
    checkpoint_at_half(scene);
    Simulation other_split(scene, MPI_COMM_WORLD, splits.back(), any_scheme);
    continue_to_end(other_split, scene);
    // As in test_semi_implicit.cpp: 40 solves to 1e-12 of |δ| stay far below 1e-9 m.
    EXPECT_LT(testing::largest_difference(other_split.positions(), uninterrupted.positions()),
              1e-9)
        << name << ", split " << testing::split_name(splits.back());

    Simulation one_rank(scene, MPI_COMM_SELF, any_scheme);
    continue_to_end(one_rank, scene);
    EXPECT_LT(testing::largest_difference(one_rank.positions(), uninterrupted.positions()), 1e-9)
        << name << " restarted on one rank";
    MPI_Barrier(MPI_COMM_WORLD);  // every rank has read it before the next run replaces it
  }
}
#endif

TEST_F(Restart, RefusesACheckpointOfAnotherGridOrStep) {
  const std::string checkpoint = (folder_ / "run.checkpoint.h5").string();
  const Scene scene = testing::odd_grid_scene(Integrator::verlet);
  {
    Simulation sim(scene, MPI_COMM_WORLD, any_scheme);
    ASSERT_TRUE(testing::advance(sim, 5));
    write_checkpoint(checkpoint, sim, scene, "test");
  }
  EXPECT_FALSE(fs::exists(checkpoint + ".partial"));
  Scene other_dt = scene;
  other_dt.dt *= 0.5;
  Simulation sim(other_dt, MPI_COMM_WORLD, any_scheme);
  EXPECT_THROW(read_checkpoint(checkpoint, sim, other_dt), CheckpointError);
  Scene other_scheme = scene;
  other_scheme.integrator = Integrator::rk4;
  Simulation rk4(other_scheme, MPI_COMM_WORLD, any_scheme);
  EXPECT_THROW(read_checkpoint(checkpoint, rk4, other_scheme), CheckpointError);
  EXPECT_THROW(read_checkpoint((folder_ / "missing.h5").string(), sim, other_dt), CheckpointError);
}

// Rank 0 rewrites part of a dataset of a closed file, as damage or a hand edit would leave it;
// the other ranks wait for it.
template <class T>
void overwrite(const std::string& file, const std::string& dataset, std::vector<hsize_t> start,
               std::vector<hsize_t> count, hid_t memory_type, const std::vector<T>& values) {
  if (world_rank() == 0) {
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
    const hid_t space = H5Dget_space(d);
    H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
    const hid_t memory = H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr);
    EXPECT_GE(H5Dwrite(d, memory_type, memory, space, H5P_DEFAULT, values.data()), 0);
    H5Sclose(memory);
    H5Sclose(space);
    H5Dclose(d);
    EXPECT_GE(H5Fclose(f), 0);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// A random sequence continues only as itself: a checkpoint of one seed or one shortest step is
// refused by a scene of another (they would continue bitwise but as another run), and by a scene
// of adaptive steps.
TEST_F(Restart, RefusesACheckpointOfAnotherStepSequence) {
  const std::string checkpoint = (folder_ / "random.checkpoint.h5").string();
  const Scene scene = testing::random_steps_scene(Integrator::verlet);
  {
    Simulation sim(scene, MPI_COMM_WORLD, any_scheme);
    ASSERT_TRUE(testing::advance(sim, 5));
    write_checkpoint(checkpoint, sim, scene, "test");
  }
  Scene other_seed = scene;
  other_seed.adaptive->seed += 1;
  Scene other_min = scene;
  other_min.adaptive->min *= 0.5;
  Scene adaptive = scene;
  adaptive.adaptive->random = false;
  for (const Scene& other : {other_seed, other_min, adaptive}) {
    Simulation sim(other, MPI_COMM_WORLD, any_scheme);
    EXPECT_THROW(read_checkpoint(checkpoint, sim, other), CheckpointError);
  }
  Simulation same(scene, MPI_COMM_WORLD, any_scheme);
  EXPECT_EQ(read_checkpoint(checkpoint, same, scene), 5);
  MPI_Barrier(MPI_COMM_WORLD);
}

// Issue 12, defect 12: what a checkpoint holds is checked before a restart uses it, and every
// rank refuses alike, even where the bad value lies in one rank's block. Before, a NaN started
// the run and constraints outside the grid or of no fix were ignored.
TEST_F(Restart, RefusesACheckpointWhoseContentsTheSceneCannotContinue) {
  const Scene scene = testing::odd_grid_scene(Integrator::verlet);
  const auto write = [&](std::optional<double> peak = {}) {
    Simulation sim(scene, MPI_COMM_WORLD, any_scheme);
    ASSERT_TRUE(testing::advance(sim, 5));
    write_checkpoint(checkpoint(), sim, scene, "test", peak);
  };
  // The message every rank got, or "" when the checkpoint was taken.
  const auto refusal = [&] {
    Simulation sim(scene, MPI_COMM_WORLD, any_scheme);
    try {
      read_checkpoint(checkpoint(), sim, scene);
    } catch (const CheckpointError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const auto expect_refused = [&](const std::string& what) {
    const std::string message = refusal();
    EXPECT_NE(message.find(checkpoint()), std::string::npos) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const hsize_t m = static_cast<hsize_t>(scene.m), n = static_cast<hsize_t>(scene.n);

  write();
  ASSERT_EQ(refusal(), "");
  // The last node: in the last rank's block for every split.
  overwrite<double>(checkpoint(), "/previous_positions", {m - 1, n - 1, 0}, {1, 1, 3},
                    H5T_NATIVE_DOUBLE, {0.0, nan, 0.0});
  expect_refused("/previous_positions at node [36, 22] is (0, nan, 0), not finite");

  write();
  overwrite<std::int32_t>(checkpoint(), "/constraint_nodes", {0, 0}, {1, 2}, H5T_NATIVE_INT32,
                          {37, 5});
  expect_refused("constraint node [37, 5] is outside the 37 x 23 grid");
  write();
  overwrite<std::int32_t>(checkpoint(), "/constraint_nodes", {0, 0}, {1, 2}, H5T_NATIVE_INT32,
                          {18, 20});
  expect_refused("constraint node [18, 20] is held by no [[fix]] of this scene");
  write();
  overwrite<std::uint8_t>(checkpoint(), "/constraint_held", {0, 0}, {1, 1}, H5T_NATIVE_UINT8,
                          {8});
  expect_refused("beyond the");
  write();
  overwrite<double>(checkpoint(), "/constraint_values", {0, 0}, {1, 3}, H5T_NATIVE_DOUBLE,
                    {0.0, 0.0, std::numeric_limits<double>::infinity()});
  expect_refused("not finite");
  write();
  overwrite<double>(checkpoint(), "/constraint_velocities", {0, 0}, {1, 3}, H5T_NATIVE_DOUBLE,
                    {nan, 0.0, 0.0});
  expect_refused("m/s: not finite");

  write(nan);
  expect_refused("peak kinetic energy is nan");

  // /positions of another shape than the grid's.
  write();
  if (world_rank() == 0) {
    const hid_t f = H5Fopen(checkpoint().c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    EXPECT_GE(H5Ldelete(f, "/positions", H5P_DEFAULT), 0);
    const std::array<hsize_t, 3> dims{m, n + 1, 3};
    const hid_t space = H5Screate_simple(3, dims.data(), nullptr);
    const hid_t d = H5Dcreate2(f, "/positions", H5T_IEEE_F64LE, space, H5P_DEFAULT,
                               H5P_DEFAULT, H5P_DEFAULT);
    H5Dclose(d);
    H5Sclose(space);
    H5Fclose(f);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  expect_refused("/positions is [37, 24, 3], not the [37, 23, 3] of this grid");
}

// Checkpoints from before fixes could move lack /constraint_since and /constraint_velocities,
// and those from before they could turn /constraint_spins and /constraint_pivots: every fix was
// still then, and such a checkpoint restarts bitwise as if they held zeros (here one written at
// step 5, before the odd grid's moving and turning fixes switch on at steps 20 and 25).
TEST_F(Restart, ACheckpointWithoutFixVelocitiesRestartsBitwise) {
  Scene scene = testing::odd_grid_scene(Integrator::verlet);
  Simulation uninterrupted(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(uninterrupted, scene.steps));
  {
    Simulation first(scene, MPI_COMM_WORLD, any_scheme);
    ASSERT_TRUE(testing::advance(first, 5));
    write_checkpoint(checkpoint(), first, scene, "test");
  }
  if (world_rank() == 0) {
    const hid_t f = H5Fopen(checkpoint().c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    EXPECT_GE(H5Ldelete(f, "/constraint_since", H5P_DEFAULT), 0);
    EXPECT_GE(H5Ldelete(f, "/constraint_velocities", H5P_DEFAULT), 0);
    EXPECT_GE(H5Ldelete(f, "/constraint_spins", H5P_DEFAULT), 0);
    EXPECT_GE(H5Ldelete(f, "/constraint_pivots", H5P_DEFAULT), 0);
    EXPECT_GE(H5Fclose(f), 0);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  Simulation restarted(scene, MPI_COMM_WORLD, any_scheme);
  EXPECT_EQ(read_checkpoint(checkpoint(), restarted, scene), 5);
  ASSERT_TRUE(testing::advance(restarted, scene.steps - 5));
  EXPECT_EQ(differing_nodes(restarted.positions(), uninterrupted.positions()), 0);
}

using Output = SharedFolder;

TEST_F(Output, OfPRanksReadsBackEqualToOneRank) {
  const Scene scene = testing::odd_grid_scene(Integrator::verlet);
  const std::string parallel = (folder_ / "parallel.h5").string();
  const std::string serial = (folder_ / "serial.h5").string();
  auto run = [&](const std::string& path, MPI_Comm comm) {
    Simulation sim(scene, comm, any_scheme);
    FrameWriter writer(path, sim.block(), scene.text, "verlet", "test", {});
    writer.write_frame(sim.step_index(), sim.time(), sim.positions());
    for (int frame = 0; frame < 4; ++frame) {
      testing::advance(sim, scene.output_every);
      writer.write_frame(sim.step_index(), sim.time(), sim.positions());
    }
  };
  run(parallel, MPI_COMM_WORLD);
  if (world_rank() == 0) run(serial, MPI_COMM_SELF);
  MPI_Barrier(MPI_COMM_WORLD);

  int equal = 1;
  if (world_rank() == 0)
    for (const char* name : {"/positions", "/time", "/step"}) {
      const auto a = dataset_bytes(parallel, name), b = dataset_bytes(serial, name);
      equal = equal && !a.empty() && a == b;
    }
  MPI_Bcast(&equal, 1, MPI_INT, 0, MPI_COMM_WORLD);
  EXPECT_TRUE(equal) << "P = " << world_size();
}

// The per-node fields (docs/output.md, "Fields") of P ranks, each computed on its block from the
// positions and their ghosts and written as its hyperslab, equal one rank's bit for bit; in
// both forms (the flux form's energy density is the energy form's formula at its positions),
// for a scheme that carries velocities and one that derives them.
TEST_F(Output, FieldsOfPRanksReadBackEqualToOneRank) {
  for (const auto& [integrator, discretisation] :
       {std::pair{Integrator::verlet, Discretisation::energy},
        std::pair{Integrator::rk4, Discretisation::flux}}) {
    Scene scene = testing::odd_grid_scene(integrator);
    scene.discretisation = discretisation;
    ASSERT_EQ(scene.output_fields, all_output_fields());
    const std::string tag = std::string(discretisation_name(discretisation));
    const std::string parallel = (folder_ / ("parallel_fields_" + tag + ".h5")).string();
    const std::string serial = (folder_ / ("serial_fields_" + tag + ".h5")).string();
    auto run = [&](const std::string& path, MPI_Comm comm) {
      Simulation sim(scene, comm, any_scheme);
      OutputFieldValues fields(sim.block(), scene.output_fields);
      FrameWriter writer(path, sim.block(), scene.text, "verlet", "test", {}, {},
                         node_fields(scene.output_fields));
      writer.write_frame(sim.step_index(), sim.time(), sim.positions(), {}, fields.evaluate(sim));
      for (int frame = 0; frame < 3; ++frame) {
        testing::advance(sim, scene.output_every);
        writer.write_frame(sim.step_index(), sim.time(), sim.positions(), {},
                           fields.evaluate(sim));
      }
    };
    run(parallel, MPI_COMM_WORLD);
    if (world_rank() == 0) run(serial, MPI_COMM_SELF);
    MPI_Barrier(MPI_COMM_WORLD);

    int equal = 1;
    if (world_rank() == 0)
      for (const OutputField field : all_output_fields()) {
        const std::string name = std::string("/fields/") + output_field_name(field);
        const auto a = dataset_bytes(parallel, name.c_str());
        const auto b = dataset_bytes(serial, name.c_str());
        EXPECT_EQ(a.size(), 4 * 37 * 23 * sizeof(double) * (field == OutputField::velocity ? 3 : 1))
            << name << ", " << tag;
        EXPECT_EQ(a, b) << name << ", " << tag;
        equal = equal && !a.empty() && a == b;
      }
    MPI_Bcast(&equal, 1, MPI_INT, 0, MPI_COMM_WORLD);
    EXPECT_TRUE(equal) << "P = " << world_size() << ", " << tag;
  }
}

// Rigid solids are replicated on every rank and written by rank 0, inside the same collective
// calls: the file of P ranks, written and then continued after a restart, equals one rank's.
TEST_F(Output, WithSolidsOfPRanksReadsBackEqualToOneRank) {
  const Scene scene = testing::odd_grid_scene(Integrator::verlet);
  const std::string parallel = (folder_ / "parallel_solids.h5").string();
  const std::string serial = (folder_ / "serial_solids.h5").string();
  const TriangleMesh tetrahedron{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                 {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
  const std::vector<SolidOutline> solids{{"floor", tetrahedron}, {"post", tetrahedron}};
  const auto poses = [](long step) {
    const double turn = 1e-3 * static_cast<double>(step);
    return std::vector<Pose>{
        Pose{Vec3{0.0, -1.0, 0.0}, Quaternion{}},
        Pose{Vec3{0.5, 1e-4 * static_cast<double>(step), 0.25},
             Quaternion{std::cos(turn), 0.0, std::sin(turn), 0.0}}};
  };
  auto run = [&](const std::string& path, MPI_Comm comm) {
    Simulation sim(scene, comm, any_scheme);
    long restart_step = 0;
    {
      FrameWriter writer(path, sim.block(), scene.text, "verlet", "test", {}, solids);
      writer.write_frame(sim.step_index(), sim.time(), sim.positions(), poses(sim.step_index()));
      for (int frame = 0; frame < 3; ++frame) {
        testing::advance(sim, scene.output_every);
        writer.write_frame(sim.step_index(), sim.time(), sim.positions(),
                           poses(sim.step_index()));
        if (frame == 0) restart_step = sim.step_index();
      }
    }
    // Continued from the frame after the first: the last two frames are written again.
    FrameWriter writer(path, sim.block(), restart_step, scene.text, restart_step, 0.0, solids);
    writer.write_frame(sim.step_index(), sim.time(), sim.positions(), poses(sim.step_index()));
  };
  run(parallel, MPI_COMM_WORLD);
  if (world_rank() == 0) run(serial, MPI_COMM_SELF);
  MPI_Barrier(MPI_COMM_WORLD);

  int equal = 1;
  if (world_rank() == 0)
    for (const char* name :
         {"/positions", "/time", "/step", "/solids/0/vertices", "/solids/0/triangles",
          "/solids/0/position", "/solids/0/orientation", "/solids/0/world_vertices",
          "/solids/1/position", "/solids/1/orientation", "/solids/1/world_vertices"}) {
      const auto a = dataset_bytes(parallel, name), b = dataset_bytes(serial, name);
      EXPECT_FALSE(a.empty()) << name;
      EXPECT_EQ(a, b) << name;
      equal = equal && !a.empty() && a == b;
    }
  MPI_Bcast(&equal, 1, MPI_INT, 0, MPI_COMM_WORLD);
  EXPECT_TRUE(equal) << "P = " << world_size();
}

// Writes the first checkpoint the loop asks for and no other, with what the loop carries; with
// no path, none.
class FirstCheckpoint : public StepObserver {
 public:
  FirstCheckpoint(Simulation& simulation, const Scene& scene, std::string path)
      : simulation_(simulation), scene_(scene), path_(std::move(path)) {}
  void frame() override {}
  void checkpoint(const LoopCarry& carry) override {
    if (written_ || path_.empty()) return;
    write_checkpoint(path_, simulation_, scene_, "test", std::nullopt, carry.adaptive_scale);
    written_ = true;
  }
  void progress(long) override {}

 private:
  Simulation& simulation_;
  const Scene& scene_;
  std::string path_;
  bool written_ = false;
};

// Runs `scene` (adaptive or random steps) uninterrupted on one block, and on all ranks
// checkpointed at step 150 (checkpoints every 150 steps, the first kept) and restarted on another
// split: both end bitwise alike. Adaptive steps must have rolled back on the way.
void expect_adaptive_restart_bitwise(const Scene& scene, const std::string& checkpoint) {
  const std::string scheme = integrator_name(scene.integrator);
  Simulation uninterrupted(scene, MPI_COMM_SELF, any_scheme);
  StepLoopOptions options;
  options.checkpoint_every = 150;
  // The same schedule: a checkpoint is also where roll-backs stop.
  FirstCheckpoint none(uninterrupted, scene, "");
  const StepLoopResult expected = run_step_loop(uninterrupted, scene, options, none);
  ASSERT_FALSE(expected.failure) << scheme;
  if (!scene.adaptive->random) {
    EXPECT_GE(expected.adaptive->rollbacks, 1) << scheme;
  }

  Simulation first(scene, MPI_COMM_WORLD, any_scheme);
  FirstCheckpoint keep(first, scene, checkpoint);
  ASSERT_FALSE(run_step_loop(first, scene, options, keep).failure);

  const auto splits = all_splits(scene.m, scene.n, world_size());
  Simulation restarted(scene, MPI_COMM_WORLD, splits.back(), any_scheme);
  double scale = 0.0;
  EXPECT_EQ(read_checkpoint(checkpoint, restarted, scene, nullptr, &scale), 150);
  options.adaptive_scale = scale;
  FirstCheckpoint ignore(restarted, scene, "");
  ASSERT_FALSE(run_step_loop(restarted, scene, options, ignore).failure);
  EXPECT_EQ(restarted.time(), uninterrupted.time());
  EXPECT_EQ(restarted.step_index(), uninterrupted.step_index()) << scheme;
  EXPECT_EQ(differing_nodes(restarted.positions(), uninterrupted.positions()), 0) << scheme;
  MPI_Barrier(MPI_COMM_WORLD);  // every rank has read it before the next run replaces it
}

// Adaptive steps restart bitwise: the checkpoint holds the last step (tc-verlet's previous step)
// and what roll-backs left of the estimate, and the restarted run holds the same states to roll
// back to.
TEST_F(Restart, AdaptiveStepsContinueBitwise) {
  for (const Integrator integrator : {Integrator::verlet, Integrator::velocity_verlet})
    expect_adaptive_restart_bitwise(testing::rolling_back_scene(integrator), checkpoint());
}

// Random steps restart bitwise: step n's length is the seed's and n's, and the checkpoint holds
// the last step (tc-verlet's previous step) and the seed.
TEST_F(Restart, RandomStepsContinueBitwise) {
  for (const Integrator integrator : {Integrator::verlet, Integrator::velocity_verlet})
    expect_adaptive_restart_bitwise(testing::random_steps_scene(integrator), checkpoint());
}

// In gusts, which rk4 reads at the middle and the end of steps whose sizes vary.
TEST_F(Restart, AdaptiveStepsInGustsContinueBitwise) {
  expect_adaptive_restart_bitwise(testing::gusty_rolling_back_scene(Integrator::rk4),
                                  checkpoint());
}

// With a free body in contact, the checkpoint also holds the solids' state: a restart on
// another split, and on one rank, continues the cloth and the body bitwise.
TEST_F(Restart, ContactWithAFreeBodyContinuesBitwise) {
  const Scene scene = testing::free_body_scene(Integrator::verlet);
  Simulation uninterrupted(scene, MPI_COMM_SELF, any_scheme);
  ASSERT_TRUE(testing::advance(uninterrupted, scene.steps));
  checkpoint_at_half(scene);
  const auto splits = all_splits(scene.m, scene.n, world_size());
  Simulation restarted(scene, MPI_COMM_WORLD, splits.back(), any_scheme);
  continue_to_end(restarted, scene);
  EXPECT_EQ(differing_nodes(restarted.positions(), uninterrupted.positions()), 0);
  EXPECT_EQ(restarted.contact()->state_vector(), uninterrupted.contact()->state_vector());
  Simulation alone(scene, MPI_COMM_SELF, any_scheme);
  continue_to_end(alone, scene);
  EXPECT_EQ(differing_nodes(alone.positions(), uninterrupted.positions()), 0);
}

}  // namespace
}  // namespace cosserat
