#include "cosserat/grid/threads.hpp"

#include <omp.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cosserat/grid/block.hpp"

namespace cosserat {

int default_threads(int cores, int sharing, long rows) {
  const long share = std::max(cores, 1) / std::max(sharing, 1);
  return static_cast<int>(std::max(1L, std::min(share, rows)));
}

namespace {

long online_cpus() { return std::clamp(sysconf(_SC_NPROCESSORS_ONLN), 1L, long{CPU_SETSIZE}); }

cpu_set_t affinity_mask() {
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (sched_getaffinity(0, sizeof(mask), &mask) != 0 || CPU_COUNT(&mask) == 0) {
    // No mask to read: every online CPU, as the OpenMP runtime assumes then.
    const long online = online_cpus();
    for (long cpu = 0; cpu < online; ++cpu) CPU_SET(static_cast<int>(cpu), &mask);
  }
  return mask;
}

// The CPUs a job may use on this node: those online, within the cgroup's cpuset where one is
// readable (a container or a batch system's allocation), whatever mpirun bound its ranks to.
int node_cpus() {
  const long online = online_cpus();
  std::ifstream file("/sys/fs/cgroup/cpuset.cpus.effective");
  std::string list;
  if (!std::getline(file, list) || list.empty()) return static_cast<int>(online);
  // "0-3,8,10-11"
  long count = 0;
  std::stringstream ranges(list);
  for (std::string range; std::getline(ranges, range, ',');) {
    const auto dash = range.find('-');
    try {
      const long first = std::stol(range.substr(0, dash));
      const long last = dash == std::string::npos ? first : std::stol(range.substr(dash + 1));
      count += std::max(0L, last - first + 1);
    } catch (const std::exception&) {
      return static_cast<int>(online);
    }
  }
  return static_cast<int>(std::clamp(count, 1L, online));
}

bool explicit_thread_count() {
  const char* value = std::getenv("OMP_NUM_THREADS");
  return value != nullptr && *value != '\0';
}

}  // namespace

ThreadPlacement place_threads(MPI_Comm comm, long rows, std::optional<int> requested) {
  MPI_Comm node;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, rank_in(comm), MPI_INFO_NULL, &node);
  const int node_ranks = size_of(node);
  const cpu_set_t mine = affinity_mask();
  std::vector<cpu_set_t> masks(static_cast<std::size_t>(node_ranks));
  MPI_Allgather(&mine, sizeof(cpu_set_t), MPI_BYTE, masks.data(), sizeof(cpu_set_t), MPI_BYTE,
                node);
  cpu_set_t all;
  CPU_ZERO(&all);
  int sharing = 0;
  for (cpu_set_t& other : masks) {
    cpu_set_t common;
    CPU_AND(&common, &other, &mine);
    if (CPU_COUNT(&common) > 0) ++sharing;
    CPU_OR(&all, &all, &other);
  }

  ThreadPlacement placement;
  placement.requested = requested.has_value() || explicit_thread_count();
  if (requested)
    omp_set_num_threads(*requested);
  else if (!placement.requested)
    omp_set_num_threads(default_threads(CPU_COUNT(&mine), sharing, rows));
  placement.threads = omp_get_max_threads();

  int node_threads = 0;
  MPI_Allreduce(&placement.threads, &node_threads, 1, MPI_INT, MPI_SUM, node);
  MPI_Comm_free(&node);
  // CPUs of a node that no rank's mask holds: Open MPI binds each of one or two ranks to a
  // single core by default, so `mpirun -np 1` on a 2-core machine runs one thread on one core
  // (docs/parallel.md, "Threads that fit").
  const int idle = std::max(0, node_cpus() - CPU_COUNT(&all));
  MPI_Allreduce(&idle, &placement.idle_cpus, 1, MPI_INT, MPI_MAX, comm);
  // Rank 0 reports one node: the one with the most threads per core.
  const int node_cores = CPU_COUNT(&all);
  struct {
    double load;
    int rank;
  } local{static_cast<double>(node_threads) / node_cores, rank_in(comm)}, busiest{};
  MPI_Allreduce(&local, &busiest, 1, MPI_DOUBLE_INT, MPI_MAXLOC, comm);
  int figures[3] = {node_ranks, node_threads, node_cores};
  MPI_Bcast(figures, 3, MPI_INT, busiest.rank, comm);
  placement.node_ranks = figures[0];
  placement.node_threads = figures[1];
  placement.node_cores = figures[2];
  return placement;
}

}  // namespace cosserat
