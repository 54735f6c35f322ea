#include "cosserat/time/stepper.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace cosserat {

namespace {

// Runs body(k, l) over the owned nodes, rows shared among threads.
template <class Body>
void for_owned(const Block& b, Body&& body) {
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) body(k, l);
}

// Solves (1 + c) w + d (n·w) n = rhs for w, |n| = 1, by Sherman–Morrison: the centred
// damping and fluid terms of MODEL.md §4 in closed form.
inline Vec3 solve_centred(const Vec3& rhs, const Vec3& n, double c, double d) {
  return (rhs - (d / (1.0 + c + d) * dot(n, rhs)) * n) / (1.0 + c);
}

// The schemes whose state is (r, r⁻): the semi-implicit step is Verlet's with J added.
bool is_verlet_family(Integrator s) {
  return s == Integrator::verlet || s == Integrator::tc_verlet ||
         s == Integrator::verlet_lagged || s == Integrator::semi_implicit;
}

}  // namespace

Stepper::Stepper(const Scene& scene, const Decomposition& decomposition, const Block& block,
                 Halo& halo, Dynamics& dynamics, const Field<Vec3>& positions,
                 const Field<Vec3>& velocities)
    : block_(&block),
      halo_(&halo),
      dynamics_(&dynamics),
      constraints_(scene.fixes, block),
      scheme_(scene.integrator),
      dt_(scene.dt),
      dt_previous_(scene.dt),
      max_move_(0.5 * std::min(scene.h1(), scene.h2())),
      r_(positions),
      v_(velocities),
      r_next_(block),
      a_(block) {
  if (scheme_ == Integrator::semi_implicit)
    implicit_ = std::make_unique<SemiImplicitSolver>(scene, decomposition, block, dynamics);
  start();
}

void Stepper::hold(Field<Vec3>& r, Field<Vec3>& v) const {
  constraints_.hold_positions(r);
  constraints_.hold_velocities(v);
}

// Initial history of each scheme (MODEL.md §4): the second-order start of the Verlet family,
// leapfrog's half step, velocity-verlet's first acceleration.
void Stepper::start() {
  const Block& b = *block_;
  constraints_.begin_step(0, r_);
  hold(r_, v_);
  halo_->exchange(r_);
  const double dt = dt_;
  switch (scheme_) {
    case Integrator::verlet:
    case Integrator::tc_verlet:
    case Integrator::verlet_lagged:
    case Integrator::semi_implicit: {
      r_prev_ = Field<Vec3>(b);
      v_report_ = Field<Vec3>(b);
      if (scheme_ == Integrator::semi_implicit) {
        r_stage_ = Field<Vec3>(b);  // d = rⁿ − rⁿ⁻¹
        v_stage_ = Field<Vec3>(b);  // δ = rⁿ⁺¹ − rⁿ
      }
      if (scheme_ == Integrator::verlet_lagged) {
        // The published start: first order.
        for_owned(b, [&](int k, int l) { r_prev_(k, l) = r_(k, l) - dt * v_(k, l); });
      } else {
        dynamics_->acceleration(r_, v_, 0, a_);
        for_owned(b, [&](int k, int l) {
          r_prev_(k, l) = r_(k, l) - dt * v_(k, l) + (0.5 * dt * dt) * a_(k, l);
        });
      }
      constraints_.hold_positions(r_prev_);
      break;
    }
    case Integrator::leapfrog:
      v_stage_ = Field<Vec3>(b);
      dynamics_->acceleration(r_, v_, 0, a_);
      for_owned(b, [&](int k, int l) { v_(k, l) -= (0.5 * dt) * a_(k, l); });
      constraints_.hold_velocities(v_);
      break;
    case Integrator::euler:
    case Integrator::symplectic_euler:
      v_stage_ = Field<Vec3>(b);
      break;
    case Integrator::midpoint:
      r_stage_ = Field<Vec3>(b);
      v_stage_ = Field<Vec3>(b);
      v_sum_ = Field<Vec3>(b);
      break;
    case Integrator::rk4:
      r_stage_ = Field<Vec3>(b);
      v_stage_ = Field<Vec3>(b);
      r_sum_ = Field<Vec3>(b);
      v_sum_ = Field<Vec3>(b);
      break;
    case Integrator::velocity_verlet:
      v_stage_ = Field<Vec3>(b);
      v_sum_ = Field<Vec3>(b);
      r_sum_ = Field<Vec3>(b);  // the next acceleration
      dynamics_->acceleration(r_, v_, 0, a_);
      break;
  }
}

