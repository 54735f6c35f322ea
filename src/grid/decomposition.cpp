#include "cosserat/grid/decomposition.hpp"

#include <fmt/format.h>

#include <limits>
#include <optional>

namespace cosserat {

namespace {

// `parts` nearly equal pieces of [0, size): the first size % parts one node longer.
std::vector<int> cuts(int size, int parts) {
  std::vector<int> c(static_cast<std::size_t>(parts) + 1, 0);
  for (int i = 0; i < parts; ++i)
    c[static_cast<std::size_t>(i) + 1] =
        c[static_cast<std::size_t>(i)] + size / parts + (i < size % parts ? 1 : 0);
  return c;
}

// A split direction is possible when its narrowest block still holds a full ghost ring of its
// neighbours: the halo exchange reads ghosts from the adjacent block only.
bool fits(int size, int parts) { return parts == 1 || size / parts >= kGhostWidth; }

std::vector<int> widths(const std::vector<int>& cuts) {
  std::vector<int> w;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) w.push_back(cuts[i + 1] - cuts[i]);
  return w;
}

}  // namespace

Decomposition::Decomposition(int m, int n, int parts_k, int parts_l)
    : m_(m), n_(n), k_cuts_(cuts(m, parts_k)), l_cuts_(cuts(n, parts_l)) {}

Decomposition Decomposition::with_parts(int m, int n, int parts_k, int parts_l) {
  if (parts_k < 1 || parts_l < 1)
    throw DecompositionError(fmt::format("a split into {} x {} blocks is empty", parts_k, parts_l));
  if (!fits(m, parts_k) || !fits(n, parts_l))
    throw DecompositionError(fmt::format(
        "grid {} x {} split into {} x {} blocks leaves a block narrower than {} nodes, the "
        "ghost width of the stencil (docs/parallel.md)",
        m, n, parts_k, parts_l, kGhostWidth));
  return Decomposition(m, n, parts_k, parts_l);
}

Decomposition Decomposition::choose(int m, int n, int ranks) {
  std::optional<Decomposition> best;
  double best_cut = std::numeric_limits<double>::infinity();
  for (int parts_k = 1; parts_k <= ranks; ++parts_k) {
    if (ranks % parts_k != 0) continue;
    const int parts_l = ranks / parts_k;
    if (!fits(m, parts_k) || !fits(n, parts_l)) continue;
    const double cut = static_cast<double>(parts_k - 1) * n + static_cast<double>(parts_l - 1) * m;
    if (cut < best_cut) {
      best_cut = cut;
      best = Decomposition(m, n, parts_k, parts_l);
    }
  }
  if (!best)
    throw DecompositionError(fmt::format(
        "grid {} x {} cannot be split over {} MPI ranks: every split leaves a block narrower "
        "than {} nodes, the ghost width of the stencil (docs/parallel.md); use fewer ranks",
        m, n, ranks, kGhostWidth));
  return *best;
}

Block Decomposition::block(int rank, MPI_Comm comm) const {
  const auto i = static_cast<std::size_t>(rank % parts_k());
  const auto j = static_cast<std::size_t>(rank / parts_k());
  return Block{comm, m_, n_, k_cuts_[i], k_cuts_[i + 1], l_cuts_[j], l_cuts_[j + 1], kGhostWidth};
}

std::vector<int> Decomposition::widths_k() const { return widths(k_cuts_); }
std::vector<int> Decomposition::widths_l() const { return widths(l_cuts_); }

int Decomposition::rank_of(int i, int j) const {
  if (i < 0 || i >= parts_k() || j < 0 || j >= parts_l()) return MPI_PROC_NULL;
  return i + parts_k() * j;
}

}  // namespace cosserat
