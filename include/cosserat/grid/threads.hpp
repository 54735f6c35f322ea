#pragma once
// OpenMP threads per rank. Left to itself each rank would start one thread per core of the
// machine, so P ranks on a node ran P times as many threads as it has cores (issue 12, defect
// 15: 8 threads on 2 cores ran 270 times slower than one thread). By default a rank takes the
// cores of its affinity mask, shared with the ranks of its node given the same cores.

#include <mpi.h>

#include <functional>
#include <optional>
#include <vector>

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

// Splits a block's rows into one contiguous band per thread, in proportion to the rate at which
// each thread went through its rows in the last steps. An even split assumes equal cores; where
// they are not (a VM's cores run at speeds that differ by up to 10 % and change from one run to
// the next, docs/kernel.md), every step waits at its closing barrier for the slower one. Where a
// row goes changes no result: each node gets the same arithmetic whichever thread computes it.
class RowBalance {
 public:
  // The first row of each thread's band, then the row count (threads + 1 entries): an even split
  // on the first call and whenever rows or threads change. Every band gets a row if there are
  // enough.
  const std::vector<long>& split(long rows, int threads);
  // The seconds thread t took for its band of the last split; each thread records its own.
  void record(int t, double seconds) { seconds_[static_cast<std::size_t>(t)] = seconds; }
  // Moves rows towards the threads that went faster; after every thread recorded.
  void rebalance();
  // Sets the bands, given as split returns them, until the next rebalance; for the tests that
  // hold a kernel to the same bits on every split.
  void assign(std::vector<long> first_row);

 private:
  std::vector<long> first_row_;
  std::vector<double> seconds_;
  std::vector<double> row_cost_;  // seconds a row, smoothed over the steps
};

// The tasks the machine is running now besides `mine` of this process's threads: Linux's
// procs_running (/proc/stat), the least of three readings 0.1 ms apart, less `mine`, at least
// 0; 0 where it cannot be read.
int others_running(int mine);
// The machine's online CPUs, which procs_running counts across.
int online_cpu_count();

// Picks the size of a rank's thread team, step by step, from the steps' measured wall time
// (docs/parallel.md, "Threads that fit the machine"). The default count suits an idle machine
// (two threads run S2's 20 x 20 sheet 1.9 times as fast as one on two idle cores), but every
// step ends at a barrier that waits for the slowest thread, and a thread whose core another
// program holds is descheduled for milliseconds at a time: with a busy process on one of two
// cores, two threads took 2.4 times as long as one on S2. No setting of the waiting threads
// fixes that from outside (OMP_WAIT_POLICY=passive came within 8–12 % of one thread, but cost
// 48 % on S6 on an idle machine), so the tuner times each count it may use, 1 to the default
// halving, over windows of steps, keeps the fastest, and times the others again now and then:
// the machine's load changes during a run. Its first round is quick and starts at one thread,
// it cuts short the timing of a count that is already clearly slower, and it does not time a
// count the machine has no free cores for (waking a thread on a core another program holds
// costs a whole descheduled step). Where the rows go changes no bit of the result.
class ThreadTuner {
 public:
  // Tunes between 1 and `most` threads (the default count); with `most` = 1 it does nothing.
  // A count above the one in use is timed only while `others` (given the count in use) leaves
  // it that many of the machine's `cpus`.
  explicit ThreadTuner(int most, std::function<int(int)> others = others_running,
                       int cpus = online_cpu_count());
  // After a step that took `seconds` (of wall time, the step alone): may set OpenMP's thread
  // count for the steps that follow.
  void record(double seconds);
  // Steps run so far with each count, index = threads − 1.
  const std::vector<long>& steps_with() const { return steps_with_; }

 private:
  void use(int threads);
  std::size_t candidate(std::size_t trial) const;

  std::function<int(int)> others_;
  int cpus_ = 1;
  std::vector<int> counts_;        // the candidates: most, most/2, ..., 1
  std::vector<double> per_step_;   // each one's last measured seconds a step
  std::vector<long> steps_with_;
  std::size_t trial_ = 0;          // the position in the exploration being timed (candidate())
  double yardstick_ = 0.0;         // the exploration's best seconds a step so far
  bool exploring_ = true;
  bool confirmed_ = false;         // a choice has passed its checks (kCheckWindows)
  bool skipped_ = false;           // this exploration left a count untimed (others_)
  long skip_ = 0;                  // steps still to pass untimed
  std::size_t best_ = 0;
  long window_steps_ = 0;
  double window_seconds_ = 0.0;
  long windows_held_ = 0;          // windows at the best count since the last exploration
  double held_seconds_ = 0.0;      // their seconds a step, summed
  int current_ = 1;
};

}  // namespace cosserat
