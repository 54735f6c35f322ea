// The step loop's schedule (time/step_loop.hpp): which steps get a frame, a checkpoint and a
// progress report, where --until-rest stops, and where an instability leaves the run. The
// observer only records, so the schedule is checked without any file.

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "cosserat/time/simulation.hpp"
#include "cosserat/time/step_loop.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

using testing::advance;
using testing::fix_nodes;
using testing::flat_sheet;

// One observer call: its kind and the simulation's step when it came.
struct Event {
  std::string kind;
  long step;
  bool operator==(const Event&) const = default;
};

void PrintTo(const Event& e, std::ostream* out) { *out << e.kind << '@' << e.step; }

class Recorder : public StepObserver {
 public:
  explicit Recorder(const Simulation& simulation) : simulation_(simulation) {}
  void frame() override { events.push_back({"frame", simulation_.step_index()}); }
  void checkpoint(const LoopCarry&) override { events.push_back({"checkpoint", simulation_.step_index()}); }
  void progress(long step) override {
    EXPECT_EQ(step, simulation_.step_index());
    events.push_back({"progress", step});
  }

  std::vector<long> steps_of(const std::string& kind) const {
    std::vector<long> steps;
    for (const Event& e : events)
      if (e.kind == kind) steps.push_back(e.step);
    return steps;
  }

  std::vector<Event> events;

 private:
  const Simulation& simulation_;
};

std::vector<long> one_to(long last) {
  std::vector<long> steps;
  for (long s = 1; s <= last; ++s) steps.push_back(s);
  return steps;
}

// A 6 x 6 sheet hung by two corners, falling and swinging under gravity with some damping: its
// kinetic energy rises to a peak and then decays.
Scene hanging_sheet() {
  Scene scene = flat_sheet(6, 6);
  scene.gravity = {0.0, -9.8, 0.0};
  scene.damping = 0.2;
  scene.fixes.push_back(fix_nodes({{0, 0}, {0, 5}}));
  return scene;
}

TEST(StepLoop, FramesCheckpointsAndProgressFollowTheSchedule) {
  Scene scene = hanging_sheet();
  scene.steps = 23;
  scene.output_every = 5;
  Simulation sim(scene, MPI_COMM_SELF);
  Recorder recorder(sim);
  const StepLoopResult result =
      run_step_loop(sim, scene, {.checkpoint_every = 10, .until_rest = {}}, recorder);

  EXPECT_FALSE(result.failure);
  EXPECT_FALSE(result.rest);
  EXPECT_EQ(result.first_step, 0);
  EXPECT_EQ(sim.step_index(), 23);
  EXPECT_GE(result.wall_seconds, 0.0);
  EXPECT_EQ(recorder.steps_of("frame"), (std::vector<long>{5, 10, 15, 20, 23}));
  EXPECT_EQ(recorder.steps_of("checkpoint"), (std::vector<long>{10, 20, 23}));
  EXPECT_EQ(recorder.steps_of("progress"), one_to(23));
  // Within a step: the frame, then the checkpoint, then progress.
  const auto frame_20 =
      std::find(recorder.events.begin(), recorder.events.end(), Event{"frame", 20});
  ASSERT_GE(recorder.events.end() - frame_20, 3);
  EXPECT_EQ(std::vector<Event>(frame_20, frame_20 + 3),
            (std::vector<Event>{{"frame", 20}, {"checkpoint", 20}, {"progress", 20}}));
}

TEST(StepLoop, NoCheckpointsUnlessAsked) {
  Scene scene = hanging_sheet();
  scene.steps = 12;
  scene.output_every = 4;
  Simulation sim(scene, MPI_COMM_SELF);
  Recorder recorder(sim);
  run_step_loop(sim, scene, {}, recorder);
  EXPECT_EQ(recorder.steps_of("frame"), (std::vector<long>{4, 8, 12}));
  EXPECT_TRUE(recorder.steps_of("checkpoint").empty());
}

// A restarted run starts the loop part-way: nothing is due for its first step, which its
// checkpoint already holds, and the schedule still counts from step 0.
TEST(StepLoop, StartsFromTheSimulationsStep) {
  Scene scene = hanging_sheet();
  scene.steps = 23;
  scene.output_every = 5;
  Simulation sim(scene, MPI_COMM_SELF);
  ASSERT_TRUE(advance(sim, 10));
  Recorder recorder(sim);
  const StepLoopResult result =
      run_step_loop(sim, scene, {.checkpoint_every = 4, .until_rest = {}}, recorder);
  EXPECT_EQ(result.first_step, 10);
  EXPECT_EQ(sim.step_index(), 23);
  EXPECT_EQ(recorder.steps_of("frame"), (std::vector<long>{15, 20, 23}));
  EXPECT_EQ(recorder.steps_of("checkpoint"), (std::vector<long>{12, 16, 20, 23}));
  EXPECT_EQ(recorder.steps_of("progress").front(), 11);
}

