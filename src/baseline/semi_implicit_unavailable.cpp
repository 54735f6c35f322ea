// A build without PETSc: the scene loader refuses "semi-implicit" before a
// Simulation exists, so only the option and shutdown hooks are reachable here.

#include <stdexcept>

#include "cosserat/baseline/semi_implicit.hpp"

namespace cosserat {

struct SemiImplicitSolver::Impl {};

SemiImplicitSolver::SemiImplicitSolver(const Scene&, const Decomposition&, const Block&,
                                       Dynamics&) {
  throw std::logic_error("the semi-implicit integrator needs a build with PETSc");
}
SemiImplicitSolver::~SemiImplicitSolver() = default;
void SemiImplicitSolver::linearise(const Field<Vec3>&) {}
std::optional<std::string> SemiImplicitSolver::solve(const VelocityTerms&, const Field<Vec3>&,
                                                     const Field<Vec3>&,
                                                     const std::vector<Constraints::NodeState>&,
                                                     Field<Vec3>&) {
  return std::nullopt;
}
const LinearSolveStats& SemiImplicitSolver::stats() const {
  static const LinearSolveStats none;
  return none;
}

void add_petsc_options(const std::string& options) {
  if (!options.empty()) throw std::invalid_argument("this build has no PETSc to pass options to");
}
void finalize_petsc() {}

}  // namespace cosserat
