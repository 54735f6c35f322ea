#include "cosserat/grid/threads.hpp"

#include <omp.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
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
  // With OMP_PROC_BIND the runtime binds the initial thread to its first place as it starts,
  // so the thread's own mask holds one core: the rank's CPUs are all its places'.
  if (omp_get_proc_bind() != omp_proc_bind_false)
    for (int place = 0; place < omp_get_num_places(); ++place) {
      std::vector<int> ids(static_cast<std::size_t>(omp_get_place_num_procs(place)));
      omp_get_place_proc_ids(place, ids.data());
      for (const int id : ids) CPU_SET(id, &mask);
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

int procs_running() {
  std::ifstream file("/proc/stat");
  for (std::string line; std::getline(file, line);) {
    if (line.rfind("procs_running ", 0) != 0) continue;
    try {
      return std::stoi(line.substr(14));
    } catch (const std::exception&) {
      return 0;
    }
  }
  return 0;
}

bool explicit_thread_count() {
  const char* value = std::getenv("OMP_NUM_THREADS");
  return value != nullptr && *value != '\0';
}

}  // namespace

int online_cpu_count() { return static_cast<int>(online_cpus()); }

// The least of three readings 0.1 ms apart: a task that runs for a moment (a kernel thread, a
// shell) is not another program holding a core, and one reading caught one often enough on the
// idle VM to keep S6's whole 1 s run at one thread.
int others_running(int mine) {
  int least = procs_running();
  for (int i = 0; i < 2 && least > mine; ++i) {
    usleep(100);
    least = std::min(least, procs_running());
  }
  return std::max(0, least - mine);
}

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

const std::vector<long>& RowBalance::split(long rows, int threads) {
  const auto bands = static_cast<std::size_t>(std::max(threads, 1));
  if (first_row_.size() != bands + 1 || first_row_.back() != rows) {
    first_row_.resize(bands + 1);
    for (std::size_t t = 0; t <= bands; ++t)
      first_row_[t] = rows * static_cast<long>(t) / static_cast<long>(bands);
    seconds_.assign(bands, 0.0);
    row_cost_.assign(bands, 0.0);
  }
  return first_row_;
}

void RowBalance::assign(std::vector<long> first_row) {
  first_row_ = std::move(first_row);
  const std::size_t bands = first_row_.empty() ? 0 : first_row_.size() - 1;
  seconds_.assign(bands, 0.0);
  row_cost_.assign(bands, 0.0);
}

void RowBalance::rebalance() {
  const std::size_t bands = seconds_.size();
  if (bands < 2) return;
  // One step's time carries the noise of the machine (a timer tick, another process), so a
  // thread's cost a row is smoothed over about ten steps and a single step moves it by at most
  // a factor of two.
  constexpr double kWeight = 0.1;
  for (std::size_t t = 0; t < bands; ++t) {
    const long rows = first_row_[t + 1] - first_row_[t];
    const double seconds = std::exchange(seconds_[t], 0.0);  // each measurement counts once
    if (rows <= 0 || !(seconds > 0.0)) continue;
    const double cost = seconds / static_cast<double>(rows);
    double& smoothed = row_cost_[t];
    if (smoothed > 0.0)
      smoothed += kWeight * (std::clamp(cost, 0.5 * smoothed, 2.0 * smoothed) - smoothed);
    else
      smoothed = cost;
  }
  double total_rate = 0.0;
  for (const double cost : row_cost_) {
    if (!(cost > 0.0)) return;  // a thread not yet measured: keep the split
    total_rate += 1.0 / cost;
  }
  const long rows = first_row_.back();
  if (rows < static_cast<long>(bands)) return;
  double rate = 0.0;
  for (std::size_t t = 1; t < bands; ++t) {
    rate += 1.0 / row_cost_[t - 1];
    const long row = std::lround(static_cast<double>(rows) * rate / total_rate);
    // Every band keeps at least one row.
    first_row_[t] = std::clamp(row, first_row_[t - 1] + 1, rows - static_cast<long>(bands - t));
  }
}

namespace {

// A window ends after at least this much wall time and this many steps: long enough that one
// descheduling of a few milliseconds does not decide it, short enough that a slow trial costs
// little. A few steps suffice where a step is long (a 1024² sheet's 45 ms). Until a choice
// has passed its checks (the kCheckWindows windows after it) the windows are shorter, so that
// a short run does not spend most of itself at its first counts (the round tablecloth's 0.5 s
// takes 0.23 s on one thread, 0.1 ms a step while the cloth falls and about four times that
// once it lies on the table): a choice made on the falling cloth against a trial on the
// landing one disappoints in its checks, and is timed again soon.
constexpr long kWindowSteps = 4;
constexpr double kWindowSeconds = 0.05;
constexpr double kFirstWindowSeconds = 0.01;
// A run's first steps touch the row buffers for the first time, and are not timed.
constexpr long kWarmSteps = 2;
// Windows at the best count between two explorations: with two candidates, one window in
// this many is spent timing the other, a few per cent of a run at most.
constexpr long kHoldWindows = 40;
// The windows after a choice that check it.
constexpr long kCheckWindows = 3;
// A candidate must be this much faster to replace the one in use: timing noise on a VM is a
// few per cent (docs/kernel.md).
constexpr double kMargin = 0.95;
// A trial is cut short once it has taken this much longer than kAbandonFactor times the best
// so far would have for its steps: a team waiting for a descheduled thread runs five times
// slower on a busy machine, and a whole window of it cost short runs up to twice their time
// (docs/parallel.md). The factor keeps a trial that meets a costlier part of the run (cloth
// landing on a table) from being cut short on an idle machine.
constexpr double kAbandonFactor = 2.0;
constexpr double kAbandonSeconds = 0.005;
// The count in use is timed afresh at once, without finishing its window, once the window has
// taken this much longer than kHeldFactor times what the count took when chosen: a team
// waiting for a descheduled thread ran 7 to 380 times slower than it had in its trial on the
// round tablecloth with another program busy (docs/parallel.md), where the cloth's landing
// makes a step about 4 times as costly on an idle machine.
constexpr double kHeldFactor = 5.0;

}  // namespace

