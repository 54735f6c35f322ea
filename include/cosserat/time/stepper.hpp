#pragma once
// The step of docs/equations.md §4 for any scheme: the constraint windows of §4.1, the per-step
// actions, the stability monitor of §4.2 and the step count around one Scheme.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/decomposition.hpp"
#include "cosserat/grid/halo.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/constraints.hpp"
#include "cosserat/time/dynamics.hpp"
#include "cosserat/time/edge_check.hpp"
#include "cosserat/time/row_walk.hpp"
#include "cosserat/time/scheme.hpp"

namespace cosserat {

// Where and when a run became unstable (docs/equations.md §4.2), or the semi-implicit step's linear
// solver failed (then k and l are -1).
struct Instability {
  long step;    // the step whose new state failed the check
  double time;  // its time
  int k, l;
  bool not_finite;  // else: moved more than half a grid spacing
  std::optional<std::string> solver_failure;
  std::string diagnosis;  // what the last good state looks like near node (k, l)
};

// The state a step proposes, before the stability check accepts it.
struct ProposedStep {
  long step;  // the step it ends at
  double dt;
  const Field<Vec3>& positions;  // at the step's start
  Field<Vec3>& next_positions;
  Field<Vec3>* next_velocities;  // null for schemes that carry r⁻ instead (see Scheme)
  double time = 0.0;             // at the step's start
  // Nodes whose velocity an action set (a contact response): the scheme carries these into
  // its next step, whether it holds velocities or r⁻ (Scheme::set_velocities). The stepper's,
  // emptied for each step: a contact scene sets up to every node's, and allocating them every
  // step cost more than the response itself.
  NodeVelocities& velocities;
  // Per owned row, 0 on entry: an action that marks_moved_rows() sets the rows it moved nodes
  // of, so that the stability check tests only those again. Null when no check needs them.
  std::vector<char>* moved_rows = nullptr;
  // Schemes that carry r⁻: Scheme::next_starts, null where it is `positions`.
  const Field<Vec3>* starts = nullptr;
};

// Something done on every step whatever the scheme (a contact response, a step-size choice):
// the one place such an action hooks in. It sees the proposed state after the scheme and its
// constraints, before the stability check.
class StepAction {
 public:
  virtual ~StepAction() = default;
  virtual void apply(ProposedStep& proposed) = 0;
  // The step apply() saw passed the check and is now the current state.
  virtual void accepted() {}
  // State the action carries from step to step (a free body's motion), as numbers: part of
  // roll-back snapshots and checkpoints; restore() takes what state() gave.
  virtual std::vector<double> state() const { return {}; }
  virtual void restore(const std::vector<double>& /*values*/) {}
  // What reads the scheme's rows as its walk finishes them (RowReader), or null.
  virtual RowReader* row_reader() { return nullptr; }
  // Whether apply() marks every row it moved a node of in ProposedStep::moved_rows (moves its
  // row_reader() made in the walk need no mark). Only when every action does may the stability
  // check's edge test run in the walk, before them.
  virtual bool marks_moved_rows() const { return false; }
};

class Stepper {
 public:
  // Takes the state at step 0: positions, velocities. Builds the scheme with `make` (the
  // explicit schemes of this module, or the baseline's any_scheme); the decomposition is the
  // one `block` and `halo` come from.
  Stepper(const Scene& scene, const Decomposition& decomposition, const Block& block, Halo& halo,
          Dynamics& dynamics, const Field<Vec3>& positions, Field<Vec3> velocities,
          const SchemeFactory& make);
  Stepper(const Stepper&) = delete;
  Stepper& operator=(const Stepper&) = delete;

  // Advances one step of the scene's fixed size. On instability the state is left at the last
  // good step and the failure is returned.
  std::optional<Instability> step();
  // Advances one step of size dt that ends at `end_time`: time() + dt, or a frame's time the
  // step was cut to reach exactly (adaptive steps). As step() otherwise.
  std::optional<Instability> step(double dt, double end_time);

  // The whole state in memory, for adaptive steps to roll back to.
  struct Snapshot {
    long step = 0;
    double time = 0.0;
    double last_dt = 0.0;
    std::vector<Field<Vec3>> fields;
    std::vector<Constraints::NodeState> constraints;
    std::vector<std::vector<double>> actions;  // each action's state()
  };
  Snapshot snapshot();
  void restore(const Snapshot& snapshot);

  // Runs `action` on every later step, after those added before it.
  void add_action(std::unique_ptr<StepAction> action) { actions_.push_back(std::move(action)); }

  using StateField = Scheme::StateField;
  // The fields that carry the scheme's state from one step to the next: together with the step
  // index, the time, the last step and the constraints' state, all a restart needs to continue
  // bitwise.
  std::vector<StateField> state_fields() { return scheme_->state_fields(); }
  Constraints& constraints() { return constraints_; }
  // Each action's state() in the order added, and back (checkpoints).
  std::vector<std::vector<double>> action_states() const;
  void restore_action_states(const std::vector<std::vector<double>>& states);
  // Continues from `step` after the state was overwritten; with a fixed step the time is
  // step x dt, adaptive steps give the time and the size of the step that ended there.
  void resume(long step);
  void resume(long step, double time, double last_dt);

  long step_index() const { return step_; }
  double time() const { return time_; }
  // The size of the last step taken (the scene's step before the first).
  double last_dt() const { return dt_; }
  const Field<Vec3>& positions() const { return scheme_->positions(); }
  // The scheme's velocity at the current time; for the Verlet family, which carries none,
  // the backward difference (r − r⁻)/Δt, the velocity half a step back.
  const Field<Vec3>& velocities() { return scheme_->velocities(); }
  // The largest |v|² of velocities() over the owned nodes.
  double max_speed2() { return scheme_->max_speed2(); }

  // The semi-implicit baseline's linear solves so far; nothing for the explicit schemes.
  std::optional<LinearSolveStats> linear_solves() const { return scheme_->linear_solves(); }

 private:
  std::optional<Instability> check(const Field<Vec3>& next, double end_time);
  void settle_stage_neighbours(ProposedStep& proposed);

  const Block* block_;
  Halo* halo_;
  Dynamics* dynamics_;
  Constraints constraints_;
  double dt_;
  double h1_, h2_;
  double max_move_;  // half the smaller grid spacing (docs/equations.md §4.2)
  EdgeCheck edge_check_;
  RowWalk rows_;                 // this step's readers of the scheme's row walk
  std::vector<char> moved_rows_;  // ProposedStep::moved_rows
  bool moved_most_ = false;       // the last step's actions moved most rows
  long step_ = 0;
  double time_ = 0.0;
  std::unique_ptr<Scheme> scheme_;
  std::vector<std::unique_ptr<StepAction>> actions_;
  NodeVelocities set_velocities_;  // ProposedStep::velocities
  Field<Vec3> velocity_set_;       // x: 1 where an action set a node's velocity (stage schemes)
};

}  // namespace cosserat
