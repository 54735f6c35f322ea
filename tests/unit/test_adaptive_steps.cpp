// Adaptive steps (time/adaptive_step.hpp, docs/stability.md): how a scene asks for them, frames
// at fixed simulated times, the roll-back when the monitor trips, and the failure below
// time.dt.min. Decomposition invariance and restarts are in tests/mpi.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "cosserat/time/simulation.hpp"
#include "cosserat/time/step_loop.hpp"
#include "support/sheets.hpp"

namespace cosserat {
namespace {

// The bending sheet held at one corner: with safety 1 its first steps are too long and the
// monitor trips.
std::string sheet(const std::string& time) {
  return testing::bending_sheet_text() + "[[fix]]\nnodes = [[0, 0]]\n[time]\n" + time + "\n";
}

Scene adaptive_sheet(const std::string& time) {
  return parse_scene(sheet(time), "sheet.toml");
}

class Recorder : public StepObserver {
 public:
  explicit Recorder(const Simulation& simulation) : simulation_(simulation) {}
  void frame() override { frame_times.push_back(simulation_.time()); }
  void checkpoint(const LoopCarry&) override {}
  void progress(long) override {}
  std::vector<double> frame_times;

 private:
  const Simulation& simulation_;
};

// Each [time] section is refused, the message naming its key.
void expect_refused(const std::vector<std::pair<std::string, std::string>>& cases) {
  for (const auto& [time, key] : cases) {
    try {
      adaptive_sheet(time);
      ADD_FAILURE() << "accepted: " << time;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << time << ": " << e.what();
    }
  }
}

TEST(AdaptiveScene, NoStepMeansAdaptiveWithDefaults) {
  const Scene scene = adaptive_sheet("duration = 0.5");
  ASSERT_TRUE(scene.adaptive);
  EXPECT_EQ(scene.duration, 0.5);
  EXPECT_EQ(scene.output_dt, 0.005);
  EXPECT_EQ(scene.adaptive->max, 0.005);
  EXPECT_EQ(scene.adaptive->safety, 0.5);
  EXPECT_GT(scene.adaptive->min, 0.0);
  EXPECT_LT(scene.adaptive->min, 1e-5 * scene.adaptive->max);
}

TEST(AdaptiveScene, TableGivesTheBounds) {
  const Scene scene = adaptive_sheet(
      "duration = 1.0\noutput_dt = 0.1\ndt = { adaptive = true, min = 1e-7, max = 0.01, "
      "safety = 0.8 }");
  ASSERT_TRUE(scene.adaptive);
  EXPECT_EQ(scene.adaptive->min, 1e-7);
  EXPECT_EQ(scene.adaptive->max, 0.01);
  EXPECT_EQ(scene.adaptive->safety, 0.8);
  EXPECT_EQ(scene.output_dt, 0.1);
}

// A scene written for adaptive steps runs with `--set time.dt=...` too.
TEST(AdaptiveScene, FixedStepTakesADurationAndFrameInterval) {
  const Scene scene = adaptive_sheet("duration = 1.0\noutput_dt = 0.1\ndt = 0.01");
  EXPECT_FALSE(scene.adaptive);
  EXPECT_EQ(scene.steps, 100);
  EXPECT_EQ(scene.output_every, 10);
}

TEST(AdaptiveScene, StepCountsAndUnfitIntegratorsAreRefusedWithTheKey) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"duration = 1.0\nsteps = 100", "time.steps"},
      {"duration = 1.0\noutput_every = 10", "time.output_every"},
      {"steps = 100", "time.steps"},
      {"output_dt = 0.1", "time.duration"},
      {"duration = 1.0\nintegrator = \"leapfrog\"", "time.dt"},
      {"duration = 1.0\nintegrator = \"verlet-lagged\"\ndt = { adaptive = true }", "time.dt"},
      {"duration = 1.0\ndt = { adaptive = true, safety = 1.5 }", "time.dt.safety"},
      {"duration = 1.0\ndt = { adaptive = true, min = 0.1, max = 0.01 }", "time.dt.min"},
      {"duration = 1.0\ndt = { adaptive = false }", "time.dt.adaptive"},
      {"duration = 1.0\ndt = { max = 0.01 }", "time.dt.adaptive"},
      {"duration = 1.0\ndt = { adaptive = true, step = 0.01 }", "time.dt.step"},
      {"duration = 1.0\ndt = 0.01\nsteps = 100", "time.duration"},
  };
  expect_refused(cases);
}

