// The semi-implicit step as a scheme of the Verlet family: Verlet's update with the internal
// force linearised about rⁿ (docs/semi-implicit.md), built only with PETSc.

#include "cosserat/baseline/semi_implicit.hpp"
#include "semi_implicit_solver.hpp"

namespace cosserat {

namespace {

class SemiImplicitScheme final : public VerletFamily {
 public:
  explicit SemiImplicitScheme(const SchemeSetup& setup)
      : VerletFamily(setup.context, setup.positions, Integrator::semi_implicit),
        solver_(setup.scene, setup.decomposition, setup.context.block, setup.context.dynamics),
        history_(setup.context.block),
        increment_(setup.context.block),
        right_hand_side_(setup.context.block) {}

  std::optional<LinearSolveStats> linear_solves() const override { return solver_.stats(); }

 protected:
  std::optional<std::string> propose(long step) override;

 private:
  SemiImplicitSolver solver_;
  Field<Vec3> history_;          // d = rⁿ − rⁿ⁻¹
  Field<Vec3> increment_;        // δ = rⁿ⁺¹ − rⁿ
  Field<Vec3> right_hand_side_;  // b
};

// The linearly implicit central-difference step: f_int(rⁿ⁺¹) ≈ f_int(rⁿ) + J δ, per unit mass
//   [(1/Δt² + D/(2Δt)) I + F/(2Δt) n nᵀ − J] δ = a(rⁿ) + (1/Δt² − D/(2Δt)) d − F/(2Δt) (n·d) n
// With J = 0 it is the centred Verlet step's closed form. semi-implicit-2 takes the force at
// the mean of rⁿ⁺¹ and rⁿ⁻¹ instead, f_int(rⁿ) + ½ J (δ − d): ½ J in the matrix, −½ J d on the
// right (the solver adds both).
std::optional<std::string> SemiImplicitScheme::propose(long step) {
  Constraints& constraints = context_.constraints;
  constraints.hold_positions(previous_positions_, previous_time(dt_previous_));
  if (solver_.needs_jacobian(step)) solver_.linearise(positions_);
  Field<Vec3>* n_field = normals();
  const VelocityTerms terms =
      context_.dynamics.free_acceleration(positions_, step, acceleration_, n_field);
  const double dt = context_.dt;
  const double lag = 1.0 / (dt * dt) - terms.damping / (2.0 * dt);
  const double fluid = terms.fluid / (2.0 * dt);
  for_owned(context_.block, [&](int k, int l) {
    const Vec3 dk = positions_(k, l) - previous_positions_(k, l);
    history_(k, l) = dk;
    Vec3 b = acceleration_(k, l) + lag * dk;
    if (fluid > 0.0) {
      const Vec3 n = (*n_field)(k, l);
      b -= (fluid * dot(n, dk)) * n;
    }
    right_hand_side_(k, l) = b;
  });
  if (auto failure = solver_.solve(terms, n_field, right_hand_side_, history_,
                                   constraints.state(), positions_, context_.end_time,
                                   increment_))
    return failure;
  for_owned(context_.block,
            [&](int k, int l) { next_positions_(k, l) = positions_(k, l) + increment_(k, l); });
  constraints.hold_positions(next_positions_, context_.end_time);
  return std::nullopt;
}

}  // namespace

std::unique_ptr<Scheme> any_scheme(const SchemeSetup& setup) {
  if (is_semi_implicit(setup.scene.integrator))
    return std::make_unique<SemiImplicitScheme>(setup);
  return explicit_scheme(setup);
}

}  // namespace cosserat
