#pragma once
// The CPU time of the calling thread, for the ceiling benchmarks. The machine is shared with
// other work (two cores, other engineers' builds): a ceiling timed by the longest CPU time of
// its threads leaves out the time the scheduler gave a core to another process, which wall
// time would count against the hardware.

#include <time.h>

namespace cosserat::bench {

inline double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace cosserat::bench