// Random steps (docs/stability.md, "Random steps"): the table's bounds and seed.
TEST(RandomScene, TableGivesTheSequence) {
  const Scene scene = adaptive_sheet(
      "duration = 0.5\noutput_dt = 0.1\ndt = { sequence = \"random\", min = 1e-4, max = 3e-4, "
      "seed = 7 }");
  ASSERT_TRUE(scene.adaptive);
  EXPECT_TRUE(scene.adaptive->random);
  EXPECT_EQ(scene.adaptive->min, 1e-4);
  EXPECT_EQ(scene.adaptive->max, 3e-4);
  EXPECT_EQ(scene.adaptive->seed, 7u);
  EXPECT_EQ(scene.dt, 3e-4);
  EXPECT_EQ(scene.output_dt, 0.1);
  EXPECT_GE(static_cast<double>(scene.steps), 0.5 / 1e-4);
}

// A random sequence never steps back, so its step indices are the seed's and a window may
// count them; adaptive steps' indices depend on their rollbacks, so there it may not.
TEST(RandomScene, WindowsMayCountSteps) {
  const std::string load = "\n[[load]]\nnodes = [[1, 1]]\nforce = [0.0, 0.0, 1.0]\nend = 50\n";
  const Scene scene = parse_scene(
      sheet("duration = 0.5\ndt = { sequence = \"random\", min = 1e-4, max = 3e-4 }") + load,
      "sheet.toml");
  ASSERT_EQ(scene.loads.size(), 1u);
  EXPECT_EQ(scene.loads[0].window.end, 50);
  EXPECT_THROW(parse_scene(sheet("duration = 0.5") + load, "sheet.toml"), SceneError);
}

TEST(RandomScene, BadTablesAreRefusedWithTheKey) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"duration = 1.0\ndt = { sequence = \"gaussian\", min = 1e-4, max = 2e-4 }",
       "time.dt.sequence"},
      {"duration = 1.0\ndt = { sequence = \"random\", max = 2e-4 }", "time.dt.min"},
      {"duration = 1.0\ndt = { sequence = \"random\", min = 1e-4 }", "time.dt.max"},
      {"duration = 1.0\ndt = { sequence = \"random\", min = 3e-4, max = 2e-4 }", "time.dt.min"},
      {"duration = 1.0\ndt = { sequence = \"random\", min = 1e-4, max = 2e-4, safety = 0.5 }",
       "time.dt.safety"},
      {"duration = 1.0\ndt = { sequence = \"random\", min = 1e-4, max = 2e-4, seed = -1 }",
       "time.dt.seed"},
      {"duration = 1.0\nintegrator = \"leapfrog\"\ndt = { sequence = \"random\", min = 1e-4, "
       "max = 2e-4 }",
       "time.dt"},
      {"steps = 10\ndt = { sequence = \"random\", min = 1e-4, max = 2e-4 }", "time.steps"},
  };
  expect_refused(cases);
}

// The steps a run takes, from the stepper after each.
class StepRecorder : public Recorder {
 public:
  explicit StepRecorder(Simulation& simulation) : Recorder(simulation), simulation_(simulation) {}
  void progress(long) override { steps.push_back(simulation_.stepper().last_dt()); }
  std::vector<double> steps;

 private:
  Simulation& simulation_;
};