std::optional<Instability> Stepper::step() {
  velocities_current_ = false;
  constraints_.begin_step(step_, r_);
  switch (scheme_) {
    case Integrator::verlet:
    case Integrator::tc_verlet: verlet_step(); break;
    case Integrator::verlet_lagged: verlet_lagged_step(); break;
    case Integrator::leapfrog: leapfrog_step(); break;
    case Integrator::euler: euler_step(false); break;
    case Integrator::symplectic_euler: euler_step(true); break;
    case Integrator::midpoint: midpoint_step(); break;
    case Integrator::rk4: rk4_step(); break;
    case Integrator::velocity_verlet: velocity_verlet_step(); break;
    case Integrator::semi_implicit:
      if (auto solver_failure = semi_implicit_step()) {
        return Instability{step_ + 1, static_cast<double>(step_ + 1) * dt_, -1, -1, false,
                           std::move(solver_failure)};
      }
      break;
  }
  if (auto failure = check(r_next_)) return failure;

  // Accept: the new state replaces the old one.
  switch (scheme_) {
    case Integrator::verlet:
    case Integrator::tc_verlet:
    case Integrator::verlet_lagged:
    case Integrator::semi_implicit:
      r_prev_.swap(r_);
      dt_previous_ = dt_;
      break;
    case Integrator::leapfrog:
    case Integrator::euler:
    case Integrator::symplectic_euler: v_.swap(v_stage_); break;
    case Integrator::midpoint:
    case Integrator::rk4: v_.swap(v_sum_); break;
    case Integrator::velocity_verlet:
      v_.swap(v_sum_);
      a_.swap(r_sum_);
      break;
  }
  r_.swap(r_next_);
  // The accepted positions are where the next step's forces are read; velocity-verlet's were
  // exchanged before its second force evaluation.
  if (scheme_ != Integrator::velocity_verlet) halo_->exchange(r_);
  ++step_;
  time_ = static_cast<double>(step_) * dt_;
  return std::nullopt;
}

// verlet and tc-verlet: r⁺ = r + (r − r⁻) Δtₙ/Δtₙ₋₁ + Δtₙ² a with the velocity terms at the
// centre, v = (r⁺ − r⁻)/(Δtₙ + Δtₙ₋₁), solved in closed form (MODEL.md §4). With a constant
// step both are the plain central-difference Verlet.
void Stepper::verlet_step() {
  constraints_.hold_positions(r_prev_);  // a node held from now on starts at rest
  const VelocityTerms terms = dynamics_->free_acceleration(r_, step_, a_);
  const double dt2 = dt_ * dt_;
  const double ratio = dt_ / dt_previous_;
  const double span = dt_ + dt_previous_;
  const double c = terms.damping * dt2 / span;
  const double d = terms.fluid * dt2 / span;
  for_owned(*block_, [&](int k, int l) {
    const Vec3 r = r_(k, l), rp = r_prev_(k, l);
    Vec3 rhs = r + ratio * (r - rp) + dt2 * a_(k, l) + c * rp;
    if (d > 0.0) {
      const Vec3 n = dynamics_->normal(k, l);
      rhs += (d * dot(n, rp)) * n;
      r_next_(k, l) = solve_centred(rhs, n, c, d);
    } else {
      r_next_(k, l) = rhs / (1.0 + c);
    }
  });
  constraints_.hold_positions(r_next_);
}

// The published Verlet: velocity terms lagged, v = (r − r⁻)/Δt; first order (MODEL.md §4).
void Stepper::verlet_lagged_step() {
  constraints_.hold_positions(r_prev_);
  const double dt = dt_;
  for_owned(*block_, [&](int k, int l) { v_(k, l) = (r_(k, l) - r_prev_(k, l)) / dt; });
  dynamics_->acceleration(r_, v_, step_, a_);
  for_owned(*block_, [&](int k, int l) {
    r_next_(k, l) = 2.0 * r_(k, l) - r_prev_(k, l) + (dt * dt) * a_(k, l);
  });
  constraints_.hold_positions(r_next_);
}

// v^{n+½} = v^{n−½} + Δt A(rⁿ, v̄ⁿ), v̄ⁿ the mean of the two, in closed form; rⁿ⁺¹ = rⁿ + Δt v^{n+½}.
void Stepper::leapfrog_step() {
  const VelocityTerms terms = dynamics_->free_acceleration(r_, step_, a_);
  const double dt = dt_;
  const double c = 0.5 * dt * terms.damping;
  const double d = 0.5 * dt * terms.fluid;
  for_owned(*block_, [&](int k, int l) {
    const Vec3 v = v_(k, l);
    Vec3 rhs = (1.0 - c) * v + dt * a_(k, l);
    if (d > 0.0) {
      const Vec3 n = dynamics_->normal(k, l);
      rhs -= (d * dot(n, v)) * n;
      v_stage_(k, l) = solve_centred(rhs, n, c, d);
    } else {
      v_stage_(k, l) = rhs / (1.0 + c);
    }
  });
  constraints_.hold_velocities(v_stage_);
  for_owned(*block_, [&](int k, int l) { r_next_(k, l) = r_(k, l) + dt * v_stage_(k, l); });
  constraints_.hold_positions(r_next_);
}

