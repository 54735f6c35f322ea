// The schemes that carry velocities (docs/equations.md §4): leapfrog, the two Euler schemes,
// midpoint, RK4 and velocity-verlet.

#include "explicit_schemes.hpp"

namespace cosserat {

void VelocityScheme::start(Field<Vec3> velocities) {
  velocity_ = std::move(velocities);
  next_velocity_ = Field<Vec3>(context_.block);
}

std::vector<Scheme::StateField> VelocityScheme::state_fields() {
  return {{"positions", &positions_}, {"velocities", &velocity_}};
}

// The half step back to v^{−½}.
void Leapfrog::start(Field<Vec3> velocities) {
  VelocityScheme::start(std::move(velocities));
  const double dt = context_.dt;
  context_.dynamics.acceleration(positions_, velocity_, 0, acceleration_, normals());
  for_owned(context_.block,
            [&](int k, int l) { velocity_(k, l) -= (0.5 * dt) * acceleration_(k, l); });
  context_.constraints.hold_velocities(velocity_, context_.time - 0.5 * dt);
}

std::optional<std::string> Leapfrog::advance(long step) {
  Field<Vec3>* n_field = normals();
  const VelocityTerms terms =
      context_.dynamics.free_acceleration(positions_, step, acceleration_, n_field);
  const double dt = context_.dt;
  const double c = 0.5 * dt * terms.damping;
  const double d = 0.5 * dt * terms.fluid;
  if (context_.dynamics.has_velocity_force()) {
    damped_springs_velocity(c, d);
  } else {
    for_owned(context_.block, [&](int k, int l) {
      const Vec3 v = velocity_(k, l);
      Vec3 rhs = (1.0 - c) * v + dt * acceleration_(k, l);
      if (d > 0.0) {
        const Vec3 n = (*n_field)(k, l);
        rhs -= (d * dot(n, v)) * n;
        next_velocity_(k, l) = solve_centred(rhs, n, c, d);
      } else {
        next_velocity_(k, l) = rhs / (1.0 + c);
      }
    });
  }
  context_.constraints.hold_velocities(next_velocity_, context_.time + 0.5 * dt);
  for_owned(context_.block, [&](int k, int l) {
    next_positions_(k, l) = positions_(k, l) + dt * next_velocity_(k, l);
  });
  context_.constraints.hold_positions(next_positions_, context_.end_time);
  return std::nullopt;
}

// v^{n+½} with the springs' damping at the mean velocity: (1 + c) w + d (n·w) n − (Δt/2) K(w)
// = (1 − c) v − d (n·v) n + Δt a + (Δt/2) K(v), solved from the first guess v (a held component
// at its held velocity).
void Leapfrog::damped_springs_velocity(double c, double d) {
  const double dt = context_.dt;
  const double s = 0.5 * dt;
  Dynamics& dynamics = context_.dynamics;
  const Field<Vec3>* n_field = normals();
  if (spring_force_.data() == nullptr) spring_force_ = Field<Vec3>(context_.block);
  dynamics.velocity_acceleration(positions_, velocity_, spring_force_);
  for_owned(context_.block, [&](int k, int l) {
    const Vec3 v = velocity_(k, l);
    Vec3 rhs = (1.0 - c) * v + dt * acceleration_(k, l) + s * spring_force_(k, l);
    if (d > 0.0) {
      const Vec3 n = (*n_field)(k, l);
      rhs -= (d * dot(n, v)) * n;
    }
    acceleration_(k, l) = rhs;
    next_velocity_(k, l) = v;
  });
  context_.constraints.hold_velocities(next_velocity_, context_.time + s);
  dynamics.solve_velocity_terms(positions_, n_field, c, d, s, acceleration_,
                                context_.constraints.state(), next_velocity_);
}

std::optional<std::string> Euler::advance(long step) {
  context_.dynamics.acceleration(positions_, velocity_, step, acceleration_, normals());
  const double dt = context_.dt;
  for_owned(context_.block, [&](int k, int l) {
    next_velocity_(k, l) = velocity_(k, l) + dt * acceleration_(k, l);
  });
  context_.constraints.hold_velocities(next_velocity_, context_.end_time);
  const Field<Vec3>& drift = symplectic_ ? next_velocity_ : velocity_;
  for_owned(context_.block, [&](int k, int l) {
    next_positions_(k, l) = positions_(k, l) + dt * drift(k, l);
  });
  context_.constraints.hold_positions(next_positions_, context_.end_time);
  return std::nullopt;
}

void Midpoint::start(Field<Vec3> velocities) {
  VelocityScheme::start(std::move(velocities));
  midpoint_positions_ = Field<Vec3>(context_.block);
  midpoint_velocity_ = Field<Vec3>(context_.block);
}

std::optional<std::string> Midpoint::advance(long step) {
  const double dt = context_.dt;
  Dynamics& dynamics = context_.dynamics;
  dynamics.acceleration(positions_, velocity_, step, acceleration_, normals());
  for_owned(context_.block, [&](int k, int l) {
    midpoint_positions_(k, l) = positions_(k, l) + (0.5 * dt) * velocity_(k, l);
    midpoint_velocity_(k, l) = velocity_(k, l) + (0.5 * dt) * acceleration_(k, l);
  });
  hold(midpoint_positions_, midpoint_velocity_, 0.5);
  context_.halo.exchange(midpoint_positions_);
  dynamics.set_stage_time(context_.time + 0.5 * dt);
  dynamics.acceleration(midpoint_positions_, midpoint_velocity_, step, acceleration_, normals());
  for_owned(context_.block, [&](int k, int l) {
    next_positions_(k, l) = positions_(k, l) + dt * midpoint_velocity_(k, l);
    next_velocity_(k, l) = velocity_(k, l) + dt * acceleration_(k, l);
  });
  hold(next_positions_, next_velocity_, 1.0);
  return std::nullopt;
}

void RungeKutta4::start(Field<Vec3> velocities) {
  VelocityScheme::start(std::move(velocities));
  stage_positions_ = Field<Vec3>(context_.block);
  stage_velocity_ = Field<Vec3>(context_.block);
  velocity_sum_ = Field<Vec3>(context_.block);
  acceleration_sum_ = Field<Vec3>(context_.block);
}

std::optional<std::string> RungeKutta4::advance(long step) {
  const double dt = context_.dt;
  Dynamics& dynamics = context_.dynamics;
  Halo& halo = context_.halo;
  dynamics.acceleration(positions_, velocity_, step, acceleration_, normals());
  for_owned(context_.block, [&](int k, int l) {
    velocity_sum_(k, l) = velocity_(k, l);
    acceleration_sum_(k, l) = acceleration_(k, l);
    stage_positions_(k, l) = positions_(k, l) + (0.5 * dt) * velocity_(k, l);
    stage_velocity_(k, l) = velocity_(k, l) + (0.5 * dt) * acceleration_(k, l);
  });
  hold(stage_positions_, stage_velocity_, 0.5);
  // Stages 2 and 3 belong to the step's middle, stage 4 to its end.
  dynamics.set_stage_time(context_.time + 0.5 * dt);
  for (const double fraction : {0.5, 1.0}) {
    halo.exchange(stage_positions_);
    dynamics.acceleration(stage_positions_, stage_velocity_, step, acceleration_, normals());
    for_owned(context_.block, [&](int k, int l) {
      const Vec3 vs = stage_velocity_(k, l), as = acceleration_(k, l);
      velocity_sum_(k, l) += 2.0 * vs;
      acceleration_sum_(k, l) += 2.0 * as;
      stage_positions_(k, l) = positions_(k, l) + (fraction * dt) * vs;
      stage_velocity_(k, l) = velocity_(k, l) + (fraction * dt) * as;
    });
    hold(stage_positions_, stage_velocity_, fraction);
  }
  halo.exchange(stage_positions_);
  dynamics.set_stage_time(context_.time + dt);
  dynamics.acceleration(stage_positions_, stage_velocity_, step, acceleration_, normals());
  for_owned(context_.block, [&](int k, int l) {
    next_positions_(k, l) =
        positions_(k, l) + (dt / 6.0) * (velocity_sum_(k, l) + stage_velocity_(k, l));
    next_velocity_(k, l) =
        velocity_(k, l) + (dt / 6.0) * (acceleration_sum_(k, l) + acceleration_(k, l));
  });
  hold(next_positions_, next_velocity_, 1.0);
  return std::nullopt;
}

void VelocityVerlet::start(Field<Vec3> velocities) {
  VelocityScheme::start(std::move(velocities));
  predicted_velocity_ = Field<Vec3>(context_.block);
  next_acceleration_ = Field<Vec3>(context_.block);
  context_.dynamics.acceleration(positions_, velocity_, 0, acceleration_, normals());
}

std::optional<std::string> VelocityVerlet::advance(long step) {
  const double dt = context_.dt;
  for_owned(context_.block, [&](int k, int l) {
    next_positions_(k, l) =
        positions_(k, l) + dt * velocity_(k, l) + (0.5 * dt * dt) * acceleration_(k, l);
    predicted_velocity_(k, l) = velocity_(k, l) + dt * acceleration_(k, l);
  });
  hold(next_positions_, predicted_velocity_, 1.0);
  context_.halo.exchange(next_positions_);
  // a⁺ belongs to the end of the step, where load windows in seconds are told.
  context_.dynamics.set_time(context_.time + dt);
  context_.dynamics.acceleration(next_positions_, predicted_velocity_, step + 1,
                                 next_acceleration_, normals());
  for_owned(context_.block, [&](int k, int l) {
    next_velocity_(k, l) =
        velocity_(k, l) + (0.5 * dt) * (acceleration_(k, l) + next_acceleration_(k, l));
  });
  context_.constraints.hold_velocities(next_velocity_, context_.end_time);
  return std::nullopt;
}

void VelocityVerlet::accept_state() {
  VelocityScheme::accept_state();
  acceleration_.swap(next_acceleration_);
}

std::vector<Scheme::StateField> VelocityVerlet::state_fields() {
  std::vector<StateField> fields = VelocityScheme::state_fields();
  fields.push_back({"accelerations", &acceleration_});
  return fields;
}

}  // namespace cosserat
