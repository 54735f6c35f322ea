#include "cosserat/time/scheme.hpp"

#include <algorithm>

#include "explicit_schemes.hpp"

namespace cosserat {

VerletFamily::VerletFamily(const StepContext& context, const Field<Vec3>& positions,
                           Integrator scheme)
    : Scheme(context, positions),
      previous_positions_(context.block),
      dt_previous_(context.dt),
      published_(scheme == Integrator::verlet_lagged),
      velocity_report_(context.block) {}

// The second-order start r⁻ = r − Δt v + ½Δt² a; verlet-lagged keeps the published first-order
// one (docs/equations.md §4).
void VerletFamily::start(Field<Vec3> velocities) {
  const double dt = context_.dt;
  if (published_) {
    for_owned(context_.block, [&](int k, int l) {
      previous_positions_(k, l) = positions_(k, l) - dt * velocities(k, l);
    });
    lagged_velocity_ = std::move(velocities);
  } else {
    context_.dynamics.acceleration(positions_, velocities, 0, acceleration_, normals());
    for_owned(context_.block, [&](int k, int l) {
      previous_positions_(k, l) =
          positions_(k, l) - dt * velocities(k, l) + (0.5 * dt * dt) * acceleration_(k, l);
    });
  }
  context_.constraints.hold_positions(previous_positions_, previous_time(dt));
}

std::optional<std::string> VerletFamily::advance(long step) {
  velocities_current_ = false;
  walked_starts_ = false;
  return propose(step);
}

std::optional<std::string> VerletFamily::propose(long step) {
  if (published_)
    lagged_step(step);
  else
    centred_step(step);
  return std::nullopt;
}

// verlet and tc-verlet: r⁺ = r + (r − r⁻) Δtₙ/Δtₙ₋₁ + Δtₙ (Δtₙ + Δtₙ₋₁)/2 a, the form that is
// consistent on a non-uniform time grid (the published form, docs/equations.md §4, has Δtₙ² a,
// first order when the step changes; docs/stability.md), with the velocity terms at the centre,
// v = (r⁺ − r⁻)/(Δtₙ + Δtₙ₋₁), solved in closed form. With a constant step both are the plain
// central-difference Verlet, bit for bit: (Δt + Δt)/2 is Δt exactly.
void VerletFamily::centred_step(long step) {
  // A node held from now on starts at its held velocity (at rest, for a still fix).
  context_.constraints.hold_positions(previous_positions_, previous_time(dt_previous_));
  Dynamics& dynamics = context_.dynamics;
  const double dt = context_.dt;
  const double weight = dt * ((dt + dt_previous_) * 0.5);
  const double ratio = dt / dt_previous_;
  const double span = dt + dt_previous_;
  // Without damping c is 0 and the update is r⁺ = r + ratio (r − r⁻) + weight a, exactly.
  auto update = [&](const Vec3& r, const Vec3& rp, const Vec3& a, double c) {
    return (r + ratio * (r - rp) + weight * a + c * rp) / (1.0 + c);
  };
  if (dynamics.fuses_rows()) {
    // Each row of a is used while the kernel still has it in cache, and never stored: the
    // step's largest sweep of memory saved (docs/kernel.md). The row is held, and the
    // contact meets the planes with it and the stability check's edge test reads it while it
    // is still there too.
    const double c = dynamics.row_velocity_terms().damping * weight / span;
    const Block& b = context_.block;
    const Constraints& constraints = context_.constraints;
    RowWalk* rows = context_.rows != nullptr && !context_.rows->empty() ? context_.rows : nullptr;
    // A walk's reader that sets velocities writes the next step's r⁻ straight into the field
    // that becomes it (RowReader::begin_walk).
    Field<Vec3>* starts = nullptr;
    if (rows != nullptr && rows->sets_velocities()) {
      if (next_previous_.data() == nullptr) next_previous_ = Field<Vec3>(b);
      starts = &next_previous_;
      walked_starts_ = true;
    }
    if (rows != nullptr) rows->begin_walk(context_.time, dt, starts);
    dynamics.free_acceleration_rows(positions_, step, [&](int l, double* x, double* y, double* z) {
      const Vec3* r = &positions_(b.k0, l);
      const Vec3* rp = &previous_positions_(b.k0, l);
      Vec3* next = &next_positions_(b.k0, l);
#pragma omp simd
      for (int i = 0; i < b.owned_k(); ++i) next[i] = update(r[i], rp[i], {x[i], y[i], z[i]}, c);
      constraints.hold_row(next_positions_, l, context_.end_time);
      if (rows != nullptr) rows->walk_row(l, positions_, next_positions_);
    });
    return;
  }
  Field<Vec3>* n_field = normals();
  const VelocityTerms terms =
      dynamics.free_acceleration(positions_, step, acceleration_, n_field);
  const double c = terms.damping * weight / span;
  const double d = terms.fluid * weight / span;
  if (dynamics.has_velocity_force()) {
    damped_springs_step(weight, ratio, span, c, d);
    return;
  }
  // Two loops rather than a test per node, so that each vectorises.
  if (d > 0.0) {
    for_owned(context_.block, [&](int k, int l) {
      const Vec3 r = positions_(k, l), rp = previous_positions_(k, l);
      const Vec3 n = (*n_field)(k, l);
      const Vec3 rhs =
          r + ratio * (r - rp) + weight * acceleration_(k, l) + c * rp + (d * dot(n, rp)) * n;
      next_positions_(k, l) = solve_centred(rhs, n, c, d);
    });
  } else {
    for_owned(context_.block, [&](int k, int l) {
      next_positions_(k, l) =
          update(positions_(k, l), previous_positions_(k, l), acceleration_(k, l), c);
    });
  }
  context_.constraints.hold_positions(next_positions_, context_.end_time);
}

// The centred step when the model's force depends on the velocities (springs damped along
// themselves): the centred velocity v = (r⁺ − r⁻)/(Δtₙ + Δtₙ₋₁) couples neighbours, so it is
// solved for (Dynamics::solve_velocity_terms) rather than found node by node, from the first
// guess (r − r⁻)/Δtₙ₋₁; a held component's is where its hold takes it.
void VerletFamily::damped_springs_step(double weight, double ratio, double span, double c,
                                       double d) {
  if (centred_velocity_.data() == nullptr) centred_velocity_ = Field<Vec3>(context_.block);
  const double dt_previous = dt_previous_;
  for_owned(context_.block, [&](int k, int l) {
    const Vec3 r = positions_(k, l), rp = previous_positions_(k, l);
    acceleration_(k, l) = (r + ratio * (r - rp) + weight * acceleration_(k, l) - rp) / span;
    centred_velocity_(k, l) = (r - rp) / dt_previous;
  });
  const std::vector<Constraints::NodeState> held = context_.constraints.state();
  for (const Constraints::NodeState& node : held)
    if (context_.block.owns(node.k, node.l))
      for (int axis = 0; axis < 3; ++axis)
        if ((node.held >> axis) & 1u)
          centred_velocity_(node.k, node.l)[axis] =
              (node.position(axis, context_.end_time) - previous_positions_(node.k, node.l)[axis]) /
              span;
  context_.dynamics.solve_velocity_terms(positions_, normals(), c, d, weight / span,
                                         acceleration_, held, centred_velocity_);
  for_owned(context_.block, [&](int k, int l) {
    next_positions_(k, l) = previous_positions_(k, l) + span * centred_velocity_(k, l);
  });
  context_.constraints.hold_positions(next_positions_, context_.end_time);
}

// The published Verlet: velocity terms lagged, v = (r − r⁻)/Δt; first order (docs/equations.md §4).
void VerletFamily::lagged_step(long step) {
  context_.constraints.hold_positions(previous_positions_, previous_time(dt_previous_));
  const double dt = context_.dt;
  for_owned(context_.block, [&](int k, int l) {
    lagged_velocity_(k, l) = (positions_(k, l) - previous_positions_(k, l)) / dt;
  });
  context_.dynamics.acceleration(positions_, lagged_velocity_, step, acceleration_, normals());
  for_owned(context_.block, [&](int k, int l) {
    next_positions_(k, l) =
        2.0 * positions_(k, l) - previous_positions_(k, l) + (dt * dt) * acceleration_(k, l);
  });
  context_.constraints.hold_positions(next_positions_, context_.end_time);
}

void VerletFamily::accept_state() {
  // rⁿ becomes rⁿ⁻¹, or what the walk made of it; Scheme::accept then makes the proposed
  // positions rⁿ.
  if (walked_starts_)
    previous_positions_.swap(next_previous_);
  else
    previous_positions_.swap(positions_);
  dt_previous_ = context_.dt;
}

void VerletFamily::set_velocities(const NodeVelocities& velocities) {
  velocities.for_each([&](const NodeVelocity& v) {
    previous_positions_(v.k, v.l) = positions_(v.k, v.l) - dt_previous_ * v.velocity;
  });
  velocities_current_ = false;
}

namespace {
// The backward difference (r − r⁻)/Δt, the one formula of velocities() and max_speed2().
Vec3 backward(const Vec3& r, const Vec3& rp, double dt) { return (r - rp) / dt; }
}  // namespace

const Field<Vec3>& VerletFamily::velocities() {
  if (!velocities_current_) {
    const double dt = dt_previous_;
    for_owned(context_.block, [&](int k, int l) {
      velocity_report_(k, l) = backward(positions_(k, l), previous_positions_(k, l), dt);
    });
    velocities_current_ = true;
  }
  return velocity_report_;
}

// velocities()'s largest |v|², without writing the field where it is not current: the adaptive
// step reads it before every step (docs/stability.md, "Adaptive steps", its cost).
double VerletFamily::max_speed2() {
  if (velocities_current_) return Scheme::max_speed2();
  const Block& b = context_.block;
  const double dt = dt_previous_;
  double most = 0.0;
#pragma omp parallel for schedule(static) reduction(max : most)
  for (int l = b.l0; l < b.l1; ++l) {
    const Vec3* r = &positions_(b.k0, l);
    const Vec3* rp = &previous_positions_(b.k0, l);
#pragma omp simd reduction(max : most)
    for (int i = 0; i < b.owned_k(); ++i) {
      const Vec3 v = backward(r[i], rp[i], dt);
      most = std::max(most, dot(v, v));
    }
  }
  return most;
}

std::vector<Scheme::StateField> VerletFamily::state_fields() {
  return {{"positions", &positions_}, {"previous_positions", &previous_positions_}};
}

}  // namespace cosserat
