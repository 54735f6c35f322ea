#include "cosserat/time/stepper.hpp"

#include "cosserat/time/failure_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace cosserat {

Stepper::Stepper(const Scene& scene, const Decomposition& decomposition, const Block& block,
                 Halo& halo, Dynamics& dynamics, const Field<Vec3>& positions,
                 Field<Vec3> velocities, const SchemeFactory& make)
    : block_(&block),
      constraints_(scene.fixes, block),
      dt_(scene.dt),
      h1_(scene.h1()),
      h2_(scene.h2()),
      max_move_(0.5 * std::min(scene.h1(), scene.h2())) {
  const StepContext context{block, halo, dynamics, constraints_, scene.dt};
  scheme_ = make(SchemeSetup{scene, decomposition, context, positions});
  scheme_->begin(std::move(velocities));
}

std::optional<Instability> Stepper::step() {
  constraints_.begin_step(step_, scheme_->positions());
  if (auto solver_failure = scheme_->advance(step_)) {
    return Instability{step_ + 1, static_cast<double>(step_ + 1) * dt_, -1, -1, false,
                       std::move(solver_failure), {}};
  }
  if (!actions_.empty()) {
    ProposedStep proposed{step_ + 1, dt_, scheme_->positions(), scheme_->next_positions(),
                          scheme_->next_velocities()};
    for (const auto& action : actions_) action->apply(proposed);
  }
  if (auto failure = check(scheme_->next_positions())) return failure;
  scheme_->accept();
  ++step_;
  time_ = static_cast<double>(step_) * dt_;
  return std::nullopt;
}

// MODEL.md §4.2: a position that is not finite, or a node that moved more than half a grid
// spacing. The first such node in (l, k) order is reported, the same for any thread count.
std::optional<Instability> Stepper::check(const Field<Vec3>& next) const {
  const Block& b = *block_;
  const Field<Vec3>& r = scheme_->positions();
  const double limit2 = max_move_ * max_move_;
  const long none = std::numeric_limits<long>::max();
  std::vector<long> first_bad(static_cast<std::size_t>(b.owned_l()), none);
  std::vector<char> not_finite(static_cast<std::size_t>(b.owned_l()), 0);
#pragma omp parallel for schedule(static)
  for (int l = b.l0; l < b.l1; ++l) {
    const auto row = static_cast<std::size_t>(l - b.l0);
    for (int k = b.k0; k < b.k1; ++k) {
      const Vec3 p = next(k, l);
      const Vec3 move = p - r(k, l);
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
  const int k = static_cast<int>(global % b.m), l = static_cast<int>(global / b.m);
  return Instability{step_ + 1, static_cast<double>(step_ + 1) * dt_, k, l, any_reason != 0,
                     std::nullopt, diagnose_failure(r, k, l, h1_, h2_)};
}

void Stepper::resume(long step) {
  step_ = step;
  time_ = static_cast<double>(step_) * dt_;
  scheme_->resume();
}

}  // namespace cosserat
