// The solver's step loop under SimGrid's SMPI (docs/parallel.md, "Simulated clusters"): the
// grid, model, contact, scene and time modules compiled with smpicxx, so that every simulated
// rank runs the solver's own steps, its halo exchanges and reductions with their real messages,
// and MPI_Wtime reads the simulated clock. No output file (the io module needs a parallel HDF5
// of a real MPI); rank 0 prints what it measured as a CSV header and line.
//   smpirun -np P -platform PLATFORM.xml smpi_step SCENE.toml STEPS [options]
//     --warmup N        steps run before the timed ones (default 2)
//     --fold            every field in SMPI's folded memory (smpi_fold_fields): a thousand
//                       ranks fit, and the fields' values mean nothing
//     --compute-ns NS   the step's computation as NS ns a node-step of the rank's block,
//                       injected once a step (smpi_execute_flops); run with
//                       --cfg=smpi/simulate-computation:no so the real computation counts
//                       nothing (benchmarks/run_smpi.sh calibrates NS on this machine)
//     --set KEY=VALUE   a scene override, as cosserat run's
#include <mpi.h>
#include <simgrid/host.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/simulation.hpp"

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  std::vector<std::string> args(argv + 1, argv + argc);
  std::vector<std::string> overrides;
  long warmup = 2;
  double compute_ns = 0.0;
  bool bad = args.size() < 2;
  for (std::size_t i = 2; i < args.size() && !bad; ++i) {
    const bool has_value = i + 1 < args.size();
    if (args[i] == "--fold") {
      cosserat::smpi_fold_fields = true;
    } else if (args[i] == "--warmup" && has_value) {
      warmup = std::atol(args[++i].c_str());
    } else if (args[i] == "--compute-ns" && has_value) {
      compute_ns = std::atof(args[++i].c_str());
    } else if (args[i] == "--set" && has_value) {
      overrides.push_back(args[++i]);
    } else {
      bad = true;
    }
  }
  if (bad) {
    if (rank == 0)
      std::fprintf(stderr,
                   "usage: smpi_step SCENE.toml STEPS [--warmup N] [--fold] "
                   "[--compute-ns NS] [--set KEY=VALUE ...]\n");
    MPI_Finalize();
    return 2;
  }
  const std::string path = args[0];
  const long steps = std::atol(args[1].c_str());
  int status = 0;
  try {
    const cosserat::Scene scene = cosserat::load_scene(path, overrides);
    cosserat::Simulation simulation(scene, MPI_COMM_WORLD);
    const cosserat::Block& b = simulation.block();
    const double compute_seconds =
        1e-9 * compute_ns * static_cast<double>(b.owned_k()) * static_cast<double>(b.owned_l());
    // As flops of this simulated node: smpi_execute() would convert the seconds with the
    // speed of the machine running the simulation (smpi/host-speed).
    const double compute_flops = compute_seconds * sg_host_get_speed(sg_host_self());
    auto step = [&] {
      if (compute_flops > 0.0) smpi_execute_flops(compute_flops);
      // With folded fields a step's values mean nothing, and the check passes it
      // (Stepper::check, COSSERAT_SMPI).
      if (simulation.step()) status = 3;
    };
    // The first steps fill caches and lists: timed after them.
    for (long s = 0; s < warmup && status == 0; ++s) step();
    MPI_Barrier(MPI_COMM_WORLD);
    const double halo_before = simulation.halo_seconds();
    const double start = MPI_Wtime();
    for (long s = 0; s < steps && status == 0; ++s) step();
    MPI_Barrier(MPI_COMM_WORLD);
    const double seconds = MPI_Wtime() - start;
    double halo = simulation.halo_seconds() - halo_before, slowest_halo = 0.0;
    // An all-reduce: SMPI 3.32's Open MPI reduce aborts on one rank.
    MPI_Allreduce(&halo, &slowest_halo, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    if (rank == 0) {
      const double nodes = static_cast<double>(scene.m) * static_cast<double>(scene.n);
      std::printf(
          "ranks,grid,block,steps,seconds_per_step,node_steps_per_second,halo_share,status\n");
      std::printf("%d,%dx%d,%dx%d,%ld,%.9g,%.9g,%.6g,%s\n", ranks, scene.m, scene.n, b.owned_k(),
                  b.owned_l(), steps, seconds / static_cast<double>(steps),
                  nodes * static_cast<double>(steps) / seconds,
                  seconds > 0.0 ? slowest_halo / seconds : 0.0, status == 0 ? "ok" : "unstable");
    }
  } catch (const std::exception& e) {
    // A bad scene fails every rank alike, but an error of one rank must not leave the others
    // waiting.
    std::fprintf(stderr, "smpi_step: %s\n", e.what());
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  MPI_Finalize();
  return status;
}
