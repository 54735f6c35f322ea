#include "cosserat/time/scheme.hpp"

#include <algorithm>
#include <stdexcept>

#include "explicit_schemes.hpp"

namespace cosserat {

Scheme::Scheme(const StepContext& context, const Field<Vec3>& positions)
    : context_(context),
      positions_(positions),
      next_positions_(context.block),
      acceleration_(context.block) {
  if (context.dynamics.has_fluid()) normals_ = Field<Vec3>(context.block);
}

void Scheme::hold(Field<Vec3>& r, Field<Vec3>& v, double fraction) const {
  context_.constraints.hold_positions(r, stage_time(fraction));
  context_.constraints.hold_velocities(v, stage_time(fraction));
}

void Scheme::begin(Field<Vec3> velocities) {
  context_.constraints.begin_step(0, 0.0, positions_);
  hold(positions_, velocities, 0.0);
  context_.halo.exchange(positions_);
  start(std::move(velocities));
}

void Scheme::exchange_next_positions(bool changed) {
  if (changed || !exchanged_next_positions()) context_.halo.exchange(next_positions_);
}

void Scheme::accept() {
  accept_state();
  positions_.swap(next_positions_);
}

double Scheme::max_speed2() {
  const Block& b = context_.block;
  const Field<Vec3>& v = velocities();
  double most = 0.0;
#pragma omp parallel for schedule(static) reduction(max : most)
  for (int l = b.l0; l < b.l1; ++l) {
    const Vec3* row = &v(b.k0, l);
#pragma omp simd reduction(max : most)
    for (int i = 0; i < b.owned_k(); ++i) most = std::max(most, dot(row[i], row[i]));
  }
  return most;
}

void Scheme::resume(double last_dt) {
  context_.dt = last_dt;
  state_changed();
  context_.halo.exchange(positions_);
}

std::unique_ptr<Scheme> explicit_scheme(const SchemeSetup& setup) {
  const StepContext& c = setup.context;
  const Field<Vec3>& r = setup.positions;
  switch (setup.scene.integrator) {
    case Integrator::verlet:
    case Integrator::tc_verlet:
    case Integrator::verlet_lagged:
      return std::make_unique<VerletFamily>(c, r, setup.scene.integrator);
    case Integrator::leapfrog: return std::make_unique<Leapfrog>(c, r);
    case Integrator::euler: return std::make_unique<Euler>(c, r, false);
    case Integrator::symplectic_euler: return std::make_unique<Euler>(c, r, true);
    case Integrator::midpoint: return std::make_unique<Midpoint>(c, r);
    case Integrator::rk4: return std::make_unique<RungeKutta4>(c, r);
    case Integrator::velocity_verlet: return std::make_unique<VelocityVerlet>(c, r);
    case Integrator::semi_implicit:
    case Integrator::semi_implicit_2: break;
  }
  throw std::logic_error(
      "the semi-implicit scheme is built by the baseline module (cosserat::any_scheme)");
}

}  // namespace cosserat
