#pragma once
// The time integrators of docs/equations.md §4, one type per scheme family. Each owns the state it
// carries from one step to the next under the name of what it holds; the Stepper around it
// does what every scheme shares (constraint windows, per-step actions, the stability check,
// the step count).

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/decomposition.hpp"
#include "cosserat/contact/contact.hpp"
#include "cosserat/grid/halo.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/constraints.hpp"
#include "cosserat/time/dynamics.hpp"
#include "cosserat/time/linear_solve_stats.hpp"
#include "cosserat/time/row_walk.hpp"

namespace cosserat {

// Runs body(k, l) over the owned nodes, rows shared among threads. Bodies are elementwise (each
// writes only node (k, l)), so a row vectorises; a node computes the same whatever lane or
// remainder it falls in, which the decomposition tests check bitwise.
template <class Body>
void for_owned(const Block& b, Body&& body) {
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l)
#pragma omp simd
    for (int k = b.k0; k < b.k1; ++k) body(k, l);
}

// What every scheme works with: the block and its halo, the forces, the constraints it applies
// after every stage (docs/equations.md §4.1), and the step.
struct StepContext {
  const Block& block;
  Halo& halo;
  Dynamics& dynamics;
  Constraints& constraints;
  double dt;
  double time = 0.0;      // at the start of the step
  double end_time = 0.0;  // at its end, as the Stepper counts it (held positions move with it)
  // What reads r⁺ row by row while a scheme that finishes it so has the rows in cache (the
  // stability check's edge test, a contact's broad phase); null or empty where none does.
  RowWalk* rows = nullptr;
};

class Scheme {
 public:
  // A field that carries the scheme's state from one step to the next (for checkpoints).
  struct StateField {
    std::string name;
    Field<Vec3>* field;
  };

  Scheme(const StepContext& context, const Field<Vec3>& positions);
  virtual ~Scheme() = default;
  Scheme(const Scheme&) = delete;
  Scheme& operator=(const Scheme&) = delete;

  // Takes the velocities at step 0: holds the state at step 0 (the constraints of step 0
  // switched on), exchanges the positions' ghosts and builds the history the first step needs.
  void begin(Field<Vec3> velocities);

  // Proposes the state at step + 1 into next_positions() (and next_velocities()), held by the
  // constraints. Returns why a linear solve failed, or nothing.
  virtual std::optional<std::string> advance(long step) = 0;

  // Exchanges the proposed positions' ghosts, unless advance() did and nothing changed them
  // since (`changed`: a step action did). The stability check reads them.
  void exchange_next_positions(bool changed);

  // The proposed state, its positions' ghosts exchanged, becomes the current one.
  void accept();

  // After a restart overwrote the state fields: `last_dt` is the step that ended at the state.
  void resume(double last_dt);

  // After accept(): the listed owned nodes move on with these velocities (a contact
  // response's, docs/contact.md, "Velocities"): a scheme that carries velocities takes them, the
  // Verlet family rewrites r⁻ so that (r − r⁻)/Δt is the given velocity.
  virtual void set_velocities(const NodeVelocities& velocities) = 0;

  const Field<Vec3>& positions() const { return positions_; }
  Field<Vec3>& next_positions() { return next_positions_; }
  // The proposed velocities, for schemes that carry velocities; the others carry r⁻ instead,
  // so changing next_positions() changes their velocity too.
  virtual Field<Vec3>* next_velocities() { return nullptr; }
  // For the schemes that carry r⁻: the next step's r⁻ where this step's row walk wrote it
  // (RowReader::begin_walk: a node it settled on a plane starts from r⁺ − Δt v), or null when
  // that is the current positions; the velocity of a proposed node is (r⁺ − it)/Δt.
  virtual const Field<Vec3>* next_starts() const { return nullptr; }
  // Whether a step reads forces at intermediate states (midpoint, rk4), which the actions'
  // responses never see: a node beside a contact then takes its neighbours inside the solid
  // for real (Stepper::settle_stage_neighbours).
  virtual bool has_stages() const { return false; }

  // The velocity at the current time (see Stepper::velocities).
  virtual const Field<Vec3>& velocities() = 0;
  // The largest |v|² of velocities() over the owned nodes (the adaptive step's estimate reads
  // it before every step).
  virtual double max_speed2();

  // Together with the step index and the constraints' state, all a restart needs.
  virtual std::vector<StateField> state_fields() = 0;

  // The next step's size, start and end time, before every step.
  void set_step(double dt, double time, double end_time) {
    context_.dt = dt;
    context_.time = time;
    context_.end_time = end_time;
  }

