// Peak FP64 arithmetic rates of this machine, the compute ceilings of the roofline
// (benchmarks/roofline.py): fused multiply-adds, square roots and divisions on scalars, ymm
// (4 lanes) and zmm (8 lanes) registers, on 1 and 2 threads. The force kernel takes about five
// square roots and several divisions a node, which run on the divider, slower than the FMAs.
// Reported as results per second (lanes × instructions); FMAs also as flops (2 per lane), over
// the longest CPU time of the threads (thread_time.hpp).
// x86-64 only: the vector widths are those the build targets (-march=native in the benchmark
// preset), and only the scalar rates exist in a portable build.

#include <benchmark/benchmark.h>
#include <immintrin.h>
#include <omp.h>

#include <cmath>
#include <string>

#include "thread_time.hpp"

namespace {

// Each thread runs this many independent dependency chains: enough to keep every port busy
// through the latency (FMA: 4 cycles on 2 ports, so 8 in flight; sqrt and div: ~20 cycles at
// one result per 4–16), and few enough to stay in the 32 vector registers.
constexpr int kChains = 16;
constexpr long kRounds = 1L << 18;

// One register's lanes, through the intrinsics of the widths this build targets.
template <int lanes>
struct Simd;

template <>
struct Simd<1> {
  using Type = double;
  static Type splat(double x) { return x; }
  // std::sqrt as the kernel calls it (with errno, a compare and a never-taken branch).
  static Type root(Type x) { return std::sqrt(x); }
  static double first(Type x) { return x; }
  // Hides the value from the optimiser, which would otherwise pack the 16 scalar chains into
  // two zmm registers.
  static Type opaque(Type x) {
    asm("" : "+v"(x));
    return x;
  }
};

#if defined(__AVX__)
template <>
struct Simd<4> {
  using Type = __m256d;
  static Type splat(double x) { return _mm256_set1_pd(x); }
  static Type root(Type x) { return _mm256_sqrt_pd(x); }
  static double first(Type x) { return x[0]; }
  static Type opaque(Type x) { return x; }
};
#endif

#if defined(__AVX512F__)
template <>
struct Simd<8> {
  using Type = __m512d;
  static Type splat(double x) { return _mm512_set1_pd(x); }
  // The masked form: _mm512_sqrt_pd trips GCC 12's -Wuninitialized (GCC bug 105593).
  static Type root(Type x) { return _mm512_maskz_sqrt_pd(0xff, x); }
  static double first(Type x) { return x[0]; }
  static Type opaque(Type x) { return x; }
};
#endif

enum class Operation { fma, sqrt, div };

// Every chain iterates a map with a fixed point of a generic mantissa (1 for the FMA, 3.32 and
// the golden ratio for sqrt and div), so no operand becomes denormal, infinite or trivial, and
// starts away from it: GCC folds a chain that starts at the FMA's fixed point, 1.0, to a
// constant, and the loop then runs 15 FMAs while 16 are counted.
template <int lanes, Operation op>
void arithmetic_rate(benchmark::State& state) {
  using S = Simd<lanes>;
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  for (auto _ : state) {
    double longest = 0.0;
#pragma omp parallel reduction(max : longest)
    {
      const double start = cosserat::bench::thread_seconds();
      const typename S::Type scale = S::splat(0.999999), shift = S::splat(1e-6);
      const typename S::Type one = S::splat(1.0), offset = S::splat(1.5);
      typename S::Type x[kChains];
      for (int c = 0; c < kChains; ++c) x[c] = S::splat(2.0 + 1e-3 * c);
      for (long round = 0; round < kRounds; ++round) {
#pragma GCC unroll 16
        for (int c = 0; c < kChains; ++c) {
          if constexpr (op == Operation::fma)
            x[c] = S::opaque(x[c] * scale + shift);
          else if constexpr (op == Operation::sqrt)
            x[c] = S::opaque(S::root(x[c]) + offset);
          else
            x[c] = S::opaque(one / x[c] + one);
        }
      }
      double sum = 0.0;
      for (int c = 0; c < kChains; ++c) sum += S::first(x[c]);
      benchmark::DoNotOptimize(sum);
      longest = cosserat::bench::thread_seconds() - start;
    }
    state.SetIterationTime(longest);
  }
  const double results = static_cast<double>(state.iterations()) * threads * kRounds * kChains * lanes;
  state.counters["results_per_second"] = benchmark::Counter(results, benchmark::Counter::kIsRate);
  if constexpr (op == Operation::fma)
    state.counters["flops_per_second"] = benchmark::Counter(2.0 * results, benchmark::Counter::kIsRate);
  state.counters["lanes"] = lanes;
  state.counters["threads"] = threads;
}

// Named op/lanes:N/threads:T, e.g. fma/lanes:8/threads:2.
template <int lanes>
void register_rates() {
  const std::string suffix = "/lanes:" + std::to_string(lanes);
  benchmark::RegisterBenchmark(("fma" + suffix).c_str(), arithmetic_rate<lanes, Operation::fma>)
      ->ArgName("threads")->DenseRange(1, 2)->UseManualTime();
  benchmark::RegisterBenchmark(("sqrt" + suffix).c_str(), arithmetic_rate<lanes, Operation::sqrt>)
      ->ArgName("threads")->DenseRange(1, 2)->UseManualTime();
  benchmark::RegisterBenchmark(("div" + suffix).c_str(), arithmetic_rate<lanes, Operation::div>)
      ->ArgName("threads")->DenseRange(1, 2)->UseManualTime();
}

}  // namespace

int main(int argc, char** argv) {
  register_rates<1>();
#if defined(__AVX__)
  register_rates<4>();
#endif
#if defined(__AVX512F__)
  register_rates<8>();
#endif
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
