#pragma once
// OpenMP threads per rank. Left to itself each rank would start one thread per core of the
// machine, so P ranks on a node ran P times as many threads as it has cores (issue 12, defect
// 15: 8 threads on 2 cores ran 270 times slower than one thread). By default a rank takes the
// cores of its affinity mask, shared with the ranks of its node given the same cores.

#include <mpi.h>

#include <optional>

namespace cosserat {

// Threads for a rank whose affinity mask holds `cores` CPUs, which `sharing` ranks of its node
// (itself included) were also given, on a block of `rows` rows: the kernels split their outer
// row loop over the threads, so a thread beyond the rows would only wait at the barriers.
// At least 1.
int default_threads(int cores, int sharing, long rows);

struct ThreadPlacement {
  int threads = 1;        // this rank's
  bool requested = false;  // by --threads or OMP_NUM_THREADS rather than by default_threads
  // The node with the most threads per core: its ranks, their threads together, and the CPUs
  // of their masks together.
  int node_ranks = 1;
  int node_threads = 1;
  int node_cores = 1;
  // The most CPUs on any node that none of its ranks' masks holds (online, within the cgroup's
  // cpuset where readable): a binding that leaves them idle.
  int idle_cpus = 0;
  bool oversubscribed() const { return node_threads > node_cores; }
};

// Sets this rank's OpenMP thread count: `requested` (the --threads option) if given, else
// OMP_NUM_THREADS if set, else default_threads from the affinity mask (sched_getaffinity), the
// ranks of this node (MPI_COMM_TYPE_SHARED) whose masks overlap it, and `rows`. Collective over
// comm; every rank gets the same node figures.
ThreadPlacement place_threads(MPI_Comm comm, long rows, std::optional<int> requested);

}  // namespace cosserat
