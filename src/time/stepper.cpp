#include "cosserat/time/stepper.hpp"

#include "cosserat/time/adaptive_step.hpp"
#include "cosserat/time/failure_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace cosserat {

namespace {
// The scene's step, the first of a random sequence, or the first adaptive one: what the rest
// sheet at its initial velocity allows. The schemes build the history of their first step
// with it.
double first_step(const Scene& scene) {
  if (!scene.adaptive) return scene.dt;
  if (scene.adaptive->random) return AdaptiveSteps(scene).next(0.0, 0.0, 0.0, 0).dt;
  const StateMeasures rest{1.0, std::sqrt(dot(scene.initial_velocity, scene.initial_velocity))};
  const AdaptiveStep& a = *scene.adaptive;
  return std::max(a.min, std::min(a.max, a.safety * stability_estimate(scene, rest)));
}
}  // namespace

Stepper::Stepper(const Scene& scene, const Decomposition& decomposition, const Block& block,
                 Halo& halo, Dynamics& dynamics, const Field<Vec3>& positions,
                 Field<Vec3> velocities, const SchemeFactory& make)
    : block_(&block),
      halo_(&halo),
      dynamics_(&dynamics),
      constraints_(scene.fixes, block),
      dt_(first_step(scene)),
      h1_(scene.h1()),
      h2_(scene.h2()),
      max_move_(0.5 * std::min(scene.h1(), scene.h2())),
      edge_check_(block, max_move_) {
  const StepContext context{block, halo, dynamics, constraints_, dt_, 0.0, 0.0, &rows_};
  scheme_ = make(SchemeSetup{scene, decomposition, context, positions});
  scheme_->begin(std::move(velocities));
}

std::optional<Instability> Stepper::step() {
  return step(dt_, static_cast<double>(step_ + 1) * dt_);
}

std::optional<Instability> Stepper::step(double dt, double end_time) {
  scheme_->set_step(dt, time_, end_time);
  dynamics_->set_time(time_);
  constraints_.begin_step(step_, time_, scheme_->positions());
  const bool marked = std::all_of(actions_.begin(), actions_.end(),
                                  [](const auto& action) { return action->marks_moved_rows(); });
  // The edge test in the walk pays where the actions move few rows; where they moved most of
  // the last step's (cloth lying on a floor), testing those again cost more than one pass
  // after them (docs/contact.md, "Cost"). Either way the same rows are found.
  edge_check_.arm(marked && !moved_most_);
  // The actions' readers first: the contact moves nodes onto planes in the walk, and the edge
  // test reads where they end.
  rows_.clear();
  for (const auto& action : actions_)
    if (RowReader* reader = action->row_reader()) rows_.add(*reader);
  if (edge_check_.armed()) rows_.add(edge_check_);
  if (auto solver_failure = scheme_->advance(step_)) {
    return Instability{step_ + 1, end_time, -1, -1, false, std::move(solver_failure), {}};
  }
  set_velocities_.clear();
  const bool mark = marked && !actions_.empty();
  if (mark)
    moved_rows_.assign(static_cast<std::size_t>(block_->owned_l()), 0);
  else
    moved_rows_.clear();
  ProposedStep proposed{step_ + 1,       dt,    scheme_->positions(), scheme_->next_positions(),
                        scheme_->next_velocities(), time_, set_velocities_,
                        mark ? &moved_rows_ : nullptr, scheme_->next_starts()};
  for (const auto& action : actions_) action->apply(proposed);
  if (scheme_->has_stages() && !actions_.empty()) settle_stage_neighbours(proposed);
  if (mark)
    moved_most_ = 2 * std::count_if(moved_rows_.begin(), moved_rows_.end(),
                                    [](char moved) { return moved != 0; }) >
                  static_cast<long>(moved_rows_.size());
  // The check compares each node's move with its neighbours', across block borders too; the
  // accepted positions are then where the next step's forces are read.
  scheme_->exchange_next_positions(!actions_.empty());
  if (auto failure = check(scheme_->next_positions(), end_time)) return failure;
  scheme_->accept();
  if (!proposed.velocities.empty()) scheme_->set_velocities(proposed.velocities);
  for (const auto& action : actions_) action->accepted();
  ++step_;
  dt_ = dt;
  time_ = end_time;
  return std::nullopt;
}

// docs/contact.md, "Velocities": a scheme with stages reads its forces at states the response
// has not seen, where a node's neighbours in contact stand inside the solid. A node within the
// force's reach of one whose velocity an action set takes those forces into its velocity but
// barely into its move: beside a drape's contact on a box rk4 reported 1.4e-4 m/s at a node
// that moved 2e-9 m a step, a speed no position held, and the drape never came to rest. Such a
// node leaves with the velocity it moved at, (r⁺ − r)/Δt, as the nodes the response moved do.
// Every rank exchanges, with velocities set or none.
void Stepper::settle_stage_neighbours(ProposedStep& proposed) {
  const Block& b = *block_;
  if (velocity_set_.data() == nullptr) velocity_set_ = Field<Vec3>(b);
  for_owned(b, [&](int k, int l) { velocity_set_(k, l).x = 0.0; });
  proposed.velocities.for_each([&](const NodeVelocity& v) { velocity_set_(v.k, v.l).x = 1.0; });
  halo_->exchange(velocity_set_);
  const int reach = dynamics_->model().reach();
  const double rate = 1.0 / proposed.dt;
  for_owned(b, [&](int k, int l) {
    if (velocity_set_(k, l).x != 0.0) return;
    for (int l2 = std::max(0, l - reach); l2 <= std::min(b.n - 1, l + reach); ++l2)
      for (int k2 = std::max(0, k - reach); k2 <= std::min(b.m - 1, k + reach); ++k2)
        if (velocity_set_(k2, l2).x != 0.0) {
          proposed.velocities.push_back(
              {k, l, rate * (proposed.next_positions(k, l) - proposed.positions(k, l))});
          return;
        }
  });
}