// euler: r⁺ = r + Δt v, v⁺ = v + Δt A(r, v). symplectic-euler: v⁺ first, then r⁺ = r + Δt v⁺.
void Stepper::euler_step(bool symplectic) {
  dynamics_->acceleration(r_, v_, step_, a_);
  const double dt = dt_;
  for_owned(*block_, [&](int k, int l) { v_stage_(k, l) = v_(k, l) + dt * a_(k, l); });
  constraints_.hold_velocities(v_stage_);
  const Field<Vec3>& drift = symplectic ? v_stage_ : v_;
  for_owned(*block_, [&](int k, int l) { r_next_(k, l) = r_(k, l) + dt * drift(k, l); });
  constraints_.hold_positions(r_next_);
}

// RK2 midpoint on (r, v).
void Stepper::midpoint_step() {
  const double dt = dt_;
  dynamics_->acceleration(r_, v_, step_, a_);
  for_owned(*block_, [&](int k, int l) {
    r_stage_(k, l) = r_(k, l) + (0.5 * dt) * v_(k, l);
    v_stage_(k, l) = v_(k, l) + (0.5 * dt) * a_(k, l);
  });
  hold(r_stage_, v_stage_);
  halo_->exchange(r_stage_);
  dynamics_->acceleration(r_stage_, v_stage_, step_, a_);
  for_owned(*block_, [&](int k, int l) {
    r_next_(k, l) = r_(k, l) + dt * v_stage_(k, l);
    v_sum_(k, l) = v_(k, l) + dt * a_(k, l);
  });
  hold(r_next_, v_sum_);
}

// Classic RK4 on (r, v): stage derivatives accumulated with weights 1, 2, 2, 1.
void Stepper::rk4_step() {
  const double dt = dt_;
  dynamics_->acceleration(r_, v_, step_, a_);
  for_owned(*block_, [&](int k, int l) {
    r_sum_(k, l) = v_(k, l);
    v_sum_(k, l) = a_(k, l);
    r_stage_(k, l) = r_(k, l) + (0.5 * dt) * v_(k, l);
    v_stage_(k, l) = v_(k, l) + (0.5 * dt) * a_(k, l);
  });
  hold(r_stage_, v_stage_);
  for (const double fraction : {0.5, 1.0}) {
    halo_->exchange(r_stage_);
    dynamics_->acceleration(r_stage_, v_stage_, step_, a_);
    for_owned(*block_, [&](int k, int l) {
      const Vec3 vs = v_stage_(k, l), as = a_(k, l);
      r_sum_(k, l) += 2.0 * vs;
      v_sum_(k, l) += 2.0 * as;
      r_stage_(k, l) = r_(k, l) + (fraction * dt) * vs;
      v_stage_(k, l) = v_(k, l) + (fraction * dt) * as;
    });
    hold(r_stage_, v_stage_);
  }
  halo_->exchange(r_stage_);
  dynamics_->acceleration(r_stage_, v_stage_, step_, a_);
  for_owned(*block_, [&](int k, int l) {
    r_next_(k, l) = r_(k, l) + (dt / 6.0) * (r_sum_(k, l) + v_stage_(k, l));
    v_sum_(k, l) = v_(k, l) + (dt / 6.0) * (v_sum_(k, l) + a_(k, l));
  });
  hold(r_next_, v_sum_);
}

// r⁺ = r + Δt v + ½Δt² a; a⁺ = A(r⁺, v + Δt a); v⁺ = v + ½Δt (a + a⁺).
void Stepper::velocity_verlet_step() {
  const double dt = dt_;
  for_owned(*block_, [&](int k, int l) {
    r_next_(k, l) = r_(k, l) + dt * v_(k, l) + (0.5 * dt * dt) * a_(k, l);
    v_stage_(k, l) = v_(k, l) + dt * a_(k, l);
  });
  hold(r_next_, v_stage_);
  Field<Vec3>& a_next = r_sum_;
  halo_->exchange(r_next_);
  dynamics_->acceleration(r_next_, v_stage_, step_ + 1, a_next);
  for_owned(*block_, [&](int k, int l) {
    v_sum_(k, l) = v_(k, l) + (0.5 * dt) * (a_(k, l) + a_next(k, l));
  });
  constraints_.hold_velocities(v_sum_);
}