// A seed's sequence is the same in every run and another seed's is not; the steps spread over
// [min, max] as a uniform draw does, end on every frame time, and no step is shorter than min,
// the ones cut to a frame included.
TEST(RandomSteps, AreTheSeedsAndLandOnTheirFrames) {
  // Between a tenth and four tenths of the rest sheet's CFL step: stable.
  const double cfl =
      rest_step_estimate(adaptive_sheet("duration = 0.05").model_spec()).dt;
  const double min = 0.1 * cfl, max = 0.4 * cfl;
  const auto run = [&](std::uint64_t seed) {
    Scene scene = adaptive_sheet(fmt::format(
        "duration = 0.05\noutput_dt = 0.007\ndt = {{ sequence = \"random\", min = {}, "
        "max = {}, seed = {} }}",
        min, max, seed));
    auto simulation = std::make_unique<Simulation>(scene, MPI_COMM_SELF);
    StepRecorder recorder(*simulation);
    const StepLoopResult result = run_step_loop(*simulation, scene, {}, recorder);
    EXPECT_FALSE(result.failure);
    EXPECT_EQ(simulation->time(), 0.05);
    return std::make_pair(std::move(simulation), recorder);
  };
  const auto [first, a] = run(3);
  const auto [again, b] = run(3);
  const auto [other, c] = run(4);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(first->positions()(5, 5).y, again->positions()(5, 5).y);
  EXPECT_NE(a.steps, c.steps);
  std::vector<double> expected;
  for (int j = 1; j * 0.007 < 0.05; ++j) expected.push_back(j * 0.007);
  expected.push_back(0.05);
  EXPECT_EQ(a.frame_times, expected);
  double sum = 0.0, squares = 0.0;
  for (const double dt : a.steps) {
    EXPECT_GE(dt, min * (1.0 - 1e-12));
    EXPECT_LE(dt, max * (1.0 + 1e-12));
    sum += dt;
    squares += dt * dt;
  }
  const double count = static_cast<double>(a.steps.size());
  const double spread = std::sqrt(squares / count - (sum / count) * (sum / count));
  // A uniform draw on [min, max] spreads by (max − min)/√12.
  EXPECT_GT(spread, 0.7 * (max - min) / std::sqrt(12.0)) << spread;
  EXPECT_LT(spread, 1.3 * (max - min) / std::sqrt(12.0)) << spread;
}

TEST(AdaptiveScene, WindowsInStepsAreRefusedAndWindowsInSecondsRead) {
  const std::string text = sheet("duration = 1.0");
  EXPECT_THROW(parse_scene(text + "[[load]]\nnodes = [[3, 3]]\nforce = [0, 1, 0]\nend = 10\n",
                           "sheet.toml"),
               SceneError);
  const Scene scene = parse_scene(
      text + "[[load]]\nnodes = [[3, 3]]\nforce = [0, 1, 0]\nstart_time = 0.1\nend_time = 0.2\n",
      "sheet.toml");
  ASSERT_EQ(scene.loads.size(), 1u);
  EXPECT_FALSE(scene.loads[0].window.contains(5, 0.05));
  EXPECT_TRUE(scene.loads[0].window.contains(5, 0.1));
  EXPECT_TRUE(scene.loads[0].window.contains(500, 0.2));
  EXPECT_FALSE(scene.loads[0].window.contains(5, 0.2000001));
  EXPECT_THROW(parse_scene(text + "[[fix]]\nnodes = [[3, 3]]\nstart_time = 0.3\nend_time = 0.2\n",
                           "sheet.toml"),
               SceneError);
}

// Frames land exactly on the multiples of output_dt, whatever the steps, the last on the
// duration; the run ends there.
TEST(AdaptiveSteps, FramesLandOnTheirTimes) {
  const Scene scene = adaptive_sheet("duration = 0.05\noutput_dt = 0.007");
  Simulation simulation(scene, MPI_COMM_SELF);
  Recorder recorder(simulation);
  const StepLoopResult result = run_step_loop(simulation, scene, {}, recorder);
  ASSERT_FALSE(result.failure);
  std::vector<double> expected;
  for (int j = 1; j * 0.007 < 0.05; ++j) expected.push_back(j * 0.007);
  expected.push_back(0.05);
  EXPECT_EQ(recorder.frame_times, expected);
  EXPECT_EQ(simulation.time(), 0.05);
  ASSERT_TRUE(result.adaptive);
  EXPECT_EQ(result.adaptive->rollbacks, 0);
  // Safety 0.5 of an estimate that is at most 1/0.61 of the limit: stable without roll-backs,
  // and more steps than frames.
  EXPECT_GT(simulation.step_index(), static_cast<long>(expected.size()));
}

