// The `cosserat` command line (DESIGN.md "Interfaces"): owns MPI, files and the step loop.

#include <mpi.h>
#include <omp.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <filesystem>
#include <fmt/core.h>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosserat/grid/decomposition.hpp"
#include "cosserat/grid/reduce.hpp"
#include "cosserat/io/checkpoint.hpp"
#include "cosserat/io/frame_writer.hpp"
#include "cosserat/io/summary.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/simulation.hpp"

#if defined(COSSERAT_TRAP_FPE)
#include <cfenv>
#endif

namespace {

// Exit statuses of DESIGN.md.
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
  bool quiet = false;
};

// One line, rewritten in place, while the run goes: only on a terminal.
class Progress {
 public:
  Progress(long total_steps, double dt, bool enabled)
      : total_(total_steps), dt_(dt), enabled_(enabled), start_(Clock::now()), last_(start_) {}

  void update(long step) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (now - last_ < std::chrono::milliseconds(200) && step != total_) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0.0 ? static_cast<double>(step) / elapsed : 0.0;
    const double eta = rate > 0.0 ? static_cast<double>(total_ - step) / rate : 0.0;
    fmt::print(stderr, "\rstep {}/{}  t = {:.4f} s  {:.0f} steps/s  ETA {:.0f} s   ", step,
               total_, static_cast<double>(step) * dt_, rate, eta);
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) fmt::print(stderr, "\n");
  }

 private:
  long total_;
  double dt_;
  bool enabled_;
  Clock::time_point start_, last_;
};

std::string default_output(const cosserat::Scene& scene) { return scene.name + ".h5"; }

