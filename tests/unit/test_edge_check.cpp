// The stability check's edge test (docs/equations.md §4.2) flags exactly the rows that hold a node
// with an edge that changed too much, whether a scheme's row walk tested most edges while its rows
// were in cache or the check tested them all in its own pass: the check then scans only those
// rows, so a row missed would be a failure missed.

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <limits>
#include <set>
#include <utility>
#include <vector>

#include "cosserat/time/edge_check.hpp"

namespace cosserat {
namespace {

constexpr double kLimit = 0.05;

// r at rest, r⁺ the same but for one node moved by `move` (ghosts included, as after the
// exchange).
struct States {
  Field<Vec3> r, next;
  States(const Block& b, int k, int l, const Vec3& move) : r(b), next(b) {
    for (int j = std::max(b.l0 - b.ghost, 0); j < std::min(b.l1 + b.ghost, b.n); ++j)
      for (int i = std::max(b.k0 - b.ghost, 0); i < std::min(b.k1 + b.ghost, b.m); ++i) {
        r(i, j) = next(i, j) = {0.1 * i, 0.0, 0.1 * j};
        if (i == k && j == l) next(i, j) = next(i, j) + move;
      }
  }
};

// Threads walk their rows as the kernel hands them over: each an ascending band.
void walk(EdgeCheck& check, const Block& b, const States& s) {
  check.begin_walk();
#pragma omp parallel
  {
    const int t = omp_get_thread_num(), threads = omp_get_num_threads();
    const long rows = b.owned_l();
    for (int l = b.l0 + static_cast<int>(rows * t / threads);
         l < b.l0 + static_cast<int>(rows * (t + 1) / threads); ++l)
      check.walk_row(l, s.r, s.next);
  }
}

std::set<int> flagged(const std::vector<char>& flags, const Block& b) {
  std::set<int> rows;
  for (int l = b.l0; l < b.l1; ++l)
    if (flags[static_cast<std::size_t>(l - b.l0)]) rows.insert(l);
  return rows;
}

// A node moved too far, to infinity or to NaN, on every position of the grid: the rows flagged
// are its own and those of its neighbours above and below that this block owns, and no other,
// for the whole grid and for blocks of it with ghosts on every side, with and without a walk, on
// 1, 2 and 3 threads (bands of one row included).
TEST(EdgeCheck, FlagsExactlyTheRowsOfTheNodesWhoseEdgesChanged) {
  const int m = 9, n = 7;
  Block whole = Block::whole(m, n, MPI_COMM_SELF);
  Block inner = whole, corner = whole;
  inner.k0 = 2, inner.k1 = 6, inner.l0 = 2, inner.l1 = 5;
  corner.k0 = 5, corner.l0 = 3;
  const int default_threads = omp_get_max_threads();
  std::vector<Vec3> moves{{0.0, 1.01 * kLimit, 0.0},
                          {std::numeric_limits<double>::infinity(), 0.0, 0.0}};
#if !defined(COSSERAT_TRAP_FPE)
  // Where a NaN does not trap: the debug build stops at the operation that makes one, so no NaN
  // ever reaches the check there, and comparing one would trap.
  moves.push_back({std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0});
#endif
  for (const Block* block : {&whole, &inner, &corner})
    for (const Vec3& move : moves)
      for (const int threads : {1, 2, 3})
        for (const bool walked : {false, true}) {
          const Block& b = *block;
          omp_set_num_threads(threads);
          EdgeCheck check(b, kLimit);
          for (int l = std::max(b.l0 - 1, 0); l < std::min(b.l1 + 1, n); ++l)
            for (int k = std::max(b.k0 - 1, 0); k < std::min(b.k1 + 1, m); ++k) {
              const States s(b, k, l, move);
              check.arm(true);
              if (walked) walk(check, b, s);
              // The rows of the owned nodes among it and its four neighbours.
              std::set<int> expected;
              for (const auto& [kk, ll] : {std::pair{k, l}, std::pair{k - 1, l},
                                           std::pair{k + 1, l}, std::pair{k, l - 1},
                                           std::pair{k, l + 1}})
                if (b.owns(kk, ll)) expected.insert(ll);
              EXPECT_EQ(flagged(check.flag_rows(s.r, s.next), b), expected)
                  << "block [" << b.k0 << ", " << b.k1 << ") x [" << b.l0 << ", " << b.l1
                  << "), node (" << k << ", " << l << "), " << threads << " threads"
                  << (walked ? ", walked" : "");
            }
        }
  omp_set_num_threads(default_threads);
}

// A step action (a contact response) moves a node after the walk tested its rows, and marks
// its row: the rows flagged are again exactly its own and its owned neighbours', on every
// position of the grid and block and on 1, 2 and 3 threads. Left unmarked on one thread and the
// whole grid (no edge left to test after the walk), the move is missed: why an action that does
// not mark its rows keeps the walk from testing at all.
TEST(EdgeCheck, TestsTheRowsAnActionMovedAfterTheWalkAgain) {
  const int m = 9, n = 7;
  Block whole = Block::whole(m, n, MPI_COMM_SELF);
  Block inner = whole;
  inner.k0 = 2, inner.k1 = 6, inner.l0 = 2, inner.l1 = 5;
  const int default_threads = omp_get_max_threads();
  const Vec3 move{0.0, 1.01 * kLimit, 0.0};
  for (const Block* block : {&whole, &inner})
    for (const int threads : {1, 2, 3}) {
      const Block& b = *block;
      omp_set_num_threads(threads);
      EdgeCheck check(b, kLimit);
      for (int l = b.l0; l < b.l1; ++l)
        for (int k = b.k0; k < b.k1; ++k) {
          States s(b, -1, -1, {});
          std::set<int> expected;
          for (const auto& [kk, ll] : {std::pair{k, l}, std::pair{k - 1, l}, std::pair{k + 1, l},
                                       std::pair{k, l - 1}, std::pair{k, l + 1}})
            if (b.owns(kk, ll)) expected.insert(ll);
          std::vector<char> moved(static_cast<std::size_t>(b.owned_l()), 0);
          for (const bool marked : {true, false}) {
            if (!marked && (block != &whole || threads != 1)) continue;
            check.arm(true);
            walk(check, b, s);
            s.next(k, l) = s.r(k, l) + move;
            moved[static_cast<std::size_t>(l - b.l0)] = marked ? 1 : 0;
            EXPECT_EQ(flagged(check.flag_rows(s.r, s.next, &moved), b),
                      marked ? expected : std::set<int>{})
                << "block [" << b.k0 << ", " << b.k1 << ") x [" << b.l0 << ", " << b.l1
                << "), node (" << k << ", " << l << "), " << threads << " threads"
                << (marked ? "" : ", unmarked");
            s.next(k, l) = s.r(k, l);
          }
        }
    }
  omp_set_num_threads(default_threads);
}

// A move just inside the limit, relative to every neighbour, flags nothing; a rigid move of
// any size neither.
TEST(EdgeCheck, FlagsNoRowForMovesWithinTheLimitOrARigidMove) {
  const Block b = Block::whole(8, 6, MPI_COMM_SELF);
  EdgeCheck check(b, kLimit);
  const States small(b, 3, 2, {0.0, 0.99 * kLimit, 0.0});
  check.arm(true);
  EXPECT_TRUE(flagged(check.flag_rows(small.r, small.next), b).empty());
  States rigid(b, -1, -1, {});
  for (int l = 0; l < b.n; ++l)
    for (int k = 0; k < b.m; ++k) rigid.next(k, l) = rigid.next(k, l) + Vec3{5.0, -3.0, 1.0};
  check.arm(true);
  walk(check, b, rigid);
  EXPECT_TRUE(flagged(check.flag_rows(rigid.r, rigid.next), b).empty());
}

}  // namespace
}  // namespace cosserat