// The step and peak at which a run of `scene` first has kinetic energy below fraction x its peak
// so far, found by stepping a simulation of its own.
struct Rest {
  long step = 0;
  double peak = 0.0;
};
std::optional<Rest> first_rest(const Scene& scene, double fraction) {
  Simulation sim(scene, MPI_COMM_SELF);
  double peak = 0.0;
  while (sim.step_index() < scene.steps) {
    if (sim.step()) return std::nullopt;
    const double energy = sim.diagnostics().kinetic_energy;
    if (energy > peak) peak = energy;
    if (energy < fraction * peak) return Rest{sim.step_index(), peak};
  }
  return std::nullopt;
}

TEST(StepLoop, StopsAtTheFirstStepBelowTheFractionOfThePeak) {
  constexpr double kFraction = 0.05;
  Scene scene = hanging_sheet();
  scene.steps = 20000;
  scene.output_every = 1000;
  const std::optional<Rest> expected = first_rest(scene, kFraction);
  ASSERT_TRUE(expected);
  // The sheet falls from rest: the stop must not come from the first steps' tiny energy.
  ASSERT_GT(expected->step, 10);
  ASSERT_NE(expected->step % scene.output_every, 0)
      << "the frame at rest would be scheduled anyway";

  Simulation sim(scene, MPI_COMM_SELF);
  Recorder recorder(sim);
  const StepLoopResult result =
      run_step_loop(sim, scene, {.checkpoint_every = 0, .until_rest = kFraction}, recorder);

  EXPECT_FALSE(result.failure);
  ASSERT_TRUE(result.rest);
  EXPECT_EQ(result.rest->fraction, kFraction);
  ASSERT_TRUE(result.rest->step);
  EXPECT_EQ(*result.rest->step, expected->step);
  EXPECT_EQ(result.rest->peak_kinetic_energy, expected->peak);
  EXPECT_EQ(sim.step_index(), expected->step);
  std::vector<long> frames;
  for (long s = scene.output_every; s < expected->step; s += scene.output_every)
    frames.push_back(s);
  frames.push_back(expected->step);
  EXPECT_EQ(recorder.steps_of("frame"), frames);
  EXPECT_EQ(recorder.steps_of("progress"), one_to(expected->step));
}

TEST(StepLoop, RunsToTheEndWhenNeverAtRest) {
  Scene scene = hanging_sheet();
  scene.steps = 50;
  scene.output_every = 20;
  Simulation sim(scene, MPI_COMM_SELF);
  Recorder recorder(sim);
  // 50 steps into its fall the sheet still moves at well over 1e-6 of its fastest.
  ASSERT_FALSE(first_rest(scene, 1e-6));
  const StepLoopResult result = run_step_loop(sim, scene, {.until_rest = 1e-6}, recorder);
  ASSERT_TRUE(result.rest);
  EXPECT_FALSE(result.rest->step);
  EXPECT_GT(result.rest->peak_kinetic_energy, 0.0);
  EXPECT_EQ(sim.step_index(), 50);
  EXPECT_EQ(recorder.steps_of("frame"), (std::vector<long>{20, 40, 50}));
}

// Far above the stability limit: the monitor stops the run after a few steps.
TEST(StepLoop, FailureStopsAtTheLastGoodStep) {
  Scene scene = hanging_sheet();
  scene.dt = 0.05;
  scene.steps = 200;
  scene.output_every = 1;
  long failing = 0;
  {
    Simulation reference(scene, MPI_COMM_SELF);
    while (reference.step_index() < scene.steps && failing == 0)
      if (const auto failure = reference.step()) failing = failure->step;
  }
  ASSERT_GT(failing, 2) << "the scene should run a few good steps first";

  Simulation sim(scene, MPI_COMM_SELF);
  Recorder recorder(sim);
  const StepLoopResult result =
      run_step_loop(sim, scene, {.checkpoint_every = 1, .until_rest = 1e-9}, recorder);

  ASSERT_TRUE(result.failure);
  EXPECT_EQ(result.failure->step, failing);
  EXPECT_EQ(sim.step_index(), failing - 1);
  ASSERT_TRUE(result.rest);
  EXPECT_FALSE(result.rest->step);
  // Every good step had its frame, checkpoint and progress; the failed one has none.
  EXPECT_EQ(recorder.steps_of("frame"), one_to(failing - 1));
  EXPECT_EQ(recorder.steps_of("checkpoint"), one_to(failing - 1));
  EXPECT_EQ(recorder.steps_of("progress"), one_to(failing - 1));
}

}  // namespace
}  // namespace cosserat
