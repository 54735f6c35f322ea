#pragma once
// The step loop of a run (docs/design.md, principle 4: scene -> Simulation -> step loop ->
// writers): it decides when a frame or a checkpoint is due and when the sheet has come to rest, and
// leaves what is done then to an observer, so that the time module needs no files and tests can
// follow the schedule without writing any.

#include <optional>
#include <vector>

#include "cosserat/scene/scene.hpp"
#include "cosserat/time/simulation.hpp"
#include "cosserat/time/stepper.hpp"

namespace cosserat {

// --until-rest: the run is at rest once its kinetic energy is below `fraction` of its peak so
// far. The peak is the run's own, so a sheet released from rest is not at rest at its first step.
struct RestSummary {
  double fraction = 0.0;
  double peak_kinetic_energy = 0.0;
  std::optional<long> step;  // the first step at rest; empty if the run ended before

  // Takes the kinetic energy after `step`; true, with `step` kept, when the run is at rest.
  bool at_rest(long step, double kinetic_energy);
};

struct StepLoopOptions {
  long checkpoint_every = 0;  // 0: no checkpoints
  std::optional<double> until_rest;
  double rest_peak = 0.0;  // a restarted run's peak kinetic energy so far (from its checkpoint)
  // Adaptive steps: what a restarted run's roll-backs left of the estimate (its checkpoint's).
  double adaptive_scale = 1.0;
  // The most threads a ThreadTuner may give this rank's team (the default count); 1: the count
  // stays as it was set (the user chose it).
  int tune_threads = 1;
};

// What a restart must continue from besides the simulation's state.
struct LoopCarry {
  std::optional<RestSummary> rest;     // with until_rest
  std::optional<double> adaptive_scale;  // with adaptive steps
};

// Told after each good step, in this order: frame and checkpoint when due, then progress. The
// state they are due for is the simulation's as it is when they are called.
class StepObserver {
 public:
  virtual ~StepObserver() = default;
  virtual void frame() = 0;
  virtual void checkpoint(const LoopCarry& carry) = 0;
  virtual void progress(long step) = 0;
};

// Adaptive steps, as they went.
struct AdaptiveSummary {
  double smallest_dt = std::numeric_limits<double>::infinity();
  double largest_dt = 0.0;
  long rollbacks = 0;  // times the monitor tripped and the run went back to a state in memory
};

struct StepLoopResult {
  long first_step = 0;  // the step the loop started from: 0, or a restart's checkpoint
  std::optional<Instability> failure;  // the simulation is left at the last good step
  std::optional<RestSummary> rest;     // with until_rest only
  std::optional<AdaptiveSummary> adaptive;  // with adaptive steps only
  double wall_seconds = 0.0;
  double halo_seconds = 0.0;  // of the wall time, in halo exchanges on this rank
  // Steps this rank ran with 1, 2, ... threads (index = threads − 1).
  std::vector<long> thread_steps;
};

// Steps `simulation` up to scene.steps (with adaptive steps: to scene.duration), stopping early
// on an instability or at rest. Frames are due every scene.output_every steps (adaptive: at
// every multiple of scene.output_dt), at the end and at the step at rest; checkpoints every
// options.checkpoint_every steps and at the end. Nothing is due for the step the loop starts
// from, nor for a step that failed. With adaptive steps, a step that trips the monitor sends
// the run back to a state held in memory, never one before the last frame or checkpoint, and on
// with a smaller step (docs/stability.md). Collective over the simulation's ranks.
StepLoopResult run_step_loop(Simulation& simulation, const Scene& scene,
                             const StepLoopOptions& options, StepObserver& observer);

}  // namespace cosserat
