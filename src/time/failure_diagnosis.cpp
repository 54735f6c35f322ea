#include "cosserat/time/failure_diagnosis.hpp"

#include <mpi.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace cosserat {

namespace {

// How far around the failing node to look: the two ghost rings beyond a block edge bound it
// there; a fold or a crossing that stops a run is local.
constexpr int kReach = 6;
// Nodes this far apart in the grid (Chebyshev) are not neighbours of one stencil.
constexpr int kFarInGrid = 3;

struct Window {
  int k0, k1, l0, l1;  // [k0, k1) x [l0, l1), inside the grid and the block's ghosts
};

Window window_around(const Block& b, int k, int l) {
  return {std::max({k - kReach, b.k0 - b.ghost, 0}), std::min({k + kReach + 1, b.k1 + b.ghost, b.m}),
          std::max({l - kReach, b.l0 - b.ghost, 0}), std::min({l + kReach + 1, b.l1 + b.ghost, b.n})};
}

// The cell (k, l)–(k+1, l+1): its normal from the diagonals, and det a / det A from its edges
// (A = diag(h1², h2²) for the flat rest sheet).
Vec3 cell_normal(const Field<Vec3>& r, int k, int l) {
  return cross(r(k + 1, l + 1) - r(k, l), r(k, l + 1) - r(k + 1, l));
}
double cell_det_ratio(const Field<Vec3>& r, int k, int l, double h1, double h2) {
  const Vec3 e1 = r(k + 1, l) - r(k, l), e2 = r(k, l + 1) - r(k, l);
  return (dot(e1, e1) * dot(e2, e2) - dot(e1, e2) * dot(e1, e2)) / (h1 * h1 * h2 * h2);
}

std::string look(const Field<Vec3>& r, int k, int l, double h1, double h2) {
  const Block& b = r.block();
  const Window w = window_around(b, k, l);
  const double h = std::min(h1, h2);

  // Self-proximity first: a sheet through itself is the cause the others follow from.
  double closest = h / 2;
  int pk = -1, pl = -1, qk = -1, ql = -1;
  for (int l1 = w.l0; l1 < w.l1; ++l1)
    for (int k1 = w.k0; k1 < w.k1; ++k1)
      for (int l2 = l1; l2 < w.l1; ++l2)
        for (int k2 = w.k0; k2 < w.k1; ++k2) {
          if (std::max(std::abs(k2 - k1), std::abs(l2 - l1)) <= kFarInGrid) continue;
          const double d = norm(r(k2, l2) - r(k1, l1));
          if (d < closest) {
            closest = d;
            pk = k1, pl = l1, qk = k2, ql = l2;
          }
        }
  if (pk >= 0)
    return fmt::format(
        "the sheet passes through itself near node [{}, {}]: nodes [{}, {}] and [{}, {}], more "
        "than {} apart in the grid, are {:.2g} h apart",
        k, l, pk, pl, qk, ql, kFarInGrid, closest / h);

  double lowest_cosine = 1.0, lowest_ratio = 1.0;
  int fk = -1, fl = -1, ck = -1, cl = -1;
  for (int cl1 = w.l0; cl1 + 1 < w.l1; ++cl1)
    for (int ck1 = w.k0; ck1 + 1 < w.k1; ++ck1) {
      const Vec3 n = cell_normal(r, ck1, cl1);
      const double ratio = cell_det_ratio(r, ck1, cl1, h1, h2);
      if (ratio < lowest_ratio) lowest_ratio = ratio, ck = ck1, cl = cl1;
      // The cell beside it along k and along l, where both are inside the window.
      for (const auto& [dk, dl] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (ck1 + dk + 1 >= w.k1 || cl1 + dl + 1 >= w.l1) continue;
        const Vec3 m = cell_normal(r, ck1 + dk, cl1 + dl);
        const double cosine = dot(n, m) / (norm(n) * norm(m));
        if (cosine < lowest_cosine) lowest_cosine = cosine, fk = ck1, fl = cl1;
      }
    }
  if (lowest_cosine < -0.9)
    return fmt::format(
        "cells fold fully over near node [{}, {}]: the normals of cell [{}, {}] and its "
        "neighbour meet at cosine {:.3f}; the sheet folds more sharply than the grid resolves",
        k, l, fk, fl, lowest_cosine);
  if (lowest_ratio < 0.05)
    return fmt::format("cell [{}, {}] near node [{}, {}] collapsed: det a / det A = {:.2g}", ck,
                       cl, k, l, lowest_ratio);
  return fmt::format(
      "the sheet near node [{}, {}] is smooth (no fold, crossing or collapsed cell), so the step "
      "is the likely cause: try a smaller time.dt (`cosserat stable-dt SCENE` finds the largest "
      "stable one)",
      k, l);
}

}  // namespace

std::string diagnose_failure(const Field<Vec3>& r, int k, int l, double h1, double h2) {
  const Block& b = r.block();
  const int rank = rank_in(b.comm);
  const int mine = b.owns(k, l) ? rank : -1;
  int owner = mine;
  MPI_Allreduce(&mine, &owner, 1, MPI_INT, MPI_MAX, b.comm);
  std::string text = rank == owner ? look(r, k, l, h1, h2) : std::string();
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, owner, b.comm);
  text.resize(static_cast<std::size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, owner, b.comm);
  return text;
}

}  // namespace cosserat
