#pragma once
// The run summary: one JSON object whose keys are fixed by docs/design.md ("Interfaces") and listed
// in docs/output.md ("Run summary"), read by scripts that compare runs, so names and types here do
// not change.

#include <mpi.h>

#include <optional>
#include <string>

#include "cosserat/grid/vec3.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/linear_solve_stats.hpp"
#include "cosserat/time/simulation.hpp"
#include "cosserat/time/step_loop.hpp"

namespace cosserat {

struct RunSummary {
  std::string scene;
  int m = 0;
  int n = 0;
  int ranks = 1;
  int threads = 1;
  std::vector<long> thread_steps;  // rank 0's steps with 1, 2, ... threads (ThreadTuner)
  int parts_k = 1, parts_l = 1;  // the decomposition: blocks along k times along l
  std::string integrator;
  double dt = 0.0;
  long steps = 0;
  double sim_time = 0.0;
  double wall_seconds = 0.0;
  double node_steps_per_second = 0.0;
  double halo_seconds = 0.0;  // wall time in halo exchanges, the largest over the ranks
  std::optional<long> restarted_from;  // the checkpoint's step, for a restarted run
  std::string status;  // "ok" or "unstable"
  std::optional<long> unstable_step;
  double area_ratio = 0.0;  // S / S0 at the end
  double max_speed = 0.0;
  std::string discretisation;  // "energy", "energy-nodal", "flux", or "mass-spring" (that model)
  double kinetic_energy = 0.0;
  double elastic_energy = 0.0;        // E of docs/equations.md §2.5 (for the flux form too)
  double gravitational_energy = 0.0;  // −Σ m g·r
  Vec3 center_of_mass;
  std::string output;  // the HDF5 file written
  std::optional<LinearSolveStats> linear_solves;  // semi-implicit only
  std::optional<RestSummary> rest;                  // with --until-rest only
  std::optional<AdaptiveSummary> adaptive;          // with adaptive steps only (dt is null)
  // With solids only (docs/output.md, "Run summary"): the run's contact maxima and each solid's
  // final state.
  std::optional<ContactSummary> contact;
  struct SolidReport {
    std::string name;
    std::string motion;
    SolidState state;
  };
  std::vector<SolidReport> solids;
  // With [self_contact] only: the most pairs held in one step and the closest a held pair came.
  std::optional<SelfContactSummary> self_contact;
};

// How a run was laid out and where it wrote, beside what its scene and step loop say.
struct RunPlacement {
  int ranks = 1;
  int threads = 1;
  int parts_k = 1, parts_l = 1;
  std::string output;
  std::optional<long> restarted_from;
};

// The summary of a run that ended as `loop` says; collective over comm, since the diagnostics
// and the halo time are reduced over the ranks.
RunSummary summarize_run(const Scene& scene, Simulation& simulation, const StepLoopResult& loop,
                         const RunPlacement& placement, MPI_Comm comm);

// Non-finite numbers and an empty unstable_step are written as null, since JSON has no NaN.
std::string to_json(const RunSummary& summary);

// Throws std::runtime_error naming path when the file cannot be written.
void write_summary(const std::string& path, const RunSummary& summary);

}  // namespace cosserat
