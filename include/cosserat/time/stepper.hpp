#pragma once
// The explicit time integrators of MODEL.md §4, each applying the constraints of §4.1 after
// every stage, and the stability monitor of §4.2.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosserat/baseline/semi_implicit.hpp"
#include "cosserat/grid/block.hpp"
#include "cosserat/grid/decomposition.hpp"
#include "cosserat/grid/halo.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/constraints.hpp"
#include "cosserat/time/dynamics.hpp"

namespace cosserat {

// Where and when a run became unstable (MODEL.md §4.2), or the semi-implicit step's linear
// solver failed (then k and l are -1).
struct Instability {
  long step;    // the step whose new state failed the check
  double time;  // its time
  int k, l;
  bool not_finite;  // else: moved more than half a grid spacing
  std::optional<std::string> solver_failure;
};

class Stepper {
 public:
  // Takes the state at step 0: positions, velocities. Exchanges the ghosts of every position
  // field before the forces read it. The decomposition is the one `block` and `halo` come
  // from; the semi-implicit baseline lays its PETSc grid over it.
  Stepper(const Scene& scene, const Decomposition& decomposition, const Block& block, Halo& halo,
          Dynamics& dynamics, const Field<Vec3>& positions, const Field<Vec3>& velocities);

  // Advances one step. On instability the state is left at the last good step and the
  // failure is returned.
  std::optional<Instability> step();

  // The fields that carry the scheme's state from one step to the next: together with the
  // step index and the constraints' state, all a restart needs to continue bitwise.
  struct StateField {
    std::string name;
    Field<Vec3>* field;
  };
  std::vector<StateField> state_fields();
  Constraints& constraints() { return constraints_; }
  // Continues from `step` after the state fields and constraints were overwritten.
  void resume(long step);

  long step_index() const { return step_; }
  double time() const { return time_; }
  const Field<Vec3>& positions() const { return r_; }
  // The scheme's velocity at the current time; for the Verlet family, which carries none,
  // the backward difference (r − r⁻)/Δt, the velocity half a step back.
  const Field<Vec3>& velocities();

  // The semi-implicit baseline's linear solves so far; nothing for the explicit schemes.
  std::optional<LinearSolveStats> linear_solves() const;

 private:
  void start();
  void verlet_step();
  void verlet_lagged_step();
  void leapfrog_step();
  void euler_step(bool symplectic);
  void midpoint_step();
  void rk4_step();
  void velocity_verlet_step();
  std::optional<std::string> semi_implicit_step();
  std::optional<Instability> check(const Field<Vec3>& next) const;
  void hold(Field<Vec3>& r, Field<Vec3>& v) const;

  const Block* block_;
  Halo* halo_;
  Dynamics* dynamics_;
  Constraints constraints_;
  Integrator scheme_;
  double dt_;
  double dt_previous_;  // Δt_{n−1} of tc-verlet; the scene's step is constant
  double max_move_;     // half the smaller grid spacing (MODEL.md §4.2)
  long step_ = 0;
  double time_ = 0.0;

  Field<Vec3> r_, v_;   // current state (v: v^{n−½} for leapfrog)
  Field<Vec3> r_next_;  // the new positions before acceptance
  Field<Vec3> r_prev_;  // Verlet family: r⁻
  Field<Vec3> a_;       // acceleration (velocity-verlet keeps it across steps)
  Field<Vec3> r_stage_, v_stage_, r_sum_, v_sum_;  // Runge–Kutta stages
  std::unique_ptr<SemiImplicitSolver> implicit_;
  bool velocities_current_ = false;
  Field<Vec3> v_report_;
};

}  // namespace cosserat
