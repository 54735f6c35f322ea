#include "cosserat/time/step_loop.hpp"

#include <algorithm>
#include <chrono>

namespace cosserat {

bool RestSummary::at_rest(long at_step, double kinetic_energy) {
  peak_kinetic_energy = std::max(peak_kinetic_energy, kinetic_energy);
  const bool rest = kinetic_energy < fraction * peak_kinetic_energy;
  if (rest) step = at_step;
  return rest;
}

StepLoopResult run_step_loop(Simulation& simulation, const Scene& scene,
                             const StepLoopOptions& options, StepObserver& observer) {
  using Clock = std::chrono::steady_clock;
  StepLoopResult result;
  result.first_step = simulation.step_index();
  if (options.until_rest)
    result.rest = RestSummary{*options.until_rest, options.rest_peak, std::nullopt};
  const double halo_before = simulation.halo_seconds();
  const auto start = Clock::now();
  while (simulation.step_index() < scene.steps) {
    result.failure = simulation.step();
    if (result.failure) break;
    const long step = simulation.step_index();
    const bool at_rest =
        result.rest && result.rest->at_rest(step, simulation.diagnostics().kinetic_energy);
    if (step % scene.output_every == 0 || step == scene.steps || at_rest) observer.frame();
    if (options.checkpoint_every > 0 &&
        (step % options.checkpoint_every == 0 || step == scene.steps))
      observer.checkpoint(result.rest);
    observer.progress(step);
    if (at_rest) break;
  }
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.halo_seconds = simulation.halo_seconds() - halo_before;
  return result;
}

}  // namespace cosserat
