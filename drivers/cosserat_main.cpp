// The `cosserat` command line (docs/design.md, "Interfaces"): owns MPI, the options and the files;
// the step loop (time/step_loop.hpp) says when a frame or a checkpoint is due.

#include <mpi.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fmt/core.h>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cosserat/baseline/semi_implicit.hpp"
#include "cosserat/grid/decomposition.hpp"
#include "cosserat/grid/reduce.hpp"
#include "cosserat/grid/threads.hpp"
#include "cosserat/io/checkpoint.hpp"
#include "cosserat/io/frame_writer.hpp"
#include "cosserat/io/output_fields.hpp"
#include "cosserat/io/output_lock.hpp"
#include "cosserat/io/stable_dt_table.hpp"
#include "cosserat/io/summary.hpp"
#include "cosserat/model/force_model.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/simulation.hpp"
#include "cosserat/time/stability.hpp"
#include "cosserat/time/step_loop.hpp"

#if defined(COSSERAT_TRAP_FPE)
#include <cfenv>
#endif

namespace {

// Exit statuses of docs/design.md, "Interfaces".
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitUnstable = 3;

using Clock = std::chrono::steady_clock;

struct RunOptions {
  std::string scene_path;
  std::vector<std::string> overrides;
  std::string output;
  std::string summary;
  std::string restart;
  long checkpoint_every = 0;
  std::optional<double> until_rest;
  std::optional<int> threads;
  bool quiet = false;
  bool overwrite = false;
};

struct StableDtOptions {
  std::string scene_path;
  std::vector<std::string> overrides;
  std::vector<std::string> integrators;
  std::optional<double> duration;
  double tolerance = 0.02;
  std::string csv;
  std::optional<int> threads;
  bool quiet = false;
};

// One line, rewritten in place, while the run goes: only on a terminal. The ETA is from
// simulated time, which adaptive steps cover at a varying rate of steps.
class Progress {
 public:
  Progress(long first_step, double first_time, double duration, bool enabled)
      : first_step_(first_step),
        first_time_(first_time),
        duration_(duration),
        enabled_(enabled),
        start_(Clock::now()),
        last_(start_) {}

  void update(long step, double time) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (now - last_ < std::chrono::milliseconds(200) && time < duration_) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0.0 ? static_cast<double>(step - first_step_) / elapsed : 0.0;
    const double covered = time - first_time_;
    const double eta = covered > 0.0 ? (duration_ - time) * elapsed / covered : 0.0;
    fmt::print(stderr, "\rstep {}  t = {:.4f} / {} s  {:.0f} steps/s  ETA {:.0f} s   ", step,
               time, duration_, rate, eta);
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) fmt::print(stderr, "\n");
  }

 private:
  long first_step_;
  double first_time_, duration_;
  bool enabled_;
  Clock::time_point start_, last_;
};

// The solids as the output draws them: each surface in its own frame (a plane as a square
// twice the sheet's size), and where each is now.
std::vector<cosserat::SolidOutline> solid_outlines(const cosserat::Simulation& simulation,
                                                   const cosserat::Scene& scene) {
  std::vector<cosserat::SolidOutline> outlines;
  if (const cosserat::Contact* contact = simulation.contact())
    for (std::size_t i = 0; i < contact->size(); ++i)
      outlines.push_back({contact->spec(i).name,
                          contact->geometry(i).surface(2.0 * std::max(scene.size1, scene.size2))});
  return outlines;
}

std::vector<cosserat::Pose> solid_poses(const cosserat::Simulation& simulation) {
  std::vector<cosserat::Pose> poses;
  if (const cosserat::Contact* contact = simulation.contact())
    for (std::size_t i = 0; i < contact->size(); ++i) poses.push_back(contact->state(i).pose);
  return poses;
}

// The step loop says when a frame or a checkpoint is due; the files and the progress line are
// the command line's.
class RunObserver : public cosserat::StepObserver {
 public:
  RunObserver(cosserat::Simulation& simulation, const cosserat::Scene& scene,
              cosserat::FrameWriter& writer, const std::string& checkpoint, Progress& progress)
      : simulation_(simulation),
        scene_(scene),
        writer_(writer),
        fields_(simulation.block(), scene.output_fields),
        checkpoint_(checkpoint),
        progress_(progress) {}

