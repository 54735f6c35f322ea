#pragma once
// The PETSc semi-implicit baseline (DESIGN.md module `baseline`): the linear
// system of the linearly implicit central-difference step, per unit mass
// (docs/semi-implicit.md),
//
//   [(1/Δt² + D/(2Δt)) I + F/(2Δt) n nᵀ − J] δ = b,   J = ∂(f_int/μ)/∂r at rⁿ,
//
// D = ϱ_D/μ and F = ϱ_R/μ the velocity terms taken at the step's centre, as the
// explicit Verlet does (MODEL.md §4). J comes from the explicit schemes' own
// force kernel by coloured finite differences on a DMDA laid over the same
// decomposition; held components are eliminated; KSP solves. Built only with
// PETSc: without it the scene loader refuses the integrator and these functions
// are never reached.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosserat/time/linear_solve_stats.hpp"
#include "cosserat/grid/block.hpp"
#include "cosserat/grid/decomposition.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/constraints.hpp"
#include "cosserat/time/dynamics.hpp"

namespace cosserat {

class SemiImplicitSolver {
 public:
  // Sets up the DMDA, Jacobian colouring and KSP from scene.solver, then
  // PETSc's options database (-ksp_*, -pc_*, ...). Starts PETSc on first use.
  // Throws SceneError for a KSP or PC name PETSc does not know.
  SemiImplicitSolver(const Scene& scene, const Decomposition& decomposition, const Block& block,
                     Dynamics& dynamics);
  ~SemiImplicitSolver();
  SemiImplicitSolver(const SemiImplicitSolver&) = delete;
  SemiImplicitSolver& operator=(const SemiImplicitSolver&) = delete;

  // J at r (owned nodes; the DMDA fills its own ghosts). Evaluates the internal
  // force about 76 times, so Dynamics::normal() is stale afterwards.
  void linearise(const Field<Vec3>& r);

  // Solves the system for δ with the J of the last linearise(), velocity terms
  // `terms` (normals from dynamics.normal()), right-hand side `rhs`, starting
  // from `guess`. The components `held` lists get δ = 0. Returns why the solve
  // failed, or nothing.
  std::optional<std::string> solve(const VelocityTerms& terms, const Field<Vec3>& rhs,
                                   const Field<Vec3>& guess,
                                   const std::vector<Constraints::NodeState>& held,
                                   Field<Vec3>& delta);

  const LinearSolveStats& stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Adds PETSc options (e.g. "-ksp_type cg -pc_type jacobi") for solvers made
// later, starting PETSc if needed. PETSC_OPTIONS in the environment is read
// too.
void add_petsc_options(const std::string& options);

// Ends PETSc if this process started it; before MPI_Finalize. Without PETSc,
// nothing.
void finalize_petsc();

}  // namespace cosserat
