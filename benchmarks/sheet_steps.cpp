// A fixed number of Verlet steps of the benchmark sheet (bench_sheet.hpp) and nothing more, for
// the tools that measure a step from outside the program: count_flops.py runs it under
// callgrind and cachegrind at two step counts and takes the difference, so the setup cancels;
// run_roofline.sh compares its peak RSS at two grid sizes. One rank; threads from
// OMP_NUM_THREADS. Prints one JSON line: nodes, steps, wall seconds of the steps, the
// project's memory estimate (Simulation::memory_bytes), the resident set after the steps (the
// fields a step keeps) and its peak (the setup's temporaries too).
//   sheet_steps NODES STEPS

#include <mpi.h>
#include <sys/resource.h>
#include <unistd.h>

#include <charconv>
#include <cstdio>
#include <cstring>

#include "bench_sheet.hpp"
#include "cosserat/time/simulation.hpp"

namespace {

// Linux's count of resident pages, the second number of /proc/self/statm; 0 elsewhere.
long resident_bytes() {
  std::FILE* statm = std::fopen("/proc/self/statm", "r");
  if (statm == nullptr) return 0;
  long size = 0, resident = 0;
  const bool read = std::fscanf(statm, "%ld %ld", &size, &resident) == 2;
  std::fclose(statm);
  return read ? resident * sysconf(_SC_PAGESIZE) : 0;
}

bool parse_positive(const char* text, long& value) {
  const char* end = text + std::strlen(text);
  const auto [last, error] = std::from_chars(text, end, value);
  return error == std::errc{} && last == end && value > 0;
}

}  // namespace

int main(int argc, char** argv) {
  long nodes = 0, steps = 0;
  // Three nodes a side is the smallest sheet with an interior node.
  if (argc != 3 || !parse_positive(argv[1], nodes) || !parse_positive(argv[2], steps) ||
      nodes < 3 || nodes > 32768) {
    std::fprintf(stderr, "usage: %s NODES STEPS (3 <= NODES <= 32768, STEPS >= 1)\n", argv[0]);
    return 2;
  }
  MPI_Init(&argc, &argv);
  const cosserat::Scene scene = cosserat::bench::flat_sheet(static_cast<int>(nodes));
  int status = 0;
  {
    cosserat::Simulation sim(scene, MPI_COMM_SELF);
    const double start = MPI_Wtime();
    for (long s = 0; s < steps && status == 0; ++s)
      if (const auto failure = sim.step()) {
        std::fprintf(stderr, "unstable at step %ld: %s\n", failure->step, failure->diagnosis.c_str());
        status = 1;
      }
    const double seconds = MPI_Wtime() - start;
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    std::printf(
        "{\"nodes\": %ld, \"steps\": %ld, \"seconds\": %.6g, \"memory_bytes\": %.17g, "
        "\"rss_bytes\": %ld, \"max_rss_bytes\": %ld}\n",
        nodes, steps, seconds,
        cosserat::Simulation::memory_bytes(sim.block(), scene.integrator, scene.model_spec()),
        resident_bytes(), usage.ru_maxrss * 1024L);
  }
  MPI_Finalize();
  return status;
}
