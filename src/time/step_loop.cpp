#include "cosserat/time/step_loop.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "cosserat/grid/threads.hpp"

namespace cosserat {

bool RestSummary::at_rest(long at_step, double kinetic_energy) {
  peak_kinetic_energy = std::max(peak_kinetic_energy, kinetic_energy);
  const bool rest = kinetic_energy < fraction * peak_kinetic_energy;
  if (rest) step = at_step;
  return rest;
}

namespace {

// A state held in memory every this many steps: a roll-back goes back between one and two of
// these, since an instability grows over many steps before the monitor sees it.
constexpr long kSnapshotEvery = 100;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void fixed_steps(Simulation& simulation, const Scene& scene, const StepLoopOptions& options,
                 StepObserver& observer, StepLoopResult& result, ThreadTuner& tuner) {
  while (simulation.step_index() < scene.steps) {
    const auto started = Clock::now();
    result.failure = simulation.step();
    tuner.record(seconds_since(started));
    if (result.failure) break;
    const long step = simulation.step_index();
    const bool at_rest =
        result.rest && result.rest->at_rest(step, simulation.diagnostics().kinetic_energy);
    if (step % scene.output_every == 0 || step == scene.steps || at_rest) observer.frame();
    if (options.checkpoint_every > 0 &&
        (step % options.checkpoint_every == 0 || step == scene.steps))
      observer.checkpoint(LoopCarry{result.rest, std::nullopt});
    observer.progress(step);
    if (at_rest) break;
  }
}

void adaptive_steps(Simulation& simulation, const Scene& scene, const StepLoopOptions& options,
                    StepObserver& observer, StepLoopResult& result, ThreadTuner& tuner) {
  Stepper& stepper = simulation.stepper();
  AdaptiveSteps steps(scene, options.adaptive_scale);
  AdaptiveSummary& summary = result.adaptive.emplace();
  // The roll-back target is the older of two recent states, or the newer when the older would
  // be before the last frame or checkpoint: what was written stays the run's history, and a
  // restart holds the same states as the run it continues.
  std::optional<Stepper::Snapshot> older;
  Stepper::Snapshot newer = stepper.snapshot();
  while (simulation.time() < scene.duration && simulation.step_index() < scene.steps) {
    // The estimate is a global reduction over the state: only steps that follow it pay for it.
    const double estimate =
        steps.follows_estimate() ? stability_estimate(scene, simulation.state_measures()) : 0.0;
    const AdaptiveSteps::Next next =
        steps.next(simulation.time(), stepper.last_dt(), estimate, simulation.step_index());
    const auto started = Clock::now();
    auto failure = stepper.step(next.dt, next.end_time);
    tuner.record(seconds_since(started));
    if (failure) {
      if (failure->solver_failure || !steps.shrink(next.dt)) {
        if (!failure->solver_failure)
          failure->diagnosis += fmt::format(
              "; adaptive steps went back {} time{} and need a step below time.dt.min = {:.3g} s "
              "here (this one was {:.3g} s)",
              summary.rollbacks, summary.rollbacks == 1 ? "" : "s", scene.adaptive->min,
              next.dt);
        result.failure = std::move(failure);
        break;
      }
      ++summary.rollbacks;
      if (older) {
        newer = std::move(*older);
        older.reset();
      }
      stepper.restore(newer);
      continue;
    }
    summary.smallest_dt = std::min(summary.smallest_dt, next.dt);
    summary.largest_dt = std::max(summary.largest_dt, next.dt);
    const long step = simulation.step_index();
    const bool at_rest =
        result.rest && result.rest->at_rest(step, simulation.diagnostics().kinetic_energy);
    const bool end = simulation.time() >= scene.duration;
    const bool frame = next.frame || at_rest;
    if (frame) observer.frame();
    const bool checkpoint =
        options.checkpoint_every > 0 && (step % options.checkpoint_every == 0 || end);
    if (checkpoint) observer.checkpoint(LoopCarry{result.rest, steps.scale()});
    if (frame || checkpoint) {
      older.reset();
      newer = stepper.snapshot();
    } else if (step % kSnapshotEvery == 0) {
      older = std::move(newer);
      newer = stepper.snapshot();
    }
    observer.progress(step);
    if (at_rest) break;
  }
}

}  // namespace

StepLoopResult run_step_loop(Simulation& simulation, const Scene& scene,
                             const StepLoopOptions& options, StepObserver& observer) {
  StepLoopResult result;
  ThreadTuner tuner(options.tune_threads);
  result.first_step = simulation.step_index();
  if (options.until_rest)
    result.rest = RestSummary{*options.until_rest, options.rest_peak, std::nullopt};
  const double halo_before = simulation.halo_seconds();
  const auto start = Clock::now();
  if (scene.adaptive)
    adaptive_steps(simulation, scene, options, observer, result, tuner);
  else
    fixed_steps(simulation, scene, options, observer, result, tuner);
  result.wall_seconds = seconds_since(start);
  result.thread_steps = tuner.steps_with();
  result.halo_seconds = simulation.halo_seconds() - halo_before;
  return result;
}

}  // namespace cosserat
