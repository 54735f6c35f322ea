#pragma once
// The linear system of the semi-implicit step on PETSc (see cosserat/baseline/semi_implicit.hpp
// and docs/semi-implicit.md). Private to the baseline module, built only with PETSc.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/decomposition.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/constraints.hpp"
#include "cosserat/time/dynamics.hpp"
#include "cosserat/time/linear_solve_stats.hpp"

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

  // J at r: from the model's node Hessians (reads r's ghosts two nodes out), or, for a model
  // without them, by finite differences (the DMDA fills its own ghosts; 76 evaluations of the
  // internal force).
  void linearise(const Field<Vec3>& r);
  // Whether step `step` takes a new J: the first step of a run or of a restart, and every
  // step that is a multiple of time.solver.jacobian_every; the others reuse the last J and
  // its preconditioner.
  bool needs_jacobian(long step) const;

  // Solves the system for δ with the J of the last linearise(), velocity terms
  // `terms` (and the normals at rⁿ when there is a fluid), right-hand side `rhs`, starting
  // from `guess`. The components `held` lists get the δ that takes them from `positions` (rⁿ)
  // to their held value at `end_time`. Returns why the solve failed, or nothing.
  std::optional<std::string> solve(const VelocityTerms& terms, const Field<Vec3>* normals,
                                   const Field<Vec3>& rhs,
                                   const Field<Vec3>& guess,
                                   const std::vector<Constraints::NodeState>& held,
                                   const Field<Vec3>& positions, double end_time,
                                   Field<Vec3>& delta);

  const LinearSolveStats& stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cosserat
