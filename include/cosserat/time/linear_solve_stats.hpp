#pragma once
// What the semi-implicit baseline's linear solves cost: kept by the solver, reported in the run
// summary.

namespace cosserat {

// On this rank (the run summary reports rank 0's; every rank takes part in every solve).
struct LinearSolveStats {
  long solves = 0;
  long iterations = 0;       // summed over the solves
  long most_iterations = 0;  // in one solve
  double jacobian_seconds = 0.0;
  long jacobians = 0;  // built; fewer than the solves with time.solver.jacobian_every > 1
  double solve_seconds = 0.0;
  double setup_seconds = 0.0;  // of solve_seconds, the preconditioner's set-up
};

}  // namespace cosserat