  void frame() override {
    writer_.write_frame(simulation_.step_index(), simulation_.time(), simulation_.positions(),
                        solid_poses(simulation_), fields_.evaluate(simulation_));
  }
  void checkpoint(const cosserat::LoopCarry& carry) override {
    cosserat::write_checkpoint(
        checkpoint_, simulation_, scene_, COSSERAT_VERSION,
        carry.rest ? std::optional(carry.rest->peak_kinetic_energy) : std::nullopt,
        carry.adaptive_scale);
  }
  void progress(long step) override { progress_.update(step, simulation_.time()); }

 private:
  cosserat::Simulation& simulation_;
  const cosserat::Scene& scene_;
  cosserat::FrameWriter& writer_;
  cosserat::OutputFieldValues fields_;
  const std::string& checkpoint_;
  Progress& progress_;
};

std::string default_output(const cosserat::Scene& scene) { return scene.name + ".h5"; }

std::string describe(const cosserat::Instability& failure) {
  if (failure.solver_failure) return *failure.solver_failure;
  return fmt::format("node [{}, {}] {}; {}", failure.k, failure.l,
                     failure.not_finite ? "has a non-finite position"
                                        : "moved more than half a grid spacing from a neighbour in one step",
                     failure.diagnosis);
}

// Memory of every rank on this node, against the node's physical memory.
bool fits_in_memory(const cosserat::Scene& scene, const cosserat::Block& block, int rank) {
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
  const auto scalar_fields = static_cast<std::size_t>(
      std::ranges::count_if(scene.output_fields, [](cosserat::OutputField field) {
        return !cosserat::node_field(field).vector;
      }));
  const double mine = cosserat::Simulation::memory_bytes(
      block, scene.integrator, scene.model_spec(), scalar_fields, scene.solids,
      scene.self_contact.has_value());
  double needed = 0.0;
  MPI_Allreduce(&mine, &needed, 1, MPI_DOUBLE, MPI_SUM, node);
  int node_rank = 0;
  MPI_Comm_rank(node, &node_rank);
  MPI_Comm_free(&node);
  const double available = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * sysconf(_SC_PAGE_SIZE);
  int fits = needed <= available ? 1 : 0;
  if (!fits && node_rank == 0)
    fmt::print(stderr,
               "error: {}: a {} x {} grid needs about {:.1f} GiB on this node, more than its "
               "{:.1f} GiB; use more nodes\n",
               scene.path, scene.m, scene.n, needed / (1 << 30), available / (1 << 30));
  int all_fit = fits;
  MPI_Allreduce(&fits, &all_fit, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all_fit != 0;
}

// Threads are set before the simulation is built, so that its fields are first touched by the
// threads that will work on them.
cosserat::ThreadPlacement set_threads(const cosserat::Decomposition& decomposition,
                                      std::optional<int> requested, int rank) {
  const cosserat::ThreadPlacement placement = cosserat::place_threads(
      MPI_COMM_WORLD, decomposition.block(rank, MPI_COMM_WORLD).owned_l(), requested);
  if (rank == 0 && placement.oversubscribed())
    fmt::print(stderr,
               "warning: {} rank{} on a node of {} cores run {} threads in all: threads wait "
               "for cores and every step waits for them (docs/parallel.md); give fewer threads "
               "(--threads or OMP_NUM_THREADS) or fewer ranks\n",
               placement.node_ranks, placement.node_ranks == 1 ? "" : "s", placement.node_cores,
               placement.node_threads);
  else if (rank == 0 && !placement.requested && placement.idle_cpus > 0)
    fmt::print(stderr,
               "note: {} CPU{} of a node {} in no rank's affinity mask (mpirun binds each "
               "rank to one core by default) and stay{} idle; to use {}, run mpirun with "
               "--map-by slot:PE=<threads per rank> or --bind-to none (docs/parallel.md)\n",
               placement.idle_cpus, placement.idle_cpus == 1 ? "" : "s",
               placement.idle_cpus == 1 ? "is" : "are", placement.idle_cpus == 1 ? "s" : "",
               placement.idle_cpus == 1 ? "it" : "them");
  return placement;
}

// Runs `work` and turns the bad input it reports into a message from rank 0: exit status 2, or
// nothing when all went well. Every rank finds the same bad input, so all return together.
template <class Work>
std::optional<int> bad_input(const std::string& scene_path, int rank, Work&& work) {
  try {
    work();
  } catch (const cosserat::SceneError& e) {
    if (rank == 0) fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadInput;
  } catch (const cosserat::DecompositionError& e) {
    if (rank == 0) fmt::print(stderr, "error: {}: {}\n", scene_path, e.what());
    return kExitBadInput;
  }
  return std::nullopt;
}

// The files a run will write, checked before any work (docs/design.md, principle 6): none may be
// the scene, the checkpoint it restarts from (but its own checkpoint, which a restart continues) or
// another of them; each must be a plain file in a folder that takes one; none may hold an
// earlier run's results unless the run is told to overwrite them or restarts. Returns what is
// wrong, or nothing.
std::optional<std::string> output_conflict(const RunOptions& options, const std::string& output) {
  namespace fs = std::filesystem;
  struct Named {
    std::string what, path;
  };
  std::vector<Named> written{{"--output", output}, {"the XDMF file", cosserat::xdmf_path(output)}};
  if (options.checkpoint_every > 0)
    written.push_back({"the checkpoint", cosserat::checkpoint_path(output)});
  if (!options.summary.empty()) written.push_back({"--summary", options.summary});
  std::vector<Named> read{{"the scene file", options.scene_path}};
  if (!options.restart.empty()) read.push_back({"--restart", options.restart});
  auto same = [](const std::string& a, const std::string& b) {
    std::error_code error;
    if (fs::exists(a, error) && fs::exists(b, error)) return fs::equivalent(a, b, error);
    return fs::weakly_canonical(a, error) == fs::weakly_canonical(b, error);
  };
  for (std::size_t i = 0; i < written.size(); ++i) {
    // A device (-o /dev/null) or a folder in the way: HDF5 and the renames of the XDMF and
    // checkpoint files need a plain file there.
    std::error_code error;
    if (fs::exists(written[i].path, error) && !fs::is_regular_file(written[i].path, error))
      return fmt::format("{} ({}) exists and is not a regular file", written[i].what,
                         written[i].path);
    const fs::path folder = fs::absolute(written[i].path).parent_path();
    if (!fs::is_directory(folder, error) || access(folder.c_str(), W_OK) != 0)
      return fmt::format("{} ({}): cannot write a file in {}", written[i].what, written[i].path,
                         folder.string());
    for (const Named& input : read) {
      const bool continues_its_checkpoint =
          written[i].what == "the checkpoint" && input.what == "--restart";
      if (!continues_its_checkpoint && same(written[i].path, input.path))
        return fmt::format("{} ({}) would be written over {} ({}); name another output",
                           written[i].what, written[i].path, input.what, input.path);
    }
    for (std::size_t j = 0; j < i; ++j)
      if (same(written[i].path, written[j].path))
        return fmt::format("{} and {} would be the same file ({}); name another",
                           written[j].what, written[i].what, written[i].path);
  }
  // An earlier run's results are not replaced unasked. A restart continues its own output (and
  // writes its XDMF file, checkpoint and summary again); an empty file holds nothing to lose (a
  // run killed between taking its lock and creating the HDF5 file leaves one).
  if (options.overwrite || !options.restart.empty()) return std::nullopt;
  for (const Named& file : written) {
    std::error_code error;
    if (!fs::exists(file.path, error) || fs::file_size(file.path, error) == 0) continue;
    const std::string checkpoint = cosserat::checkpoint_path(output);
    const std::string restart =
        fs::exists(checkpoint, error)
            ? fmt::format(", or continue that run with --restart {}", checkpoint)
            : "";
    return fmt::format(
        "{} ({}) exists, from an earlier run; pass --overwrite to replace it, or name another "
        "{}{}",
        file.what, file.path, file.what == "--summary" ? "--summary" : "--output", restart);
  }
  return std::nullopt;
}

int run(const RunOptions& options, int rank, int ranks) {
  using namespace cosserat;
  Scene scene;
  std::optional<Decomposition> decomposition;
  if (const auto status = bad_input(options.scene_path, rank, [&] {
        scene = load_scene(options.scene_path, options.overrides);
        decomposition = Decomposition::choose(scene.m, scene.n, ranks);
      }))
    return *status;
  if (rank == 0)
    for (const std::string& warning : scene.warnings) fmt::print(stderr, "warning: {}\n", warning);
  if (!fits_in_memory(scene, decomposition->block(rank, MPI_COMM_WORLD), rank))
    return kExitBadInput;
  const std::string output = options.output.empty() ? default_output(scene) : options.output;
  // Rank 0 looks and tells the others, so that all return together even where the ranks' file
  // systems differ.
  int conflicting = 0;
  if (rank == 0)
    if (const auto conflict = output_conflict(options, output)) {
      fmt::print(stderr, "error: {}\n", *conflict);
      conflicting = 1;
    }
  MPI_Bcast(&conflicting, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (conflicting) return kExitBadInput;
  const cosserat::ThreadPlacement placement = set_threads(*decomposition, options.threads, rank);
  const int threads = placement.threads;

  // The semi-implicit baseline checks its solver names with PETSc while it is set up.
  std::unique_ptr<Simulation> simulation_owner;
  if (const auto status = bad_input(options.scene_path, rank, [&] {
        simulation_owner = std::make_unique<Simulation>(scene, MPI_COMM_WORLD, *decomposition,
                                                        any_scheme);
      }))
    return *status;
  Simulation& simulation = *simulation_owner;
  std::optional<long> restarted_from;
  std::optional<double> rest_peak;  // --until-rest's peak so far, when the checkpoint has it
  double adaptive_scale = 1.0;
  if (!options.restart.empty()) {
    try {
      restarted_from =
          read_checkpoint(options.restart, simulation, scene, &rest_peak, &adaptive_scale);
    } catch (const CheckpointError& e) {
      if (rank == 0) fmt::print(stderr, "error: {}\n", e.what());
      return kExitBadInput;
    }
  }

  // One run writes an output at a time: the second is refused before it writes anything.
  std::unique_ptr<OutputLock> lock;
  try {
    lock = std::make_unique<OutputLock>(output, MPI_COMM_WORLD);
  } catch (const OutputBusy& e) {
    if (rank == 0) fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadInput;
  }
  std::unique_ptr<FrameWriter> writer;
  bool continued = false;
  try {
    // A restart continues the earlier run's file when there is one: the frames up to the
    // checkpoint are kept, and the frames written after it are written again.
    continued = restarted_from && lock->had_contents();
    if (continued)
      writer = std::make_unique<FrameWriter>(
          output, simulation.block(), *restarted_from, scene.text,
          scene.adaptive ? 0 : *restarted_from - *restarted_from % scene.output_every,
          // Adaptive steps schedule frames in time.
          scene.adaptive ? AdaptiveSteps(scene).frame_at_or_before(simulation.time()) : 0.0,
          solid_outlines(simulation, scene), node_fields(scene.output_fields));
    else
      writer = std::make_unique<FrameWriter>(output, simulation.block(), scene.text,
                                             integrator_name(scene.integrator), COSSERAT_VERSION,
                                             scene.overrides, solid_outlines(simulation, scene),
                                             node_fields(scene.output_fields));
  } catch (const std::exception& e) {
    // This rank alone may have failed (rank 0 writes the XDMF file), and a file whose first
    // write failed crashes HDF5's clean-up in MPI_Finalize: end every rank now.
    fmt::print(stderr, "error: cannot write the output file: {}\n", e.what());
    MPI_Abort(MPI_COMM_WORLD, kExitBadInput);
  }
  const std::string checkpoint = checkpoint_path(output);

  const bool on_terminal = !options.quiet && rank == 0 && isatty(STDERR_FILENO);
  if (!options.quiet && rank == 0) {
    const std::string steps =
        !scene.adaptive ? fmt::format("{} steps of {} s", scene.steps, scene.dt)
        : scene.adaptive->random
            ? fmt::format("{} s in random steps of {} to {} s (seed {})", scene.duration,
                          scene.adaptive->min, scene.adaptive->max, scene.adaptive->seed)
            : fmt::format("{} s in adaptive steps (at most {} s, safety {})", scene.duration,
                          scene.adaptive->max, scene.adaptive->safety);
    fmt::print("{}: {} x {} nodes, {} with {}, {} rank{} ({} x {} blocks) x {} threads -> {}\n",
               scene.title.empty() ? scene.name : scene.title, scene.m, scene.n, steps,
               integrator_name(scene.integrator), ranks, ranks == 1 ? "" : "s",
               decomposition->parts_k(), decomposition->parts_l(), threads, output);
    if (restarted_from)
      fmt::print("restarted from {} at step {}\n", options.restart, *restarted_from);
  }

  Progress progress(simulation.step_index(), simulation.time(), scene.duration, on_terminal);
  RunObserver observer(simulation, scene, *writer, checkpoint, progress);
  // A continued file already holds every scheduled frame up to the checkpoint; a new file starts
  // with the state the run starts from.
  if (!continued) observer.frame();
  const StepLoopResult loop = run_step_loop(
      simulation, scene,
      StepLoopOptions{options.checkpoint_every, options.until_rest, rest_peak.value_or(0.0),
                      adaptive_scale, placement.requested ? 1 : threads},
      observer);
  progress.finish();

  const std::optional<Instability>& failure = loop.failure;
  if (failure) {
    // Keep the last good state: it is the newest frame unless it was just written.
    if (writer->last_step() != simulation.step_index()) observer.frame();
    if (rank == 0)
      fmt::print(stderr,
                 "error: unstable at step {} (t = {:.6g} s): {}; stopped, the last good state "
                 "(step {}) is the last frame of {}\n",
                 failure->step, failure->time, describe(*failure), simulation.step_index(),
                 output);
    if (rank == 0 && !failure->solver_failure) {
      const CflEstimate cfl = cosserat::rest_step_estimate(scene.model_spec());
      if (scene.adaptive && scene.adaptive->random)
        fmt::print(stderr,
                   "hint: this run's random steps reach time.dt.max = {} s; the rest sheet's "
                   "CFL estimate is {:.3g} s (docs/stability.md, \"Random steps\"): keep max "
                   "below it\n",
                   scene.adaptive->max, cfl.dt);
      else if (scene.adaptive)
        fmt::print(stderr,
                   "hint: adaptive steps went down to time.dt.min = {:.3g} s (the rest sheet's "
                   "CFL estimate is {:.3g} s): a failure no step cures is a property of the "
                   "model here, not of the integrator (docs/stability.md); `cosserat stable-dt "
                   "{}` says whether any fixed step gets past it\n",
                   scene.adaptive->min, cfl.dt, options.scene_path);
      else
        fmt::print(stderr,
                   "hint: this run's dt is {} s; the rest sheet's CFL estimate is {:.3g} s "
                   "(docs/stability.md); `cosserat stable-dt {}` measures the largest stable "
                   "step, and says when no step helps; or leave time.dt out for adaptive "
                   "steps\n",
                   scene.dt, cfl.dt, options.scene_path);
      if (scene.energy_indefinite)
        fmt::print(stderr,
                   "hint: this material's stored energy is not positive definite (phi^2 >= 4 "
                   "zeta xi, see the warning above): creases one cell wide can grow whatever "
                   "the step; raise xi or lower phi\n");
    }
    writer->set_attribute("status", fmt::format("unstable at step {}", failure->step));
  } else {
    writer->set_attribute("status", "ok");
  }

  const RunSummary summary =
      summarize_run(scene, simulation, loop,
                    RunPlacement{ranks, threads, decomposition->parts_k(), decomposition->parts_l(),
                                 output, restarted_from},
                    MPI_COMM_WORLD);
  const double steps_run = static_cast<double>(summary.steps - loop.first_step);
  const double wall = summary.wall_seconds;
  if (rank == 0) {
    if (!options.summary.empty()) write_summary(options.summary, summary);
    if (!options.quiet)
      fmt::print("{} steps in {:.3f} s ({:.3g} node-steps/s, {:.1f} % in halo exchange); area "
                 "ratio {:.4f}; status {}\n",
                 steps_run, wall, summary.node_steps_per_second,
                 wall > 0.0 ? 100.0 * summary.halo_seconds / wall : 0.0, summary.area_ratio,
                 summary.status);
    if (const auto& l = summary.linear_solves)
      fmt::print("semi-implicit: {:.1f} Krylov iterations per step (most {}); Jacobian {:.3f} s, "
                 "linear solves {:.3f} s\n",
                 l->solves > 0 ? static_cast<double>(l->iterations) / l->solves : 0.0,
                 l->most_iterations, l->jacobian_seconds, l->solve_seconds);
    if (const auto& rest = summary.rest; rest && !options.quiet)
      fmt::print("{}\n", rest->step ? fmt::format("at rest at step {}", *rest->step)
                                    : std::string("not at rest by the last step"));
  }
  return failure ? kExitUnstable : kExitOk;
}

// `cosserat stable-dt`: the largest stable Δt of each integrator, beside the CFL estimate.
int stable_dt(const StableDtOptions& options, int rank) {
  using namespace cosserat;
  std::vector<std::string> integrators = options.integrators;
  if (integrators.size() == 1 && integrators[0] == "all") integrators = integrator_names();
  std::vector<Scene> scenes;
  std::optional<Decomposition> decomposition;
  double duration = 0.0;
  const auto status = bad_input(options.scene_path, rank, [&] {
    const Scene base = load_scene(options.scene_path, options.overrides);
    if (integrators.empty()) integrators.push_back(integrator_name(base.integrator));
    duration = options.duration.value_or(base.duration);
    if (!(duration > 0.0))
      throw SceneError(fmt::format("{}: the simulated time must be > 0 (give --time T)",
                                   options.scene_path));
    check_trial_length(base, duration);
    for (const std::string& name : integrators) {
      std::vector<std::string> overrides = options.overrides;
      overrides.push_back(fmt::format("time.integrator=\"{}\"", name));
      // Trials take fixed steps, which every integrator can; the search starts from the
      // largest adaptive step.
      if (base.adaptive) overrides.push_back(fmt::format("time.dt={}", base.dt));
      scenes.push_back(load_scene(options.scene_path, overrides));
    }
    decomposition = Decomposition::choose(base.m, base.n, size_of(MPI_COMM_WORLD));
    if (rank == 0)
      for (const std::string& warning : base.warnings) fmt::print(stderr, "warning: {}\n", warning);
  });
  if (status) return *status;
  set_threads(*decomposition, options.threads, rank);

  const Scene& first = scenes.front();
  const CflEstimate cfl = rest_step_estimate(first.model_spec());
  const std::string title = first.title.empty() ? first.name : first.title;
  if (rank == 0) {
    fmt::print("{}: {} x {} nodes, stable over T = {} s, to {:.3g} %; CFL estimate {:.4g} s "
               "(c_L = {:.4g} m/s, c_S = {:.4g} m/s: membrane {:.4g} s, bending {:.4g} s)\n",
               title, first.m, first.n, duration, 100.0 * options.tolerance, cfl.dt,
               cfl.longitudinal_speed, cfl.shear_speed, cfl.membrane_dt, cfl.bending_dt);
    fmt::print("{:<17} {:>12} {:>12} {:>7} {:>7} {:>9}  {}\n", "integrator", "stable dt",
               "unstable dt", "/ CFL", "trials", "wall s", "first unstable trial");
  }
  StableDtTable table{title, duration, cfl.dt, {}};
  for (const Scene& scene : scenes) {
    const std::string name = integrator_name(scene.integrator);
    StableStep found;
    const auto report = [&](const StabilityTrial& t) {
      if (rank == 0 && !options.quiet)
        fmt::print(stderr, "  {} dt = {:.6g}: {}\n", name, t.dt,
                   t.stable ? "stable" : "unstable, " + t.cause);
    };
    // The semi-implicit solver's names are checked by PETSc when its first trial sets it up.
    if (const auto failed = bad_input(options.scene_path, rank, [&] {
          found = largest_stable_step(scene, duration, options.tolerance, MPI_COMM_WORLD,
                                      any_scheme, report);
        }))
      return *failed;
    const StableDtRow& row =
        table.rows.emplace_back(stable_dt_row(name, std::move(found), duration));
    if (rank == 0) {
      fmt::print("{:<17} {:>12.6g} {:>12.6g} {:>7.3f} {:>7} {:>9.2f}  {}\n", name,
                 row.found.stable_dt, row.found.unstable_dt, row.found.stable_dt / cfl.dt,
                 row.found.trials.size(), row.wall_seconds, row.cause);
      std::fflush(stdout);
    }
  }
  if (rank == 0 && !options.csv.empty()) {
    try {
      write_csv(options.csv, table);
    } catch (const std::runtime_error& e) {
      fmt::print(stderr, "error: {}\n", e.what());
      return kExitFailure;
    }
  }
  return kExitOk;
}

}  // namespace

// CLI11's ranges let NaN through (every comparison with it is false).
const CLI::Validator finite_number(
    [](std::string& text) {
      double value = 0.0;
      return CLI::detail::lexical_cast(text, value) && std::isfinite(value)
                 ? std::string()
                 : "must be a finite number, got " + text;
    },
    "FINITE");

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
#if defined(COSSERAT_TRAP_FPE)
  feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
#endif

  CLI::App app{"cosserat: Cosserat-surface cloth dynamics on rectangular grids (MPI + OpenMP)"};
  app.set_version_flag("--version", std::string("cosserat ") + COSSERAT_VERSION);
  app.require_subcommand(1);
  RunOptions options;
  std::string petsc_options;
  CLI::App* run_command = app.add_subcommand("run", "Run a scene and write its frames to HDF5 + XDMF");
  run_command->add_option("scene", options.scene_path, "Scene file (TOML, see docs/scene-format.md)")
      ->required();
  run_command
      ->add_option("--set", options.overrides,
                   "Override a scene key: dotted.key=value, the value read as TOML "
                   "(e.g. --set time.dt=5e-4 --set solid[0].friction=0); repeatable")
      ->allow_extra_args(false);
  run_command->add_option("-o,--output", options.output,
                          "HDF5 output file (default: <scene file stem>.h5 in the working "
                          "directory); the XDMF file goes beside it");
  run_command->add_option("--summary", options.summary,
                          "Write the run summary as one JSON object to this file");
  run_command->add_option("--checkpoint-every", options.checkpoint_every,
                          "Every N steps (and at the end) write the whole state to <output "
                          "stem>.checkpoint.h5, replacing the previous checkpoint only once the "
                          "new one is complete")
      ->check(CLI::PositiveNumber);
  run_command->add_option("--restart", options.restart,
                          "Continue from a checkpoint written for this scene (same grid, "
                          "integrator and dt; any number of ranks): the result equals an "
                          "uninterrupted run bitwise. The output file, if present, keeps its "
                          "frames up to the checkpoint and is continued")
      ->check(CLI::ExistingFile);
  run_command->add_option("--until-rest", options.until_rest,
                          "Stop once the kinetic energy is below this fraction of its peak so "
                          "far (e.g. 1e-6); the summary's \"rest\" gives the step")
      ->check(CLI::Range(0.0, 1.0))
      ->check(finite_number);
  run_command->add_option("--petsc", petsc_options,
                          "PETSc options for the semi-implicit integrator, in one string "
                          "(e.g. \"-ksp_type cg -pc_type jacobi -ksp_rtol 1e-8\"); they override "
                          "the scene's [time.solver]. PETSC_OPTIONS is read too");
  run_command->add_option("--threads", options.threads,
                          "OpenMP threads per rank (default: OMP_NUM_THREADS if set, else the "
                          "cores this rank may run on, shared with the ranks of its node given "
                          "the same cores, and at most its block's rows)")
      ->check(CLI::Range(1, 4096));
  run_command->add_flag("--overwrite", options.overwrite,
                        "Replace the output files (HDF5, XDMF, checkpoint, summary) when they "
                        "exist; without it a run whose output files exist exits with status 2 "
                        "before any work (a --restart continues its output and needs no flag)");
  run_command->add_flag("-q,--quiet", options.quiet,
                        "Print nothing but warnings and errors (the progress line is shown "
                        "only on a terminal anyway)");
  run_command->footer(
      "Threads: --threads, else OMP_NUM_THREADS, else the cores of this rank's affinity mask "
      "shared among the ranks of its node (a warning when a node's ranks x threads exceed its "
      "cores). On a terminal a progress line shows the "
      "step, simulated time, steps/s and ETA. Ranks: mpirun -np P splits the grid into P "
      "blocks (see jobs/README.md).");

  StableDtOptions stable;
  CLI::App* stable_command = app.add_subcommand(
      "stable-dt",
      "Largest stable time step of a scene per integrator, by bisection on the stability "
      "monitor (docs/stability.md), beside the CFL estimate from the model's wave speeds");
  stable_command->add_option("scene", stable.scene_path, "Scene file (TOML)")->required();
  stable_command->add_option("--integrator", stable.integrators,
                             "Integrator to test (repeatable; \"all\" for every one; default: "
                             "the scene's)");
  stable_command->add_option("--time", stable.duration,
                             "Simulated time T each trial must survive (s; default: the "
                             "scene's steps x dt)")
      ->check(CLI::PositiveNumber);
  stable_command->add_option("--tolerance", stable.tolerance,
                             "Stop when the stable and unstable steps are within this fraction "
                             "(default 0.02)")
      ->check(CLI::Range(1e-6, 1.0));
  stable_command->add_option("--set", stable.overrides,
                             "Override a scene key, as for run (repeatable)")
      ->allow_extra_args(false);
  stable_command->add_option("--csv", stable.csv, "Also write the table as CSV to this file");
  stable_command->add_option("--petsc", petsc_options,
                             "PETSc options for the semi-implicit integrator, as for run");
  stable_command->add_option("--threads", stable.threads,
                             "OpenMP threads per rank, as for run")
      ->check(CLI::Range(1, 4096));
  stable_command->add_flag("-q,--quiet", stable.quiet, "No line per trial on stderr");
  stable_command->footer(
      "Each trial runs the scene for ceil(T/dt) steps without output. Steps start from the "
      "scene's dt, double or halve to bracket the limit, then bisect. Threads and ranks as for "
      "run.");

  app.footer(
      "Exit status: 0 ok, 2 bad input (nothing was run), 3 the run became unstable (frames so "
      "far and the last good state are kept), 1 anything else.");

  int status = kExitOk;
  try {
    app.parse(argc, argv);
    if (!petsc_options.empty()) cosserat::add_petsc_options(petsc_options);
    status = *run_command ? run(options, rank, ranks) : stable_dt(stable, rank);
  } catch (const CLI::Success& e) {
    status = app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    status = kExitBadInput;
  } catch (const std::invalid_argument& e) {
    // --petsc on a build without PETSc
    if (rank == 0) fmt::print(stderr, "error: {}\n", e.what());
    status = kExitBadInput;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    // The other ranks may be waiting in a collective call for this one, and an HDF5 file whose
    // write failed crashes HDF5's own clean-up inside MPI_Finalize: end every rank now, with
    // this status.
    MPI_Abort(MPI_COMM_WORLD, kExitFailure);
  }
  cosserat::finalize_petsc();
  MPI_Finalize();
  return status;
}