// The planner on its own (docs/stability.md, "Adaptive steps"), on an estimate that wobbles by
// 2 % from one step to the next as a drape's stretch does: the step stays the same, never
// longer than the estimate allows. A step that followed the wobble pumped the drape's fastest
// modes (sphere_drape: energy rose in 131 of 334 frames). When the estimate falls the next
// step follows at once; when it rises the step grows by at most 1.25 a step.
TEST(AdaptiveSteps, AWobblingEstimateLeavesTheStepAlone) {
  const Scene scene = adaptive_sheet("duration = 1.0\noutput_dt = 0.05");
  const AdaptiveSteps steps(scene);
  const double safety = scene.adaptive->safety;
  std::mt19937_64 pattern(3);
  std::uniform_real_distribution<double> wobble(-0.02, 0.02);
  double time = 0.0, last = 4e-4, level = 1e-3;
  int frames = 0;
  std::vector<double> taken;
  const auto step = [&] {
    const double estimate = level * (1.0 + wobble(pattern));
    const AdaptiveSteps::Next next = steps.next(time, last, estimate, 0);
    EXPECT_LE(next.dt, safety * estimate * (1.0 + 1e-12)) << "t = " << time;
    EXPECT_LE(next.dt, 1.25 * last * (1.0 + 1e-12)) << "t = " << time;
    frames += next.frame;
    time = next.end_time;
    last = next.dt;
    taken.push_back(next.dt);
  };
  while (time < 0.3) step();
  // After the first frame, every step is the first one's to round-off.
  const std::size_t after_first = static_cast<std::size_t>(std::lround(0.05 / taken.back()));
  for (std::size_t i = after_first; i < taken.size(); ++i)
    EXPECT_NEAR(taken[i], taken.back(), 1e-12 * taken.back()) << "step " << i;
  EXPECT_GT(taken.back(), 0.8 * safety * level);

  const double kept = taken.back();
  level = 0.7e-3;
  step();
  EXPECT_LT(taken.back(), 0.8 * kept);
  level = 2e-3;
  while (time < 0.6) step();
  EXPECT_GT(taken.back(), 0.8 * safety * level);
  while (time < scene.duration) step();
  EXPECT_EQ(time, scene.duration);
  EXPECT_EQ(frames, 20);
}

// A restart finds the last frame its checkpoint follows from the time alone, as the loop put it.
TEST(AdaptiveSteps, TheFrameBeforeATimeIsTheOneTheLoopWrote) {
  const Scene scene = adaptive_sheet("duration = 0.05\noutput_dt = 0.007");
  const AdaptiveSteps steps(scene);
  EXPECT_EQ(steps.frame_at_or_before(0.0), 0.0);
  EXPECT_EQ(steps.frame_at_or_before(0.0069), 0.0);
  EXPECT_EQ(steps.frame_at_or_before(3 * 0.007), 3 * 0.007);
  EXPECT_EQ(steps.frame_at_or_before(0.0489), 6 * 0.007);
}

