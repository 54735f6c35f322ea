#pragma once
// A portable x86-64 build (the release preset) vectorises two doubles wide. Its hottest loops
// (the force kernel's interior rows, the contact walk's planes) carry a second copy compiled
// for AVX2, four wide, taken where the CPU has AVX2 (docs/kernel.md, "The run-time wide
// kernel"). A copy may use no FMA ("avx2", not "arch=x86-64-v3"), so that it rounds every
// operation as the portable one does: the same bits on every x86-64 CPU. A build for a CPU
// that has AVX2 already (-march=native) needs none.

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__AVX2__)
#define COSSERAT_WIDE_COPIES 1
#else
#define COSSERAT_WIDE_COPIES 0
#endif

namespace cosserat {

// Whether this build carries the copies and the CPU runs them.
inline bool wide_copies_available() {
#if COSSERAT_WIDE_COPIES
  static const bool cpu_has_avx2 = __builtin_cpu_supports("avx2");
  return cpu_has_avx2;
#else
  return false;
#endif
}

}  // namespace cosserat
