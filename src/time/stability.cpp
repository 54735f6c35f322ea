#include "cosserat/time/stability.hpp"

#include <fmt/format.h>

#include <chrono>
#include <algorithm>
#include <cmath>
#include <vector>

#include "cosserat/time/simulation.hpp"

namespace cosserat {

StabilityTrial run_trial(const Scene& scene, double dt, double duration, MPI_Comm comm,
                         const SchemeFactory& make) {
  Scene trial_scene = scene;
  // Every trial takes fixed steps, whatever the scene's own.
  trial_scene.adaptive.reset();
  trial_scene.dt = dt;
  // Checked by largest_stable_step: a step count that fits a long.
  trial_scene.steps = static_cast<long>(std::ceil(duration / dt - 1e-9));
  trial_scene.duration = static_cast<double>(trial_scene.steps) * dt;
  const auto start = std::chrono::steady_clock::now();
  Simulation simulation(trial_scene, comm, make);
  StabilityTrial trial;
  trial.dt = dt;
  trial.stable = true;
  while (simulation.step_index() < trial_scene.steps) {
    if (const auto failure = simulation.step()) {
      trial.stable = false;
      trial.cause =
          failure->solver_failure
              ? fmt::format("step {}: {}", failure->step, *failure->solver_failure)
              : fmt::format("step {}: node [{}, {}] {}; {}", failure->step, failure->k,
                            failure->l, failure->not_finite ? "not finite" : "moved > h/2 from a neighbour",
                            failure->diagnosis);
      break;
    }
  }
  trial.steps = simulation.step_index();
  trial.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return trial;
}

void check_trial_length(const Scene& scene, double duration) {
  // Far beyond any affordable trial, and well inside a long.
  constexpr double kMostSteps = 1e15;
  if (!(duration / scene.dt <= kMostSteps))
    throw SceneError(fmt::format("{}: T/dt = {:.3g}/{:.3g} is more than {:.0e} steps; give a "
                                 "larger time.dt or a shorter --time",
                                 scene.path, duration, scene.dt, kMostSteps));
}

StableStep largest_stable_step(const Scene& scene, double duration, double tolerance, MPI_Comm comm,
                               const SchemeFactory& make,
                               const std::function<void(const StabilityTrial&)>& report) {
  StableStep result;
  auto trial = [&](double dt) {
    result.trials.push_back(run_trial(scene, dt, duration, comm, make));
    if (report) report(result.trials.back());
    return result.trials.back().stable;
  };
  check_trial_length(scene, duration);
  const double floor = 1e-6 * scene.dt;
  double dt = scene.dt;
  if (trial(dt)) {
    result.stable_dt = dt;
    while (result.unstable_dt == 0.0) {
      dt *= 2.0;
      if (dt > duration) return result;
      if (trial(dt))
        result.stable_dt = dt;
      else
        result.unstable_dt = dt;
    }
  } else {
    result.unstable_dt = dt;
    // When the run fails at the same simulated time whatever the step, halving is hopeless.
    auto failure_time = [&] {
      const StabilityTrial& t = result.trials.back();
      return static_cast<double>(t.steps + 1) * t.dt;
    };
    std::vector<double> failure_times{failure_time()};
    while (result.stable_dt == 0.0) {
      dt *= 0.5;
      if (dt < floor) return result;
      if (trial(dt)) {
        result.stable_dt = dt;
        break;
      }
      result.unstable_dt = dt;
      failure_times.push_back(failure_time());
      if (failure_times.size() >= 3) {
        const auto last = failure_times.end() - 3;
        const auto [low, high] = std::minmax_element(last, failure_times.end());
        if (*high - *low <= 0.05 * *high) {
          result.fails_near_time = failure_times.back();
          return result;
        }
      }
    }
  }
  while (result.unstable_dt - result.stable_dt > tolerance * result.stable_dt) {
    const double middle = 0.5 * (result.stable_dt + result.unstable_dt);
    if (trial(middle))
      result.stable_dt = middle;
    else
      result.unstable_dt = middle;
  }
  return result;
}

}  // namespace cosserat