// Safety 1 takes steps past the stable limit: the monitor trips, the run goes back to a state
// in memory and on with a smaller step, and ends where a safe run ends, to the integrator's
// error (measured 5.7e-7 m against safety 0.25, on a sheet 2 m wide; an instability that had
// stayed in the state would leave centimetres).
TEST(AdaptiveSteps, RollsBackAndFinishesWhereASafeRunEnds) {
  const Scene bold = adaptive_sheet(
      "duration = 0.2\noutput_dt = 0.1\ndt = { adaptive = true, safety = 1.0 }");
  Simulation fast(bold, MPI_COMM_SELF);
  Recorder recorder(fast);
  const StepLoopResult result = run_step_loop(fast, bold, {}, recorder);
  ASSERT_FALSE(result.failure) << result.failure->diagnosis;
  ASSERT_TRUE(result.adaptive);
  EXPECT_GE(result.adaptive->rollbacks, 1);
  EXPECT_EQ(fast.time(), 0.2);
  // Frames only ever move forward in time: nothing written is rolled back.
  for (std::size_t i = 1; i < recorder.frame_times.size(); ++i)
    EXPECT_LT(recorder.frame_times[i - 1], recorder.frame_times[i]);

  const Scene safe = adaptive_sheet("duration = 0.2\ndt = { adaptive = true, safety = 0.25 }");
  Simulation careful(safe, MPI_COMM_SELF);
  Recorder careful_recorder(careful);
  ASSERT_FALSE(run_step_loop(careful, safe, {}, careful_recorder).failure);
  double largest = 0.0;
  const Block& b = fast.block();
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k)
      largest = std::max(largest, norm(fast.positions()(k, l) - careful.positions()(k, l)));
  EXPECT_LT(largest, 1e-5) << result.adaptive->rollbacks << " roll-backs";
  EXPECT_GT(careful.step_index(), fast.step_index());
}

// A moving fix under adaptive steps, through roll-backs: its node ends exactly where its
// velocity takes it in the run's time, whatever steps were taken or undone.
TEST(AdaptiveSteps, AMovingFixFollowsItsVelocityThroughRollBacks) {
  Scene scene = adaptive_sheet(
      "duration = 0.2\noutput_dt = 0.1\ndt = { adaptive = true, safety = 1.0 }");
  Fix lifted = testing::fix_nodes({{23, 23}});
  lifted.velocity = {0.1, 0.5, -0.2};
  scene.fixes.push_back(lifted);
  Simulation simulation(scene, MPI_COMM_SELF);
  const Vec3 start = simulation.positions()(23, 23);
  Recorder recorder(simulation);
  const StepLoopResult result = run_step_loop(simulation, scene, {}, recorder);
  ASSERT_FALSE(result.failure);
  ASSERT_TRUE(result.adaptive);
  EXPECT_GE(result.adaptive->rollbacks, 1);
  EXPECT_EQ(simulation.time(), 0.2);
  const Vec3 r = simulation.positions()(23, 23);
  EXPECT_EQ(r.x, start.x + lifted.velocity.x * 0.2);
  EXPECT_EQ(r.y, start.y + lifted.velocity.y * 0.2);
  EXPECT_EQ(r.z, start.z + lifted.velocity.z * 0.2);
}

// A run that needs a step below time.dt.min is unstable (exit 3), and says so.
TEST(AdaptiveSteps, BelowTheSmallestStepTheRunIsUnstable) {
  const Scene scene = adaptive_sheet(
      "duration = 0.2\ndt = { adaptive = true, safety = 1.0, min = 0.003, max = 0.004 }");
  Simulation simulation(scene, MPI_COMM_SELF);
  Recorder recorder(simulation);
  const StepLoopResult result = run_step_loop(simulation, scene, {}, recorder);
  ASSERT_TRUE(result.failure);
  EXPECT_NE(result.failure->diagnosis.find("time.dt.min"), std::string::npos)
      << result.failure->diagnosis;
  EXPECT_LT(simulation.time(), 0.2);
}

