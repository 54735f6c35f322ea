#pragma once
// The largest stable step of a scene and integrator, by bisection on the
// stability monitor of docs/equations.md §4.2, never by eye (docs/scenes.md,
// "S1–S6: the integrator study"): the engine of `cosserat stable-dt`.

#include <mpi.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cosserat/scene/scene.hpp"
#include "cosserat/time/scheme.hpp"

namespace cosserat {

// One run of the scene at step dt over ceil(duration/dt) steps, without output.
struct StabilityTrial {
  double dt = 0.0;
  long steps = 0;       // steps run (the failing one not counted)
  bool stable = false;  // the monitor never stopped it
  std::string cause;    // what stopped it, when it was stopped
  double wall_seconds = 0.0;
};

// The scheme is built by `make`, as for Simulation.
StabilityTrial run_trial(const Scene& scene, double dt, double duration, MPI_Comm comm,
                         const SchemeFactory& make);

struct StableStep {
  double stable_dt = 0.0;    // the largest step found stable (0: none, down to the floor)
  double unstable_dt = 0.0;  // the smallest found unstable (0: none, up to the ceiling)
  // Set when halving the step stopped changing when the run fails: the failure is the
  // semi-discrete system's, not the integrator's, and no step will cure it.
  std::optional<double> fails_near_time;
  std::vector<StabilityTrial> trials;
};

// A step so small that ceil(T/dt) would not fit a long is bad input (SceneError), not a trial
// of zero steps that calls itself stable.
void check_trial_length(const Scene& scene, double duration);

// Starting from the scene's dt, doubles or halves until stable and unstable
// steps bracket the limit, then bisects until they are within `tolerance` of
// each other (relative to the stable one). Steps above `duration` or below 1e-6
// of the scene's dt end the search unbracketed, and so do three halvings in a row whose
// runs all fail within 5 % of the same simulated time. `report` sees every trial as it
// ends (rank 0 prints progress with it).
StableStep largest_stable_step(const Scene& scene, double duration, double tolerance, MPI_Comm comm,
                               const SchemeFactory& make,
                               const std::function<void(const StabilityTrial&)>& report = {});

}  // namespace cosserat