// The linearly implicit central-difference step (docs/semi-implicit.md): Verlet's update with
// the velocity terms at the centre and the internal force linearised about rⁿ,
// f_int(rⁿ⁺¹) ≈ f_int(rⁿ) + J δ, per unit mass:
//   [(1/Δt² + D/(2Δt)) I + F/(2Δt) n nᵀ − J] δ = a(rⁿ) + (1/Δt² − D/(2Δt)) d − F/(2Δt) (n·d) n
// with d = rⁿ − rⁿ⁻¹, δ = rⁿ⁺¹ − rⁿ. With J = 0 it is verlet_step's closed form.
std::optional<std::string> Stepper::semi_implicit_step() {
  constraints_.hold_positions(r_prev_);
  Field<Vec3>& d = r_stage_;
  Field<Vec3>& delta = v_stage_;
  implicit_->linearise(r_);
  // After the Jacobian, whose evaluations moved the normals the fluid terms read at rⁿ.
  const VelocityTerms terms = dynamics_->free_acceleration(r_, step_, a_);
  const double dt = dt_;
  const double lag = 1.0 / (dt * dt) - terms.damping / (2.0 * dt);
  const double fluid = terms.fluid / (2.0 * dt);
  Field<Vec3>& rhs = a_;
  for_owned(*block_, [&](int k, int l) {
    const Vec3 dk = r_(k, l) - r_prev_(k, l);
    d(k, l) = dk;
    Vec3 b = a_(k, l) + lag * dk;
    if (fluid > 0.0) {
      const Vec3 n = dynamics_->normal(k, l);
      b -= (fluid * dot(n, dk)) * n;
    }
    rhs(k, l) = b;
  });
  if (auto failure = implicit_->solve(terms, rhs, d, constraints_.state(), delta)) return failure;
  for_owned(*block_, [&](int k, int l) { r_next_(k, l) = r_(k, l) + delta(k, l); });
  constraints_.hold_positions(r_next_);
  return std::nullopt;
}

// MODEL.md §4.2: a position that is not finite, or a node that moved more than half a grid
// spacing. The first such node in (l, k) order is reported, the same for any thread count.
std::optional<Instability> Stepper::check(const Field<Vec3>& next) const {
  const Block& b = *block_;
  const double limit2 = max_move_ * max_move_;
  const long none = std::numeric_limits<long>::max();
  std::vector<long> first_bad(static_cast<std::size_t>(b.owned_l()), none);
  std::vector<char> not_finite(static_cast<std::size_t>(b.owned_l()), 0);
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l) {
    const auto row = static_cast<std::size_t>(l - b.l0);
    for (int k = b.k0; k < b.k1; ++k) {
      const Vec3 p = next(k, l);
      const Vec3 move = p - r_(k, l);
      const bool finite = is_finite(p);
      // Written so that a NaN displacement also fails.
      if (!finite || !(dot(move, move) <= limit2)) {
        first_bad[row] = static_cast<long>(l) * b.m + k;
        not_finite[row] = !finite;
        break;
      }
    }
  }
  long local = none;
  bool local_not_finite = false;
  for (std::size_t row = 0; row < first_bad.size(); ++row)
    if (first_bad[row] != none) {
      local = first_bad[row];
      local_not_finite = not_finite[row];
      break;
    }
  long global = local;
  MPI_Allreduce(&local, &global, 1, MPI_LONG, MPI_MIN, b.comm);
  if (global == none) return std::nullopt;
  int reason = global == local && local_not_finite ? 1 : 0;
  int any_reason = reason;
  MPI_Allreduce(&reason, &any_reason, 1, MPI_INT, MPI_MAX, b.comm);
  return Instability{step_ + 1, static_cast<double>(step_ + 1) * dt_, static_cast<int>(global % b.m),
                     static_cast<int>(global / b.m), any_reason != 0, std::nullopt};
}

std::vector<Stepper::StateField> Stepper::state_fields() {
  std::vector<StateField> fields{{"positions", &r_}};
  if (is_verlet_family(scheme_)) {
    fields.push_back({"previous_positions", &r_prev_});
  } else {
    fields.push_back({"velocities", &v_});
    if (scheme_ == Integrator::velocity_verlet) fields.push_back({"accelerations", &a_});
  }
  return fields;
}

void Stepper::resume(long step) {
  step_ = step;
  time_ = static_cast<double>(step_) * dt_;
  velocities_current_ = false;
  halo_->exchange(r_);
}

std::optional<LinearSolveStats> Stepper::linear_solves() const {
  if (!implicit_) return std::nullopt;
  return implicit_->stats();
}

const Field<Vec3>& Stepper::velocities() {
  if (!is_verlet_family(scheme_)) return v_;
  if (!velocities_current_) {
    const double dt = dt_previous_;
    for_owned(*block_, [&](int k, int l) { v_report_(k, l) = (r_(k, l) - r_prev_(k, l)) / dt; });
    velocities_current_ = true;
  }
  return v_report_;
}

}  // namespace cosserat
