#pragma once
// The PETSc semi-implicit baseline (docs/design.md, "Modules": `baseline`): the linear
// system of the linearly implicit central-difference step (docs/semi-implicit.md),
//
//   [(1/Δt² + D/(2Δt)) I + F/(2Δt) n nᵀ − J] δ = b,   J = ∂(f_int/μ)/∂r at rⁿ,
//
// (½ J, and −½ J d in b, for semi-implicit-2), D = ϱ_D/μ and F = ϱ_R/μ the velocity terms
// taken at the step's centre, as the explicit Verlet does (docs/equations.md §4). J is
// assembled from the model's exact node Hessians where it has them (the energy form; the system
// is then solved times the node weights, symmetric), otherwise from the explicit schemes' own
// force kernel by coloured finite differences on a DMDA laid over the same decomposition; held
// components are eliminated; KSP solves. Without PETSc the scene loader refuses the
// integrators, and any_scheme builds the explicit ones.

#include <memory>
#include <string>

#include "cosserat/time/scheme.hpp"

namespace cosserat {

// The scheme a scene asks for: the semi-implicit baseline for "semi-implicit", the time
// module's explicit schemes for the others. Whoever assembles a Simulation passes this to run
// every scheme this build has.
std::unique_ptr<Scheme> any_scheme(const SchemeSetup& setup);

// The Krylov method and preconditioner of a [time.solver] that names none: cg with hypre's
// BoomerAMG for an exact, symmetric Jacobian on a grid of at least 240 × 240 nodes, where
// block Jacobi needs hundreds of iterations and from 480 × 480 on does not converge, and
// PETSc's own smoothed aggregation (gamg) fails once the sheet has deformed; gmres with block
// Jacobi (ILU(0) blocks) otherwise, and where PETSc was built without hypre
// (docs/semi-implicit.md, "Preconditioners, against grid size").
struct KrylovChoice {
  std::string ksp, pc;
};
KrylovChoice default_linear_solver(bool exact_jacobian, long nodes, bool have_hypre);

// Adds PETSc options (e.g. "-ksp_type cg -pc_type jacobi") for solvers made
// later, starting PETSc if needed. PETSC_OPTIONS in the environment is read
// too.
void add_petsc_options(const std::string& options);

// Ends PETSc if this process started it; before MPI_Finalize. Without PETSc,
// nothing.
void finalize_petsc();

}  // namespace cosserat
