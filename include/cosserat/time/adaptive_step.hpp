#pragma once
// Adaptive steps (docs/stability.md, "Adaptive steps"): the rest of each frame in equal steps
// that the stability estimate of the current state times a safety factor allows, changed only
// when the estimate moves by more than a tenth, and shrunk after the monitor
// (docs/stability.md) trips and the run rolls back. Every choice is made from
// global maxima, which are exact, so the steps are the same on any number of ranks.

#include <limits>

#include "cosserat/scene/scene.hpp"

namespace cosserat {

// What the estimate reads from the current state, from global maxima.
struct StateMeasures {
  double stretch2 = 1.0;   // the largest |r_,α|² / |R_,α|² over the grid's edges
  double max_speed = 0.0;  // m/s
  // The longest step in which no moving solid comes more than a quarter of the smaller spacing
  // into the box of the cloth's nodes (Contact::approach_step), s.
  double solid_step = std::numeric_limits<double>::infinity();
};

// The step the state allows, before the safety factor: the force model's for its stretched
// edges (stretched_step_estimate, model/model_spec.hpp), no more than a quarter of the smaller
// spacing per step at the fastest node (half of what the monitor allows), and the moving
// solids' `solid_step`.
double stability_estimate(const Scene& scene, const StateMeasures& state);

class AdaptiveSteps {
 public:
  // `scale`: what earlier roll-backs left of the estimate (a restart's, from its checkpoint).
  explicit AdaptiveSteps(const Scene& scene, double scale = 1.0);

  struct Next {
    double dt;
    double end_time;  // time + dt, or exactly the frame time the step was cut to reach
    bool frame;       // the step ends at a frame time (the last one is the duration)
  };
  // Step `step` (counted from the run's start), from `time`, after a step of `last_dt`, for a
  // state estimated at `estimate`; random steps read neither the estimate nor the last step.
  Next next(double time, double last_dt, double estimate, long step) const;

  // Whether the steps follow the state's estimate (random ones do not, and never roll back).
  bool follows_estimate() const { return !settings_.random; }

  // A step of `failed_dt` tripped the monitor: from now on the run takes half of what it took
  // of the estimate. False when half the failed step is below time.dt.min, or the steps are
  // random (the sequence is the seed's): the run is unstable. The factor never grows back: an
  // estimate that was too large once is so by a factor the state carries on (a fold, a stiffer
  // bending mode), and growing back would only repeat the roll-back.
  bool shrink(double failed_dt);

  double scale() const { return scale_; }

  // The last frame time at or before `time`: j x output_dt (0 for the first frame).
  double frame_at_or_before(double time) const;

 private:
  double frame_index(double time) const;
  Next random_step(double time, long step) const;
  // The first frame time after `time`: j x output_dt, or the duration.
  double frame_after(double time) const;

  AdaptiveStep settings_;
  double duration_, output_dt_;
  double scale_;
};

}  // namespace cosserat