// Explorations time the count in use first, for a fresh yardstick, then the others. The first
// starts at one thread, which no other count can make a run slower than: a trial of more is
// cut short when it is hopeless, where a first window at the default count, with no yardstick
// yet, ran whole on a busy machine (its descheduled steps cost the round tablecloth's 0.5 s
// 0.05 s or more of its 0.23 s).
ThreadTuner::ThreadTuner(int most, std::function<int(int)> others, int cpus)
    : others_(std::move(others)), cpus_(std::max(cpus, 1)) {
  for (int t = std::max(most, 1); t >= 1; t /= 2) {
    counts_.push_back(t);
    if (t == 1) break;
  }
  per_step_.assign(counts_.size(), 0.0);
  steps_with_.assign(static_cast<std::size_t>(std::max(most, 1)), 0);
  exploring_ = counts_.size() > 1;
  current_ = counts_.front();
  best_ = counts_.size() - 1;
  use(counts_[best_]);
  skip_ = kWarmSteps;
}

void ThreadTuner::use(int threads) {
  if (threads != current_) omp_set_num_threads(threads);
  current_ = threads;
}

// The candidate timed at position `trial` of an exploration: the best first, then the others.
std::size_t ThreadTuner::candidate(std::size_t trial) const {
  if (trial == 0) return best_;
  return trial <= best_ ? trial - 1 : trial;
}

void ThreadTuner::record(double seconds) {
  ++steps_with_[static_cast<std::size_t>(current_ - 1)];
  if (counts_.size() < 2) return;
  if (skip_ > 0) {
    --skip_;
    return;
  }
  ++window_steps_;
  window_seconds_ += seconds;
  const double steps = static_cast<double>(window_steps_);
  const bool hopeless =
      exploring_ && trial_ > 0 &&
      window_seconds_ > kAbandonFactor * yardstick_ * steps + kAbandonSeconds;
  const bool collapsed =
      !exploring_ && window_seconds_ > kHeldFactor * per_step_[best_] * steps + kAbandonSeconds;
  const double window = confirmed_ ? kWindowSeconds : kFirstWindowSeconds;
  if (!hopeless && !collapsed && (window_steps_ < kWindowSteps || window_seconds_ < window))
    return;
  const double per_step = window_seconds_ / steps;
  window_steps_ = 0;
  window_seconds_ = 0.0;
  if (collapsed) {
    // The window stands for the count in use in a new exploration, which goes on to the others.
    exploring_ = true;
    trial_ = 0;
    skipped_ = false;
  }
  if (exploring_) {
    per_step_[candidate(trial_)] = per_step;
    yardstick_ = trial_ == 0 ? per_step : std::min(yardstick_, per_step);
    while (++trial_ < counts_.size()) {
      // Waking a thread whose core another program holds took 37-68 ms on the round
      // tablecloth with a busy loop beside it, a sixth of its 0.23 s, however short the trial
      // (docs/parallel.md): a count the machine has no free cores for is not timed this round.
      const std::size_t next = candidate(trial_);
      if (counts_[next] > current_ && others_(current_) + counts_[next] > cpus_) {
        per_step_[next] = std::numeric_limits<double>::infinity();
        skipped_ = true;
        continue;
      }
      use(counts_[next]);
      return;
    }
    // The one in use before keeps its place unless another is clearly faster.
    std::size_t best = best_;
    for (std::size_t i = 0; i < counts_.size(); ++i)
      if (per_step_[i] < kMargin * per_step_[best]) best = i;
    best_ = best;
    exploring_ = false;
    windows_held_ = 0;
    held_seconds_ = 0.0;
    use(counts_[best_]);
    return;
  }
  // A count chosen on one lucky window shows itself in the next few: then it is timed again at
  // once rather than kept for kHoldWindows.
  held_seconds_ += per_step;
  ++windows_held_;
  // A count left untimed for want of cores is asked after again as soon.
  const bool disappointing =
      windows_held_ == kCheckWindows &&
      (skipped_ || held_seconds_ / kCheckWindows * kMargin > per_step_[best_]);
  if (windows_held_ == kCheckWindows && !disappointing) confirmed_ = true;
  if (!disappointing && windows_held_ < kHoldWindows) return;
  exploring_ = true;
  trial_ = 0;
  skipped_ = false;
}

}  // namespace cosserat
