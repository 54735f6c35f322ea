#include "cosserat/time/edge_check.hpp"

#include <omp.h>

#include <algorithm>
#include <climits>

namespace cosserat {

namespace {
// docs/equations.md §4.2: the edge from a node moved by `a` to one moved by `b` changed by more
// than the limit. Written so that a NaN also fails; an int, which the loops' reductions vectorise
// (a bool does not, with g++ 12).
inline int changed(double ax, double ay, double az, double bx, double by, double bz,
                   double limit2) {
  const double x = ax - bx, y = ay - by, z = az - bz;
  return !(x * x + y * y + z * z <= limit2) ? 1 : 0;
}
}  // namespace

EdgeCheck::EdgeCheck(const Block& block, double limit)
    : block_(&block),
      limit2_(limit * limit),
      may_fail_(static_cast<std::size_t>(block.owned_l()), 0),
      below_done_(static_cast<std::size_t>(block.owned_l()), 0) {}

// The one edge from node (ka, la) to node (kb, lb).
bool EdgeCheck::edge(int ka, int la, int kb, int lb, const Field<Vec3>& r,
                     const Field<Vec3>& next) const {
  const Vec3 a = next(ka, la) - r(ka, la), b = next(kb, lb) - r(kb, lb);
  return changed(a.x, a.y, a.z, b.x, b.y, b.z, limit2_) != 0;
}

// The edges from node i of (p, q) to node i of (p2, q2), i in [0, count): r⁺ and r at the
// edges' two ends, each a run of a row.
bool EdgeCheck::runs_changed(const Vec3* p, const Vec3* q, const Vec3* p2, const Vec3* q2,
                             int count) const {
  const double limit2 = limit2_;
  int flagged = 0;
#pragma omp simd reduction(| : flagged)
  for (int i = 0; i < count; ++i)
    flagged |= changed(p[i].x - q[i].x, p[i].y - q[i].y, p[i].z - q[i].z,
                       p2[i].x - q2[i].x, p2[i].y - q2[i].y, p2[i].z - q2[i].z, limit2);
  return flagged != 0;
}

// Edges (la, la + 1) of columns [ka, kb).
bool EdgeCheck::vertical(int la, int ka, int kb, const Field<Vec3>& r,
                         const Field<Vec3>& next) const {
  return runs_changed(&next(ka, la), &r(ka, la), &next(ka, la + 1), &r(ka, la + 1), kb - ka);
}

// The edges (k, l)–(k + 1, l) within the owned columns.
bool EdgeCheck::horizontal(int l, const Field<Vec3>& r, const Field<Vec3>& next) const {
  const Block& b = *block_;
  const Vec3 *p = &next(b.k0, l), *q = &r(b.k0, l);
  return runs_changed(p, q, p + 1, q + 1, b.owned_k() - 1);
}

void EdgeCheck::begin_walk() {
  walkers_.resize(static_cast<std::size_t>(omp_get_max_threads()));
  for (Walker& w : walkers_) w.last = INT_MIN;
  walked_ = true;
}

void EdgeCheck::walk_row(int l, const Field<Vec3>& r, const Field<Vec3>& next) {
  const Block& b = *block_;
  Walker& walker = walkers_[static_cast<std::size_t>(omp_get_thread_num())];
  const int w = b.owned_k();
  const auto width = static_cast<std::size_t>(w);
  // Sized, and so first touched, by the thread that uses it.
  if (walker.moves.size() != 6 * width) walker.moves.assign(6 * width, 0.0);
  // Row l's moves go where the row before the last one's were.
  double* move = walker.moves.data() + ((l & 1) != 0 ? 3 * width : 0);
  const double* below = walker.moves.data() + ((l & 1) != 0 ? 0 : 3 * width);
  const Vec3 *p = &next(b.k0, l), *q = &r(b.k0, l);
#pragma omp simd
  for (int i = 0; i < w; ++i) {
    move[i] = p[i].x - q[i].x;
    move[width + i] = p[i].y - q[i].y;
    move[2 * width + i] = p[i].z - q[i].z;
  }
  const double *x = move, *y = move + width, *z = move + 2 * width;
  const double limit2 = limit2_;
  int flagged = 0;
#pragma omp simd reduction(| : flagged)
  for (int i = 0; i < w - 1; ++i)
    flagged |= changed(x[i], y[i], z[i], x[i + 1], y[i + 1], z[i + 1], limit2);
  const auto row = static_cast<std::size_t>(l - b.l0);
  below_done_[row] = walker.last == l - 1;
  if (below_done_[row]) {
    const double *bx = below, *by = below + width, *bz = below + 2 * width;
    int vertical_flagged = 0;
#pragma omp simd reduction(| : vertical_flagged)
    for (int i = 0; i < w; ++i)
      vertical_flagged |= changed(bx[i], by[i], bz[i], x[i], y[i], z[i], limit2);
    if (vertical_flagged != 0) {
      flagged = 1;
      may_fail_[row - 1] = 1;
    }
  }
  may_fail_[row] = static_cast<char>(flagged);
  walker.last = l;
}

const std::vector<char>& EdgeCheck::flag_rows(const Field<Vec3>& r, const Field<Vec3>& next,
                                              const std::vector<char>* moved) {
  const Block& b = *block_;
  const bool walked = walked_;
  if (!walked_) {
    begin_walk();
    // Static: each thread's rows are one ascending range, as in a scheme's walk.
#pragma omp parallel for schedule(static)
    for (int l = b.l0; l < b.l1; ++l) walk_row(l, r, next);
  }
  walked_ = false;
  auto flag = [&](int l) {
    if (l >= b.l0 && l < b.l1) may_fail_[static_cast<std::size_t>(l - b.l0)] = 1;
  };
  // The edges between threads' rows, and to the ghost row below and above the block.
  for (int l = std::max(b.l0, 1); l < b.l1; ++l)
    if (!below_done_[static_cast<std::size_t>(l - b.l0)] && vertical(l - 1, b.k0, b.k1, r, next)) {
      flag(l - 1);
      flag(l);
    }
  if (b.l1 < b.n && vertical(b.l1 - 1, b.k0, b.k1, r, next)) flag(b.l1 - 1);
  // The edges to the ghost columns.
  if (b.k0 > 0 || b.k1 < b.m)
    for (int l = b.l0; l < b.l1; ++l) {
      if ((b.k0 > 0 && edge(b.k0 - 1, l, b.k0, l, r, next)) ||
          (b.k1 < b.m && edge(b.k1 - 1, l, b.k1, l, r, next)))
        flag(l);
    }
  // What the walk tested before an action moved the row: the walk's flags stay, a superset of
  // the rows to scan (a flag only costs the scan), and the moved rows' edges are tested anew.
  if (walked && moved != nullptr)
    for (int l = b.l0; l < b.l1; ++l) {
      if (!(*moved)[static_cast<std::size_t>(l - b.l0)]) continue;
      const auto row = static_cast<std::size_t>(l - b.l0);
      if (horizontal(l, r, next)) flag(l);
      // The edges to the row below, and to the row above unless that moved too and tests them.
      if (l > b.l0 && vertical(l - 1, b.k0, b.k1, r, next)) {
        flag(l - 1);
        flag(l);
      }
      if (l + 1 < b.l1 && !(*moved)[row + 1] && vertical(l, b.k0, b.k1, r, next)) {
        flag(l);
        flag(l + 1);
      }
    }
  // A lone node has no edge: only its own test can fail it.
  if (b.m == 1 && b.n == 1) flag(0);
  return may_fail_;
}

}  // namespace cosserat
