#pragma once
// The explicit schemes that carry velocities (docs/equations.md §4), private to the time module:
// the factory in scheme.cpp is the only place that names them.

#include "cosserat/time/scheme.hpp"

namespace cosserat {

// Solves (1 + c) w + d (n·w) n = rhs for w, |n| = 1, by Sherman–Morrison: the centred
// damping and fluid terms of docs/equations.md §4 in closed form.
inline Vec3 solve_centred(const Vec3& rhs, const Vec3& n, double c, double d) {
  return (rhs - (d / (1.0 + c + d) * dot(n, rhs)) * n) / (1.0 + c);
}

// A scheme whose state is (r, v): v is the current velocity, next_velocity_ the proposed one.
class VelocityScheme : public Scheme {
 public:
  using Scheme::Scheme;
  void start(Field<Vec3> velocities) override;
  Field<Vec3>* next_velocities() override { return &next_velocity_; }
  const Field<Vec3>& velocities() override { return velocity_; }
  std::vector<StateField> state_fields() override;
  void set_velocities(const NodeVelocities& velocities) override {
    velocities.for_each([&](const NodeVelocity& v) { velocity_(v.k, v.l) = v.velocity; });
  }

 protected:
  void accept_state() override { velocity_.swap(next_velocity_); }

  Field<Vec3> velocity_;       // vⁿ (leapfrog: v^{n−½})
  Field<Vec3> next_velocity_;  // vⁿ⁺¹ (leapfrog: v^{n+½}), proposed
};

// v^{n+½} = v^{n−½} + Δt A(rⁿ, v̄ⁿ), v̄ⁿ the mean of the two, in closed form;
// rⁿ⁺¹ = rⁿ + Δt v^{n+½}. Starts with a half step back.
class Leapfrog final : public VelocityScheme {
 public:
  using VelocityScheme::VelocityScheme;
  void start(Field<Vec3> velocities) override;
  std::optional<std::string> advance(long step) override;

 private:
  void damped_springs_velocity(double c, double d);

  Field<Vec3> spring_force_;  // K(v^{n−½}), with a velocity force only
};

// euler: r⁺ = r + Δt v, v⁺ = v + Δt A(r, v). symplectic-euler: v⁺ first, then r⁺ = r + Δt v⁺.
class Euler final : public VelocityScheme {
 public:
  Euler(const StepContext& context, const Field<Vec3>& positions, bool symplectic)
      : VelocityScheme(context, positions), symplectic_(symplectic) {}
  std::optional<std::string> advance(long step) override;

 private:
  bool symplectic_;
};

// RK2 midpoint on (r, v).
class Midpoint final : public VelocityScheme {
 public:
  using VelocityScheme::VelocityScheme;
  bool has_stages() const override { return true; }
  void start(Field<Vec3> velocities) override;
  std::optional<std::string> advance(long step) override;

 private:
  Field<Vec3> midpoint_positions_, midpoint_velocity_;
};

// Classic RK4 on (r, v): stage derivatives accumulated with weights 1, 2, 2, 1.
class RungeKutta4 final : public VelocityScheme {
 public:
  using VelocityScheme::VelocityScheme;
  bool has_stages() const override { return true; }
  void start(Field<Vec3> velocities) override;
  std::optional<std::string> advance(long step) override;

 private:
  Field<Vec3> stage_positions_, stage_velocity_;
  Field<Vec3> velocity_sum_, acceleration_sum_;  // Σ weight × stage derivative
};

// r⁺ = r + Δt v + ½Δt² a; a⁺ = A(r⁺, v + Δt a); v⁺ = v + ½Δt (a + a⁺). The acceleration is
// part of the state: each step evaluates the forces once, at the new positions.
class VelocityVerlet final : public VelocityScheme {
 public:
  using VelocityScheme::VelocityScheme;
  void start(Field<Vec3> velocities) override;
  std::optional<std::string> advance(long step) override;
  std::vector<StateField> state_fields() override;

 protected:
  void accept_state() override;
  bool exchanged_next_positions() const override { return true; }

 private:
  Field<Vec3> predicted_velocity_;  // v + Δt a, where a⁺ is evaluated
  Field<Vec3> next_acceleration_;   // a⁺
};

}  // namespace cosserat