  // The semi-implicit baseline's linear solves; nothing for the explicit schemes.
  virtual std::optional<LinearSolveStats> linear_solves() const { return std::nullopt; }

 protected:
  // Builds the history the first step needs (docs/equations.md §4) from the state at step 0, whose
  // positions are held and exchanged and whose velocities are held.
  virtual void start(Field<Vec3> velocities) = 0;
  // The family's own fields take their new values; accept() then swaps the positions.
  virtual void accept_state() = 0;
  // Whether advance() already exchanged the new positions' ghosts (velocity-verlet reads
  // forces there), so accept() need not.
  virtual bool exchanged_next_positions() const { return false; }
  // Called by resume(), after context_.dt became the step that ended at the state, for
  // families that cache something derived from the state.
  virtual void state_changed() {}

  // Where the fluid term's normals go, or null when the scene has no fluid.
  Field<Vec3>* normals() { return context_.dynamics.has_fluid() ? &normals_ : nullptr; }
  // Holds a state of the step at `fraction` of it (0: its start, 1: its end).
  void hold(Field<Vec3>& r, Field<Vec3>& v, double fraction) const;
  double stage_time(double fraction) const {
    return fraction == 1.0 ? context_.end_time : context_.time + fraction * context_.dt;
  }
  // rⁿ⁻¹ of the Verlet family belongs to the start of the previous step.
  double previous_time(double dt_previous) const { return context_.time - dt_previous; }

  StepContext context_;
  Field<Vec3> positions_;       // rⁿ
  Field<Vec3> next_positions_;  // rⁿ⁺¹, proposed
  Field<Vec3> acceleration_;    // of the last force evaluation
  Field<Vec3> normals_;         // allocated only with a fluid
};

// The Verlet family (verlet, tc-verlet, verlet-lagged): state (rⁿ, rⁿ⁻¹), no velocity carried.
// The semi-implicit baseline derives from it: its step is Verlet's with J added.
class VerletFamily : public Scheme {
 public:
  VerletFamily(const StepContext& context, const Field<Vec3>& positions, Integrator scheme);

  std::optional<std::string> advance(long step) final;
  void set_velocities(const NodeVelocities& velocities) override;
  const Field<Vec3>* next_starts() const override {
    return walked_starts_ ? &next_previous_ : nullptr;
  }
  // The backward difference (r − r⁻)/Δt: the velocity half a step back.
  const Field<Vec3>& velocities() override;
  double max_speed2() override;
  std::vector<StateField> state_fields() override;

 protected:
  void start(Field<Vec3> velocities) override;
  // The new positions from (rⁿ, rⁿ⁻¹): verlet-lagged's or the centred step.
  virtual std::optional<std::string> propose(long step);
  void accept_state() override;
  void state_changed() override {
    velocities_current_ = false;
    dt_previous_ = context_.dt;
  }

  Field<Vec3> previous_positions_;  // rⁿ⁻¹
  double dt_previous_;              // Δtₙ₋₁: the Stepper's last step

 private:
  void centred_step(long step);
  void damped_springs_step(double weight, double ratio, double span, double c, double d);
  void lagged_step(long step);

  bool published_;             // verlet-lagged: first-order start, velocity terms lagged
  Field<Vec3> lagged_velocity_;  // verlet-lagged: (rⁿ − rⁿ⁻¹)/Δt fed to the forces
  Field<Vec3> velocity_report_;  // what velocities() returns
  Field<Vec3> centred_velocity_;  // (r⁺ − r⁻)/(Δtₙ + Δtₙ₋₁), with a velocity force only
  bool velocities_current_ = false;
  // The next step's r⁻ as the step's row walk wrote it (RowReader::begin_walk), allocated
  // for the first walk that sets velocities; walked_starts_: this step's walk did.
  Field<Vec3> next_previous_;
  bool walked_starts_ = false;
};

// What a scheme is built from: the scene (the scheme and its settings), the decomposition the
// block comes from (the semi-implicit baseline lays its PETSc grid over it), the context and
// the positions at step 0.
struct SchemeSetup {
  const Scene& scene;
  const Decomposition& decomposition;
  const StepContext& context;
  const Field<Vec3>& positions;
};
using SchemeFactory = std::function<std::unique_ptr<Scheme>(const SchemeSetup&)>;

// The explicit schemes of this module. The semi-implicit one is the baseline module's
// (baseline/semi_implicit.hpp: any_scheme): asked for it, this throws std::logic_error.
std::unique_ptr<Scheme> explicit_scheme(const SchemeSetup& setup);

}  // namespace cosserat