// A sphere at 200 m/s struck through a hanging sheet (21 x 21 nodes on 1 m, h = 5 cm): the
// estimate knows how far the sphere is (docs/stability.md, "Adaptive steps"), so the steps
// shorten as it comes, to no more than a quarter spacing of its travel into the cloth's box, and
// lengthen again where it is far. Before the solids were in the estimate this run rolled back
// once as the sphere struck (236 steps, against 129 now): the monitor, not the estimate, found
// the step too long.
TEST(AdaptiveSteps, AFastSolidShortensTheStepsBeforeItStrikes) {
  const std::string text = R"(
[grid]
nodes = [21, 21]
size = [1.0, 1.0]
origin = [-0.5, 1.0, 0.0]
u = [1.0, 0.0, 0.0]
v = [0.0, -1.0, 0.0]
[material]
mass = 0.2
zeta = 100.0
xi = 1e-3
phi = 1e-3
[environment]
gravity = [0.0, -9.8, 0.0]
damping = 0.3
[time]
duration = 0.005
output_dt = 0.001
[[fix]]
region = { rect = [0, 0, 20, 0] }
[[solid]]
name = "ball"
shape = "sphere"
center = [0.0, 0.5, -0.5]
radius = 0.15
motion = "kinematic"
velocity = [0.0, 0.0, 200.0]
end_time = 0.0075
thickness = 0.005
)";
  const Scene scene = parse_scene(text, "strike.toml");
  Simulation simulation(scene, MPI_COMM_SELF);
  // The sheet lies in z = 0; the sphere's surface, grown by its offset, 0.5 − 0.155 m from it.
  const double quarter = 0.25 * 0.05, speed = 200.0;
  EXPECT_NEAR(simulation.state_measures().solid_step, (0.345 + quarter) / speed, 1e-15);
  Recorder recorder(simulation);
  const StepLoopResult result = run_step_loop(simulation, scene, {}, recorder);
  ASSERT_FALSE(result.failure) << result.failure->diagnosis;
  ASSERT_TRUE(result.adaptive);
  EXPECT_EQ(result.adaptive->rollbacks, 0);
  EXPECT_LE(result.adaptive->smallest_dt, scene.adaptive->safety * quarter / speed);
  EXPECT_GT(result.adaptive->largest_dt, 10.0 * scene.adaptive->safety * quarter / speed);
  // A solid that does not move leaves the estimate alone.
  Scene fixed = scene;
  fixed.solids[0].motion = SolidMotion::fixed;
  EXPECT_EQ(Simulation(fixed, MPI_COMM_SELF).state_measures().solid_step,
            std::numeric_limits<double>::infinity());
}

// The errors of `integrator` with random steps at Δt, Δt/2 and Δt/4 (the same pattern of
// lengths between 0.5 and 1.5 of each), against its own fixed step 64 times finer.
std::vector<double> random_step_errors(Integrator integrator) {
  Scene scene = testing::flat_sheet(6, 5);
  scene.integrator = integrator;
  scene.gravity = {0.0, -9.8, 0.0};
  scene.fixes.push_back(testing::fix_nodes({{0, 0}}));
  const double duration = 0.5, mean = 4e-3;
  auto run = [&](double dt, bool random) {
    Scene s = scene;
    s.dt = dt;
    auto sim = std::make_unique<Simulation>(s, MPI_COMM_SELF);
    std::mt19937_64 pattern(7);
    std::uniform_real_distribution<double> share(0.5, 1.5);
    double time = 0.0;
    while (time < duration) {
      const double step = std::min(random ? dt * share(pattern) : dt, duration - time);
      const double end = step < duration - time ? time + step : duration;
      EXPECT_FALSE(sim->stepper().step(end - time, end));
      time = end;
    }
    return sim;
  };
  const auto reference = run(mean / 64, false);
  std::vector<double> errors;
  for (const double dt : {mean, mean / 2, mean / 4}) {
    const auto sim = run(dt, true);
    double largest = 0.0;
    for (int l = 0; l < scene.n; ++l)
      for (int k = 0; k < scene.m; ++k)
        largest =
            std::max(largest, norm(sim->positions()(k, l) - reference->positions()(k, l)));
    errors.push_back(largest);
  }
  return errors;
}