// Memory of every rank on this node, against the node's physical memory.
bool fits_in_memory(const cosserat::Scene& scene, const cosserat::Block& block, int rank) {
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
  const double mine = cosserat::Simulation::memory_bytes(block);
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

int run(const RunOptions& options, int rank, int ranks) {
  using namespace cosserat;
  Scene scene;
  std::optional<Decomposition> decomposition;
  try {
    scene = load_scene(options.scene_path, options.overrides);
    decomposition = Decomposition::choose(scene.m, scene.n, ranks);
  } catch (const SceneError& e) {
    if (rank == 0) fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadInput;
  } catch (const DecompositionError& e) {
    if (rank == 0) fmt::print(stderr, "error: {}: {}\n", options.scene_path, e.what());
    return kExitBadInput;
  }
  if (rank == 0)
    for (const std::string& warning : scene.warnings) fmt::print(stderr, "warning: {}\n", warning);
  if (!fits_in_memory(scene, decomposition->block(rank, MPI_COMM_WORLD), rank))
    return kExitBadInput;

  Simulation simulation(scene, MPI_COMM_WORLD, *decomposition);
  std::optional<long> restarted_from;
  if (!options.restart.empty()) {
    try {
      restarted_from = read_checkpoint(options.restart, simulation, scene);
    } catch (const CheckpointError& e) {
      if (rank == 0) fmt::print(stderr, "error: {}\n", e.what());
      return kExitBadInput;
    }
  }

  const std::string output = options.output.empty() ? default_output(scene) : options.output;
  std::unique_ptr<FrameWriter> writer;
  bool continued = false;
  try {
    // A restart continues the earlier run's file when there is one: the frames up to the
    // checkpoint are kept, and the frames written after it are written again.
    continued = restarted_from && std::filesystem::exists(output);
    if (continued)
      writer = std::make_unique<FrameWriter>(output, simulation.block(), *restarted_from);
    else
      writer = std::make_unique<FrameWriter>(output, simulation.block(), scene.text,
                                             integrator_name(scene.integrator), COSSERAT_VERSION,
                                             scene.overrides);
  } catch (const std::exception& e) {
    if (rank == 0) fmt::print(stderr, "error: cannot write the output file: {}\n", e.what());
    return kExitBadInput;
  }
  const std::string checkpoint = checkpoint_path(output);

  const int threads = omp_get_max_threads();
  const bool on_terminal = !options.quiet && rank == 0 && isatty(STDERR_FILENO);
  if (!options.quiet && rank == 0) {
    fmt::print("{}: {} x {} nodes, {} steps of {} s with {}, {} rank{} ({} x {} blocks) x {} "
               "threads -> {}\n",
               scene.title.empty() ? scene.name : scene.title, scene.m, scene.n, scene.steps,
               scene.dt, integrator_name(scene.integrator), ranks, ranks == 1 ? "" : "s",
               decomposition->parts_k(), decomposition->parts_l(), threads, output);
    if (restarted_from)
      fmt::print("restarted from {} at step {}\n", options.restart, *restarted_from);
  }

  auto write_frame = [&] {
    writer->write_frame(simulation.step_index(), simulation.time(), simulation.positions());
  };
  // A continued file already holds every scheduled frame up to the checkpoint; a new file starts
  // with the state the run starts from.
  if (!continued) write_frame();
  const long first_step = simulation.step_index();
  const double halo_before = simulation.halo_seconds();
  Progress progress(scene.steps, scene.dt, on_terminal);
  const auto start = Clock::now();
  std::optional<Instability> failure;
  while (simulation.step_index() < scene.steps) {
    failure = simulation.step();
    if (failure) break;
    const long step = simulation.step_index();
    if (step % scene.output_every == 0 || step == scene.steps) write_frame();
    if (options.checkpoint_every > 0 &&
        (step % options.checkpoint_every == 0 || step == scene.steps))
      write_checkpoint(checkpoint, simulation, scene, COSSERAT_VERSION);
    progress.update(step);
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  progress.finish();

  if (failure) {
    // Keep the last good state: it is the newest frame unless it was just written.
    if (writer->last_step() != simulation.step_index()) write_frame();
    if (rank == 0)
      fmt::print(stderr,
                 "error: unstable at step {} (t = {:.6g} s): node [{}, {}] {}; stopped, the last "
                 "good state (step {}) is the last frame of {}\n",
                 failure->step, failure->time, failure->k, failure->l,
                 failure->not_finite ? "has a non-finite position"
                                     : "moved more than half a grid spacing in one step",
                 simulation.step_index(), output);
    writer->set_attribute("status", fmt::format("unstable at step {}", failure->step));
  } else {
    writer->set_attribute("status", "ok");
  }

  const Diagnostics diagnostics = simulation.diagnostics();
  const double steps_run = static_cast<double>(simulation.step_index() - first_step);
  RunSummary summary;
  summary.scene = scene.title.empty() ? scene.name : scene.title;
  summary.m = scene.m;
  summary.n = scene.n;
  summary.ranks = ranks;
  summary.threads = threads;
  summary.parts_k = decomposition->parts_k();
  summary.parts_l = decomposition->parts_l();
  summary.integrator = integrator_name(scene.integrator);
  summary.dt = scene.dt;
  summary.steps = simulation.step_index();
  summary.sim_time = simulation.time();
  summary.wall_seconds = wall;
  summary.node_steps_per_second =
      wall > 0.0 ? static_cast<double>(scene.m) * scene.n * steps_run / wall : 0.0;
  summary.halo_seconds = global_max(simulation.halo_seconds() - halo_before, MPI_COMM_WORLD);
  summary.restarted_from = restarted_from;
  summary.status = failure ? "unstable" : "ok";
  if (failure) summary.unstable_step = failure->step;
  summary.area_ratio = diagnostics.area_ratio;
  summary.max_speed = diagnostics.max_speed;
  summary.kinetic_energy = diagnostics.kinetic_energy;
  summary.center_of_mass = diagnostics.center_of_mass;
  summary.output = output;
  if (rank == 0) {
    if (!options.summary.empty()) write_summary(options.summary, summary);
    if (!options.quiet)
      fmt::print("{} steps in {:.3f} s ({:.3g} node-steps/s, {:.1f} % in halo exchange); area "
                 "ratio {:.4f}; status {}\n",
                 steps_run, wall, summary.node_steps_per_second,
                 wall > 0.0 ? 100.0 * summary.halo_seconds / wall : 0.0, summary.area_ratio,
                 summary.status);
  }
  return failure ? kExitUnstable : kExitOk;
}

}  // namespace

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
  CLI::App* run_command = app.add_subcommand("run", "Run a scene and write its frames to HDF5 + XDMF");
  run_command->add_option("scene", options.scene_path, "Scene file (TOML, see docs/scene-format.md)")
      ->required();
  run_command->add_option("--set", options.overrides,
                          "Override a scene key: dotted.key=value, the value read as TOML "
                          "(e.g. --set time.dt=5e-4 --set grid.nodes=[64,64]); repeatable")
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
  run_command->add_flag("-q,--quiet", options.quiet,
                        "Print nothing but warnings and errors (the progress line is shown "
                        "only on a terminal anyway)");
  run_command->footer(
      "Threads: OMP_NUM_THREADS (default: all cores). On a terminal a progress line shows the "
      "step, simulated time, steps/s and ETA. Ranks: mpirun -np P splits the grid into P "
      "blocks (see jobs/README.md).");
  app.footer(
      "Exit status: 0 ok, 2 bad input (nothing was run), 3 the run became unstable (frames so "
      "far and the last good state are kept), 1 anything else.");

  int status = kExitOk;
  try {
    app.parse(argc, argv);
    status = run(options, rank, ranks);
  } catch (const CLI::Success& e) {
    status = app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    status = kExitBadInput;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    status = kExitFailure;
  }
  MPI_Finalize();
  return status;
}
