#include "cosserat/time/adaptive_step.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "cosserat/model/model_spec.hpp"

namespace cosserat {

namespace {
// A step may grow by this factor over the last: tc-verlet stays second order on a smoothly
// varying step, and an estimate that jumps does not leap past the state it was read from.
constexpr double kGrowth = 1.25;
// docs/stability.md, "Adaptive steps": a step that changes goes to this share of what the
// estimate allows, and grows only when that is this factor longer than the step it keeps, so
// the estimate's wobble from step to step leaves the step alone.
constexpr double kMargin = 0.9;
constexpr double kRegrow = 1.1;
}  // namespace

double stability_estimate(const Scene& scene, const StateMeasures& state) {
  double estimate = stretched_step_estimate(scene.model_spec(), state.stretch2);
  if (state.max_speed > 0.0)
    estimate = std::min(estimate, 0.25 * std::min(scene.h1(), scene.h2()) / state.max_speed);
  return std::min(estimate, state.solid_step);
}

AdaptiveSteps::AdaptiveSteps(const Scene& scene, double scale)
    : settings_(*scene.adaptive),
      duration_(scene.duration),
      output_dt_(scene.output_dt),
      scale_(scale) {}

// The largest j ≥ 0 with j x output_dt ≤ time, found from the products themselves, which are
// the frame times, so that a time that landed on a frame is never taken for just before it.
double AdaptiveSteps::frame_index(double time) const {
  double j = std::max(std::floor(time / output_dt_), 0.0);
  while (j > 0.0 && j * output_dt_ > time) j -= 1.0;
  while ((j + 1.0) * output_dt_ <= time) j += 1.0;
  return j;
}

double AdaptiveSteps::frame_after(double time) const {
  return std::min((frame_index(time) + 1.0) * output_dt_, duration_);
}

double AdaptiveSteps::frame_at_or_before(double time) const {
  return frame_index(time) * output_dt_;
}

// docs/stability.md, "Adaptive steps": the rest of the frame in equal steps. A step that
// followed the estimate from one step to the next pumped a drape's fastest modes: the stretch
// it reads swings with them, so the step swung at their frequency (sphere_drape over 10 s:
// energy rose in 131 of 334 frames, by up to 0.015 J, and nodes chattered at 2 m/s; at a fixed
// step of the same length, or by this rule, it rose in a few frames by at most 1e-5 J).
AdaptiveSteps::Next AdaptiveSteps::next(double time, double last_dt, double estimate,
                                        long step) const {
  if (settings_.random) return random_step(time, step);
  const double stable = scale_ * settings_.safety * estimate;
  const auto bounded = [&](double dt) {
    return std::max(std::min(dt, settings_.max), settings_.min);
  };
  const double longest = std::min(bounded(stable), kGrowth * last_dt);
  const double aim = bounded(kMargin * stable);
  const double target = frame_after(time);
  const double left = target - time;
  // As many steps as the last one's length fits in the rest of the frame, unless they would
  // be too long, or the estimate has left room for a longer step worth taking.
  double count = std::max(1.0, std::round(left / last_dt));
  if (left / count > longest || aim >= kRegrow * (left / count)) {
    count = std::max(std::ceil(left / aim), std::ceil(left / (kGrowth * last_dt)));
    // The estimate is advice; only the monitor declares a run unstable (then below min).
    count = std::max(1.0, std::min(count, std::floor(left / settings_.min)));
  }
  if (count <= 1.0) return Next{left, target, true};
  const double dt = left / count;
  return Next{dt, time + dt, false};
}

// docs/stability.md, "Random steps": step n's length from the seed and n alone (SplitMix64 of
// the two, uniform in [min, max]), so that every rank, thread count and restart draws the same
// sequence. A step is cut short to end on a frame time, or stretched to it when it would leave
// less than min before it (or, where that would pass max, the step is half of what is left).
AdaptiveSteps::Next AdaptiveSteps::random_step(double time, long step) const {
  std::uint64_t x = settings_.seed + 0x9E3779B97F4A7C15ULL * (static_cast<std::uint64_t>(step) + 1);
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  x ^= x >> 31;
  const double unit = static_cast<double>(x >> 11) * 0x1.0p-53;
  const double dt = settings_.min + unit * (settings_.max - settings_.min);
  const double target = frame_after(time);
  const double left = target - time;
  if (dt >= left || (left - dt < settings_.min && left <= settings_.max))
    return Next{left, target, true};
  if (left - dt < settings_.min) return Next{0.5 * left, time + 0.5 * left, false};
  return Next{dt, time + dt, false};
}

bool AdaptiveSteps::shrink(double failed_dt) {
  if (settings_.random) return false;
  scale_ *= 0.5;
  return 0.5 * failed_dt >= settings_.min;
}

}  // namespace cosserat