// Verlet with a varying step takes r⁺ = r + (r − r⁻) Δt/Δt₋ + a Δt (Δt + Δt₋)/2, the form that
// is consistent on a non-uniform time grid (the published form, docs/equations.md §4, has a Δt²,
// first order when the step changes). Random steps between 0.5 and 1.5 of a mean Δt, the same
// pattern at Δt, Δt/2 and Δt/4, against a fixed step 64 times finer: the error falls about four
// times per halving (measured 1.86e-5, 5.86e-6, 1.25e-6 m: ratios 3.2 and 4.7; first order
// would give 2).
TEST(AdaptiveSteps, VerletOnRandomStepsIsSecondOrder) {
  const std::vector<double> errors = random_step_errors(Integrator::verlet);
  EXPECT_GT(errors[0] / errors[1], 2.8) << errors[0] << " " << errors[1];
  EXPECT_GT(errors[1] / errors[2], 2.8) << errors[1] << " " << errors[2];
}

// tc-verlet (the consistent form above) is exact for a constant acceleration on any steps: a
// sheet falling from rest on random steps between 0.5 and 1.5 of 4 ms is at −½ g t² to
// round-off after 0.5 s. The published time-corrected form, r⁺ = r + (r − r⁻) Δt/Δt₋ + Δt² a
// (docs/models.md, "One particle"), applied here to the same steps from the same start, is not:
// each change of step costs it a Δt (Δt − Δt₋)/2, which adds up (measured: 1.6e-14 m against
// 3.5e-4 m).
TEST(AdaptiveSteps, TimeCorrectedVerletFallsExactlyOnRandomSteps) {
  Scene scene = testing::flat_sheet(4, 3);
  scene.integrator = Integrator::tc_verlet;
  const double g = 9.8, duration = 0.5, mean = 4e-3;
  scene.gravity = {0.0, -g, 0.0};
  scene.dt = mean;
  Simulation sim(scene, MPI_COMM_SELF);
  std::mt19937_64 pattern(7);
  std::uniform_real_distribution<double> share(0.5, 1.5);
  // The published form from the same start r⁻ = r0 + ½ Δt₀² a (at rest), on the same steps.
  double y = 0.0, y_previous = -0.5 * g * mean * mean, dt_previous = mean;
  double time = 0.0;
  while (time < duration) {
    const double step = std::min(mean * share(pattern), duration - time);
    const double end = step < duration - time ? time + step : duration;
    const double dt = end - time;
    ASSERT_FALSE(sim.stepper().step(dt, end));
    const double next = y + (y - y_previous) * (dt / dt_previous) - g * dt * dt;
    y_previous = y;
    y = next;
    dt_previous = dt;
    time = end;
  }
  const double exact = -0.5 * g * duration * duration;
  const double consistent = std::abs(sim.positions()(2, 1).y - exact);
  const double published = std::abs(y - exact);
  std::printf("[random steps] free fall after %.1f s: tc-verlet %.2g m, published form %.2g m\n",
              duration, consistent, published);
  EXPECT_LT(consistent, 1e-12);
  EXPECT_GT(published, 1e-5);
}

// Positional Verlet as published, r⁺ = 2r − r⁻ + Δt² a with the lagged velocity (r − r⁻)/Δt
// (`verlet-lagged`, docs/equations.md §4), takes the last move for a step's worth of velocity
// whatever its length, an error of the order of the velocity itself in every step that changes
// length: on the same random steps its error does not converge (measured 0.19, 0.060 and 0.12 m
// at Δt, Δt/2 and Δt/4, where first order would have fallen to a quarter of the first, and the
// consistent form's is 1e-6 m). The scene refuses it variable steps (docs/stability.md, "Random
// steps").
TEST(AdaptiveSteps, PublishedVerletOnRandomStepsDoesNotConverge) {
  const std::vector<double> errors = random_step_errors(Integrator::verlet_lagged);
  const std::vector<double> consistent = random_step_errors(Integrator::verlet);
  std::printf("[random steps] verlet-lagged errors %.3g %.3g %.3g m\n", errors[0], errors[1],
              errors[2]);
  EXPECT_GT(errors[2], 0.25 * errors[0]) << errors[0] << " " << errors[2];
  EXPECT_GT(errors[2], 1e3 * consistent[2]) << errors[2] << " " << consistent[2];
}

}  // namespace
}  // namespace cosserat