Stepper::Snapshot Stepper::snapshot() {
  Snapshot s{step_, time_, dt_, {}, constraints_.state(), action_states()};
  for (const StateField& f : scheme_->state_fields()) s.fields.push_back(*f.field);
  return s;
}

std::vector<std::vector<double>> Stepper::action_states() const {
  std::vector<std::vector<double>> states;
  for (const auto& action : actions_) states.push_back(action->state());
  return states;
}

void Stepper::restore_action_states(const std::vector<std::vector<double>>& states) {
  for (std::size_t i = 0; i < actions_.size() && i < states.size(); ++i)
    actions_[i]->restore(states[i]);
}

void Stepper::restore(const Snapshot& s) {
  const std::vector<StateField> fields = scheme_->state_fields();
  // Values only: a snapshot's fields name the block of the run that took it, which may have
  // ended (a snapshot restored into another run of the same scene).
  for (std::size_t i = 0; i < fields.size(); ++i) fields[i].field->assign_values(s.fields[i]);
  constraints_.restore(s.constraints);
  restore_action_states(s.actions);
  resume(s.step, s.time, s.last_dt);
}

// docs/equations.md §4.2: a position that is not finite, or a node that moved more than half a grid
// spacing relative to a neighbour in one step: an edge of the grid changed by more than h/2.
// The published rule (docs/model.md, "Integrators") compares each node's move with zero, which
// stops a sheet in fast rigid motion (S1 in free fall, at t = 57 s) though nothing in it deforms;
// the unstable modes of an explicit step are the grid's highest, where neighbours move apart, and
// the relative move sees them (at twice the size: neighbours move oppositely). Of an edge that
// changed too much, the end that moved more is blamed (both ends on a tie); the first node blamed
// in (l, k) order is reported, the same for any thread count and decomposition, since the ghosts of
// both states are exchanged.
std::optional<Instability> Stepper::check(const Field<Vec3>& next, double end_time) {
  const Block& b = *block_;
  const Field<Vec3>& r = scheme_->positions();
  const double limit2 = max_move_ * max_move_;
  const long none = std::numeric_limits<long>::max();
  // Written so that a NaN also fails.
  // Neighbours a torn model parted (a broken spring) may fly apart.
  const ForceModel& model = dynamics_->model();
  auto too_far = [&](const Vec3& move, int k, int l, int k2, int l2) {
    if (model.parted(k, l, k2, l2)) return false;
    const Vec3 neighbour = next(k2, l2) - r(k2, l2);
    const Vec3 relative = move - neighbour;
    return !(dot(relative, relative) <= limit2) && !(dot(move, move) < dot(neighbour, neighbour));
  };
  auto fails = [&](int k, int l) {
    const Vec3 p = next(k, l);
    const Vec3 move = p - r(k, l);
    return !is_finite(p) || (k > 0 && too_far(move, k, l, k - 1, l)) ||
           (k + 1 < b.m && too_far(move, k, l, k + 1, l)) ||
           (l > 0 && too_far(move, k, l, k, l - 1)) ||
           (l + 1 < b.n && too_far(move, k, l, k, l + 1));
  };
  // A node fails only if one of its edges changed by more than the limit, or its position is
  // not finite (and then every edge of it fails the edge test too): only a row with such an
  // edge, which the edge test finds without an early exit (in the Verlet step while the rows
  // are still in cache), is scanned for its first failing node. Most steps flag none, and a
  // flagged row holds a failing node or neighbours one, so the scan is serial: threads started
  // for it would cost a step more than it does.
  const std::vector<char>& may_fail =
      edge_check_.flag_rows(r, next, moved_rows_.empty() ? nullptr : &moved_rows_);
  long local = none;
  bool local_not_finite = false;
  for (int l = b.l0; l < b.l1 && local == none; ++l) {
    if (!may_fail[static_cast<std::size_t>(l - b.l0)]) continue;
    for (int k = b.k0; k < b.k1; ++k)
      if (fails(k, l)) {
        local = static_cast<long>(l) * b.m + k;
        local_not_finite = !is_finite(next(k, l));
        break;
      }
  }
#if defined(COSSERAT_SMPI)
  // Folded fields hold no state to check (benchmarks/smpi): the reduction still runs, as in a
  // real step.
  if (smpi_fold_fields) local = none;
#endif
  long global = local;
  MPI_Allreduce(&local, &global, 1, MPI_LONG, MPI_MIN, b.comm);
  if (global == none) return std::nullopt;
  int reason = global == local && local_not_finite ? 1 : 0;
  int any_reason = reason;
  MPI_Allreduce(&reason, &any_reason, 1, MPI_INT, MPI_MAX, b.comm);
  const int k = static_cast<int>(global % b.m), l = static_cast<int>(global / b.m);
  return Instability{step_ + 1, end_time, k, l, any_reason != 0,
                     std::nullopt, diagnose_failure(r, k, l, h1_, h2_)};
}

void Stepper::resume(long step) { resume(step, static_cast<double>(step) * dt_, dt_); }

void Stepper::resume(long step, double time, double last_dt) {
  step_ = step;
  time_ = time;
  dt_ = last_dt;
  scheme_->resume(last_dt);
}

}  // namespace cosserat
