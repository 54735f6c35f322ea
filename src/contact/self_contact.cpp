#include "cosserat/contact/self_contact.hpp"

#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>

namespace cosserat {

namespace {

// Passes of the position and of the velocity correction (docs/contact.md, "Self-contact"):
// each moves a node by its pairs' relaxed moves, which never overshoots where several pairs
// press one node but leaves part of a shared correction to the next pass.
constexpr int kPasses = 8;

// A node within this fraction of the thickness above a fixed plane's offset surface lies on it.
constexpr double kOnFloor = 1e-6;

// The candidate lists' margin, in grid spacings: a node's box at a build, grown by it, meets the
// cells of its own four in a flat sheet. The lists serve until a node moves its leeway from
// where it was at the build: half the margin, or for a node that moves fast what its step at
// the build takes it in kLead steps, up to kMostLeeway margins. A few fast nodes (the folds of
// S6 with its loads x 5 at 240²) otherwise rebuild every node's list every few steps.
constexpr double kMargin = 0.25;
constexpr double kLead = 8.0;
constexpr double kMostLeeway = 2.0;

// Numbers per node sent to another rank: its number k + m l, start, end, velocity and the held
// mark.
constexpr int kPerNode = 11;

// Numbers per rank in the exchange of what its nodes reach (SelfContact::gather): the box of its
// nodes over the step (low and high corners), the largest extent at the step's start of the
// cells whose first corner it owns, the farthest one of its nodes moves in a coordinate,
// whether all its positions are finite, and the largest leeway of its nodes at its last build.
constexpr int kReach = 10;

// How many pairs apart the response can carry a node's state to another's: each pass of the
// positions and of the velocities moves a node by its pairs' moves, one pair further each pass,
// friction adds one, a pair's relaxation reads the pairs of its nodes, the statistics read a
// pair's other nodes after them, and an edges' pair reads the cells beside both edges. A
// node this many pairs from every node a rank owns cannot change what the rank's nodes end the
// step with.
constexpr int kHops = 2 * kPasses + 4;

// A rank is sent the nodes within this many times the reach of its own, and builds its lists
// again only when a node it does not hold comes within the reach itself.
constexpr double kSpare = 1.5;

// A cell's box, in spacings of the hash, may cover up to this many buckets; larger cells (a
// sheet tearing apart) are tested against every node.
constexpr long kMostBuckets = 27;
// A cell's own look-up (build_candidates, for the pairs of edges) is its box grown by its leeway
// and the thickness, up to about three mean cell extents a side where a corner moves fast, so
// four or five buckets of the hash a side: up to this many before every cell is taken.
constexpr long kMostCellBuckets = 125;
// A cell's six edges in the order SelfContact::cell_edges gives them (its sides at l, at
// l + 1, at k, at k + 1, its diagonals from (k, l) and from (k + 1, l)): each end's offsets in k
// and l from the cell's first node.
constexpr int kCellEdges[6][2][2] = {{{0, 0}, {1, 0}}, {{0, 1}, {1, 1}}, {{0, 0}, {0, 1}},
                                     {{1, 0}, {1, 1}}, {{0, 0}, {1, 1}}, {{1, 0}, {0, 1}}};

// Whether two boxes meet: six comparisons and no branch, as the look-ups that call it test cells
// that pass at random.
inline bool boxes_meet(const Vec3& alo, const Vec3& ahi, const Vec3& blo, const Vec3& bhi) {
  return !(bhi.x < alo.x) & !(blo.x > ahi.x) & !(bhi.y < alo.y) & !(blo.y > ahi.y) &
         !(bhi.z < alo.z) & !(blo.z > ahi.z);
}

struct Foot {
  double a, b, c;
  // Within `slack` of the triangle, in barycentric units.
  bool near(double slack) const { return a >= -slack && b >= -slack && c >= -slack; }
  // The nearest point of the triangle, approximately: the negative coordinates cut off.
  Foot clamped() const {
    const double ca = std::max(a, 0.0), cb = std::max(b, 0.0), cc = std::max(c, 0.0);
    const double sum = ca + cb + cc;
    return {ca / sum, cb / sum, cc / sum};
  }
};

// The barycentric coordinates of the foot of p on the plane of (a, b, c); all NaN for a
// triangle with no area.
Foot foot(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, w = p - a;
  const double d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
  const double w1 = dot(w, e1), w2 = dot(w, e2);
  const double denominator = d11 * d22 - d12 * d12;
  const double beta = (d22 * w1 - d12 * w2) / denominator;
  const double gamma = (d11 * w2 - d12 * w1) / denominator;
  return {1.0 - beta - gamma, beta, gamma};
}

Vec3 lerp(const Vec3& a, const Vec3& b, double t) { return a + t * (b - a); }

// A node's velocity at the step's end (SelfContact::respond).
Vec3 velocity_of(int k, int l, double dt, const Field<Vec3>& current, const Field<Vec3>& next,
                 const Field<Vec3>* next_velocities, const Field<Vec3>* starts) {
  return next_velocities != nullptr ? (*next_velocities)(k, l)
         : starts != nullptr        ? (next(k, l) - (*starts)(k, l)) / dt
                                    : (next(k, l) - current(k, l)) / dt;
}

// The buckets of each 4 x 4 x 4 block of space lie side by side (64 of them, 256 bytes of
// bucket_start_), and the blocks are hashed. A cell's box covers about 8 buckets, and the cells
// and nodes come in the grid's order, whose neighbours lie near in space, so the fill and the
// lists touch a few lines of memory where a hash of each bucket scattered them over the whole
// table: on S6 with its loads x 5 at 240² the builds' samples fell from 1.34 to 0.86 times the
// force kernel's (docs/contact.md, "Cost"). Any function of the bucket gives the same lists.
std::uint64_t bucket_of(std::int64_t i, std::int64_t j, std::int64_t k, std::uint64_t mask) {
  const auto block = static_cast<std::uint64_t>(i >> 2) * 73856093u ^
                     static_cast<std::uint64_t>(j >> 2) * 19349663u ^
                     static_cast<std::uint64_t>(k >> 2) * 83492791u;
  const auto within = static_cast<std::uint64_t>((i & 3) << 4 | (j & 3) << 2 | (k & 3));
  return (block << 6 | within) & mask;
}

// The sign of the volume of (a, b, c, d): which side of the plane through a, b, c d lies on.
int orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double volume = dot(cross(b - a, c - a), d - a);
  return (volume > 0.0) - (volume < 0.0);
}

// Whether the segment pq passes through the triangle abc (touching not counted).
bool through(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  if (orient(a, b, c, p) * orient(a, b, c, q) >= 0) return false;
  const int s1 = orient(p, q, a, b), s2 = orient(p, q, b, c), s3 = orient(p, q, c, a);
  return s1 != 0 && s1 == s2 && s2 == s3;
}

}  // namespace

SelfContact::SelfContact(double thickness, double friction, bool every_edge, double spacing,
                         const Block& block, const NodeMass& mass,
                         const std::vector<SolidSpec>& solids)
    : thickness_(thickness),
      friction_(friction),
      every_edge_(every_edge),
      margin_(kMargin * spacing),
      block_(&block),
      ranks_(size_of(block.comm)) {
  for (const SolidSpec& solid : solids)
    if (solid.shape.kind == ShapeKind::plane && solid.motion == SolidMotion::fixed) {
      const Vec3 normal = rotate(solid.pose.orientation, {0.0, 0.0, 1.0});
      floors_.push_back({normal, dot(normal, solid.pose.position) + solid.thickness});
    }
  const auto nodes = static_cast<std::size_t>(block.m) * static_cast<std::size_t>(block.n);
  if (ranks_ > 1) {
    reach_.resize(kReach * static_cast<std::size_t>(ranks_));
    send_counts_.resize(static_cast<std::size_t>(ranks_));
    send_offsets_.resize(static_cast<std::size_t>(ranks_));
    receive_counts_.resize(static_cast<std::size_t>(ranks_));
    receive_offsets_.resize(static_cast<std::size_t>(ranks_));
  }
  const int m = block.m, n = block.n;
  const int horizontal = (m - 1) * n;
  border_edge_.assign(static_cast<std::size_t>(horizontal + m * (n - 1)) +
                          2 * static_cast<std::size_t>(m - 1) * static_cast<std::size_t>(n - 1),
                      0);
  for (int e = 0; e < horizontal; ++e) {
    const int l = e / (m - 1);
    if (l == 0 || l == n - 1) border_edge_[static_cast<std::size_t>(e)] = 1;
  }
  for (int e = 0; e < m * (n - 1); ++e) {
    const int k = e % m;
    if (k == 0 || k == m - 1) border_edge_[static_cast<std::size_t>(horizontal + e)] = 1;
  }
  present_.assign(nodes, ranks_ == 1 ? 1 : 0);
  if (ranks_ == 1) {
    present_nodes_.resize(nodes);
    for (std::size_t i = 0; i < nodes; ++i) present_nodes_[i] = static_cast<std::int32_t>(i);
    present_cells();
  }
  start_.resize(nodes);
  end_.resize(nodes);
  velocity_.resize(nodes);
  inverse_mass_.resize(nodes);
  slide_inverse_mass_.resize(nodes);
  node_inverse_mass_.resize(nodes);
  for (int l = 0; l < block.n; ++l)
    for (int k = 0; k < block.m; ++k)
      node_inverse_mass_[static_cast<std::size_t>(k) + static_cast<std::size_t>(block.m) * l] =
          1.0 / mass(k, l);
  move_.resize(nodes);
  kick_.resize(nodes);
  share_.resize(nodes);
  pending_mark_.assign(nodes, 0);
  touched_.assign(nodes, 0);
  const auto cells = static_cast<std::size_t>(block.m - 1) * static_cast<std::size_t>(block.n - 1);
  box_lo_.resize(cells);
  box_hi_.resize(cells);
  leeway_.assign(nodes, 0.5 * margin_);
  reach_lo_.resize(cells);
  reach_hi_.resize(cells);
  needed_.assign(cells, 0);
  edge_lo_.resize(border_edge_.size());
  edge_hi_.resize(border_edge_.size());
}

// A node on a fixed plane's offset surface or below it (the contact meets the planes before
// or after this response, docs/contact.md "Cost") is the plane's to hold: the layer above it
// takes the whole push. Shared, the push would sink the lower node into the plane, which
// puts it back, and lift the upper one: the stack would climb by its overlap every step.
bool SelfContact::on_floor(const Vec3& x) const {
  for (const Floor& floor : floors_)
    if (dot(floor.normal, x) <= floor.level + kOnFloor * thickness_) return true;
  return false;
}

// The nodes whose state of the step this rank needs (docs/contact.md, "Self-contact", "Parallel
// runs and restarts"): its own and every node of another rank within kHops pairs of them, so
// that the response below, the same computation on every rank over the nodes it holds, gives
// its own nodes the bits one rank would. The two nodes of a pair, or of a candidate the lists
// hold, lie within 2t + 2L + 2D of each other in every coordinate, their boxes over the step
// taken, L the largest leeway of a node (find_pairs) and D the largest side of a cell's box over
// the step: a node is within t of a triangle's cell box, which holds the
// corners' boxes; two edges' nearest points are within t at the step's end, or met within t
// of both edges during it, and each node lies within an edge's extent of them. D is at most
// the largest extent of a cell's corners at the step's start plus twice the farthest any node
// moves in a coordinate. So a rank needs the nodes whose box lies within the reach
// R = kHops (2t + 2L + 2D) of its own nodes' box, and is sent those within kSpare R.
// Whether every position is finite, on every rank.
bool SelfContact::gather(const Field<Vec3>& current, const Field<Vec3>& next,
                         const Field<Vec3>* next_velocities, const Field<Vec3>* starts, double dt,
                         const std::vector<char>& held) {
  const Block& b = *block_;
  bool finite = true;
  // How much farther than its leeway a node has gone from where the candidate lists were built
  // (find_pairs): the lists serve while no node has.
  const bool built = !built_.empty();
  drift_ = built ? 0.0 : std::numeric_limits<double>::infinity();
  // One node's positions into the whole grid's arrays at i = k + m l, into a thread's own
  // `all_finite` and `drift` (whose reductions, && and max, give the same on any count).
  auto take = [&](std::size_t i, const Vec3& r, const Vec3& r1, bool& all_finite, double& drift) {
    start_[i] = r;
    end_[i] = r1;
    all_finite = all_finite && is_finite(r) && is_finite(r1);
    if (built) {
      double moved = 0.0;
      for (int a = 0; a < 3; ++a)
        moved = std::max({moved, std::abs(r[a] - built_[i][a]), std::abs(r1[a] - built_[i][a])});
      // Exact: of two finite doubles, the difference is positive only where the first is larger.
      drift = std::max(drift, moved - leeway_[i]);
    }
  };
  const auto m = static_cast<std::size_t>(b.m);
  // One rank: no message, and the velocities and masses only of the nodes the pairs reach
  // (respond). On threads: a sheet where nothing touches spends most of self-contact's time
  // here.
  if (ranks_ == 1) {
    double drift = drift_;
#pragma omp parallel for schedule(static) reduction(&& : finite) reduction(max : drift)
    for (int l = b.l0; l < b.l1; ++l)
      for (int k = b.k0; k < b.k1; ++k)
        take(static_cast<std::size_t>(k) + m * static_cast<std::size_t>(l), current(k, l),
             next(k, l), finite, drift);
    drift_ = drift;
    return finite;
  }
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  double mine[kReach] = {kInfinity,  kInfinity, kInfinity, -kInfinity, -kInfinity,
                         -kInfinity, 0.0,       0.0,       1.0,        0.0};
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const Vec3 &r = current(k, l), &r1 = next(k, l);
      if (!is_finite(r) || !is_finite(r1)) mine[8] = 0.0;
      mine[9] =
          std::max(mine[9], leeway_[static_cast<std::size_t>(k) + m * static_cast<std::size_t>(l)]);
      for (int a = 0; a < 3; ++a) {
        mine[a] = std::min({mine[a], r[a], r1[a]});
        mine[3 + a] = std::max({mine[3 + a], r[a], r1[a]});
        mine[7] = std::max(mine[7], std::abs(r1[a] - r[a]));
      }
      // The start positions of the ring around the block are its neighbours' (exchanged).
      if (k + 1 < b.m && l + 1 < b.n)
        for (int a = 0; a < 3; ++a) {
          const double x[4] = {r[a], current(k + 1, l)[a], current(k, l + 1)[a],
                               current(k + 1, l + 1)[a]};
          mine[6] = std::max(mine[6], *std::max_element(x, x + 4) - *std::min_element(x, x + 4));
        }
    }
  MPI_Allgather(mine, kReach, MPI_DOUBLE, reach_.data(), kReach, MPI_DOUBLE, b.comm);
  double extent = 0.0, farthest = 0.0, leeway = 0.0;
  for (int rank = 0; rank < ranks_; ++rank) {
    const double* other = &reach_[kReach * static_cast<std::size_t>(rank)];
    if (!(other[8] != 0.0)) return false;
    extent = std::max(extent, other[6]);
    farthest = std::max(farthest, other[7]);
    leeway = std::max(leeway, other[9]);
  }
  const double reach = kHops * (2.0 * thickness_ + 2.0 * leeway + 2.0 * (extent + 2.0 * farthest));
  // Sent: the nodes within half as far again, so that the nodes a rank holds serve it for many
  // steps of a moving sheet (below).
  const double sent = kSpare * reach;

  const int me = rank_in(b.comm);
  send_.clear();
  for (int rank = 0; rank < ranks_; ++rank) {
    const auto r = static_cast<std::size_t>(rank);
    send_offsets_[r] = static_cast<int>(send_.size());
    const double* other = &reach_[kReach * r];
    bool near = rank != me;
    for (int a = 0; a < 3; ++a)
      near = near && mine[a] <= other[3 + a] + sent && mine[3 + a] >= other[a] - sent;
    if (near) {
      std::size_t owned = 0;
      for (int l = b.l0; l < b.l1; ++l)
        for (int k = b.k0; k < b.k1; ++k, ++owned) {
          const Vec3 &x = current(k, l), &x1 = next(k, l);
          bool reaches = true;
          for (int a = 0; a < 3; ++a)
            reaches = reaches && std::min(x[a], x1[a]) <= other[3 + a] + sent &&
                      std::max(x[a], x1[a]) >= other[a] - sent;
          if (!reaches) continue;
          send_.push_back(static_cast<double>(k) + static_cast<double>(m) * l);
          for (const Vec3& v :
               {x, x1, velocity_of(k, l, dt, current, next, next_velocities, starts)}) {
            send_.push_back(v.x);
            send_.push_back(v.y);
            send_.push_back(v.z);
          }
          send_.push_back(held[owned] != 0 ? 1.0 : 0.0);
        }
    }
    send_counts_[r] = static_cast<int>(send_.size()) - send_offsets_[r];
  }
  MPI_Alltoall(send_counts_.data(), 1, MPI_INT, receive_counts_.data(), 1, MPI_INT, b.comm);
  int received = 0;
  for (int rank = 0; rank < ranks_; ++rank) {
    receive_offsets_[static_cast<std::size_t>(rank)] = received;
    received += receive_counts_[static_cast<std::size_t>(rank)];
  }
  receive_.resize(static_cast<std::size_t>(received));
  MPI_Alltoallv(send_.data(), send_counts_.data(), send_offsets_.data(), MPI_DOUBLE,
                receive_.data(), receive_counts_.data(), receive_offsets_.data(), MPI_DOUBLE,
                b.comm);

  // The nodes held stay those of the last build while no node this rank does not hold comes
  // within the reach: the candidate lists cover them. A held node that no rank sends any more
  // lies beyond the reach and keeps its last state, which changes no node within it.
  bool rebuild = present_nodes_.empty();
  for (std::size_t at = 0; at < receive_.size() && !rebuild; at += kPerNode) {
    const double* x = &receive_[at];
    if (present_[static_cast<std::size_t>(x[0])] != 0) continue;
    bool reaches = true;
    for (int a = 0; a < 3; ++a)
      reaches = reaches && std::min(x[1 + a], x[4 + a]) <= mine[3 + a] + reach &&
                std::max(x[1 + a], x[4 + a]) >= mine[a] - reach;
    rebuild = reaches;
  }
  if (rebuild) {
    for (const std::int32_t i : present_nodes_) present_[static_cast<std::size_t>(i)] = 0;
    present_nodes_.clear();
    for (int l = b.l0; l < b.l1; ++l)
      for (int k = b.k0; k < b.k1; ++k)
        present_nodes_.push_back(static_cast<std::int32_t>(k + b.m * l));
    for (std::size_t at = 0; at < receive_.size(); at += kPerNode)
      present_nodes_.push_back(static_cast<std::int32_t>(receive_[at]));
    std::sort(present_nodes_.begin(), present_nodes_.end());
    for (const std::int32_t i : present_nodes_) present_[static_cast<std::size_t>(i)] = 1;
    present_cells();
    // Nodes that were not here at the last build have no candidate lists.
    drift_ = std::numeric_limits<double>::infinity();
  }
  double drift = drift_;
#pragma omp parallel for schedule(static) reduction(&& : finite) reduction(max : drift)
  for (int l = b.l0; l < b.l1; ++l)
    for (int k = b.k0; k < b.k1; ++k) {
      const std::size_t i = static_cast<std::size_t>(k) + m * static_cast<std::size_t>(l);
      const std::size_t owned = static_cast<std::size_t>(l - b.l0) * b.owned_k() + (k - b.k0);
      take(i, current(k, l), next(k, l), finite, drift);
      motion(i, velocity_of(k, l, dt, current, next, next_velocities, starts), held[owned] != 0);
    }
  for (std::size_t at = 0; at < receive_.size(); at += kPerNode) {
    const double* x = &receive_[at];
    const auto i = static_cast<std::size_t>(x[0]);
    if (present_[i] == 0) continue;
    take(i, {x[1], x[2], x[3]}, {x[4], x[5], x[6]}, finite, drift);
    motion(i, {x[7], x[8], x[9]}, x[10] != 0.0);
  }
  drift_ = drift;
  return finite;
}

// The cells whose four corners this rank holds, in increasing order.
void SelfContact::present_cells() {
  const auto m = static_cast<std::size_t>(block_->m), n = static_cast<std::size_t>(block_->n);
  present_cells_.clear();
  for (const std::int32_t node : present_nodes_) {
    const auto i = static_cast<std::size_t>(node);
    const std::size_t k = i % m, l = i / m;
    if (k + 1 < m && l + 1 < n && present_[i + 1] != 0 && present_[i + m] != 0 &&
        present_[i + m + 1] != 0)
      present_cells_.push_back(static_cast<std::int32_t>(k + (m - 1) * l));
  }
  // The edges of those cells that meet others, in increasing number, and the cells that look
  // up their pairs: their own cells (every cell held, or with the border's edges alone the cells
  // along the border).
  present_edges_.clear();
  for (std::int32_t e = 0; e < static_cast<std::int32_t>(border_edge_.size()); ++e) {
    const auto cells = edge_cells(e);
    if (meets_others(e) && (cell_present(cells[0]) || cell_present(cells[1])))
      present_edges_.push_back(e);
  }
  looked_up_.clear();
  for (const std::int32_t c : present_cells_) {
    const auto edges = cell_edges(c);
    if (std::any_of(edges.begin(), edges.end(),
                    [&](std::int32_t f) { return meets_others(f) && own_cell(f) == c; }))
      looked_up_.push_back(c);
  }
}

// Whether this rank holds cell c's four corners (false for no cell, c < 0).
bool SelfContact::cell_present(std::int32_t c) const {
  if (c < 0) return false;
  const std::int32_t m = block_->m;
  const auto n00 = static_cast<std::size_t>(c % (m - 1) + m * (c / (m - 1)));
  const auto mu = static_cast<std::size_t>(m);
  return present_[n00] != 0 && present_[n00 + 1] != 0 && present_[n00 + mu] != 0 &&
         present_[n00 + mu + 1] != 0;
}

// A node's velocity and inverse masses for the response: none for a held node; none across the
// layers for one on a floor, which the floor holds that way, but its own along them, where the
// floor's friction does not hold it: as immovable there too, a node sliding on the floor
// dragged the layer above by friction with no reaction, and fed energy into it
// (docs/contact.md, "Self-contact").
void SelfContact::motion(std::size_t i, const Vec3& velocity, bool held) {
  velocity_[i] = velocity;
  slide_inverse_mass_[i] = held ? 0.0 : node_inverse_mass_[i];
  inverse_mass_[i] = held || on_floor(end_[i]) ? 0.0 : slide_inverse_mass_[i];
}

// Edge number e's two nodes, k + m l (SelfContact::edge_candidates_).
std::array<std::int32_t, 2> SelfContact::edge_nodes(std::int32_t e) const {
  const std::int32_t m = block_->m, n = block_->n, horizontal = (m - 1) * n;
  const std::int32_t sides = horizontal + m * (n - 1), cells = (m - 1) * (n - 1);
  if (e < horizontal) {
    const std::int32_t first = e % (m - 1) + m * (e / (m - 1));
    return {first, first + 1};
  }
  if (e < sides) {
    const std::int32_t first = e - horizontal;
    return {first, first + m};
  }
  const std::int32_t c = (e - sides) % cells;
  const std::int32_t n00 = c % (m - 1) + m * (c / (m - 1));
  return e - sides < cells ? std::array<std::int32_t, 2>{n00, n00 + m + 1}
                           : std::array<std::int32_t, 2>{n00 + 1, n00 + m};
}

// The cells edge number e bounds (−1: none beyond the border).
std::array<std::int32_t, 2> SelfContact::edge_cells(std::int32_t e) const {
  const std::int32_t m = block_->m, n = block_->n, horizontal = (m - 1) * n;
  const std::int32_t sides = horizontal + m * (n - 1), cells = (m - 1) * (n - 1);
  if (e < horizontal) {
    const std::int32_t k = e % (m - 1), l = e / (m - 1);
    return {l > 0 ? k + (m - 1) * (l - 1) : -1, l < n - 1 ? k + (m - 1) * l : -1};
  }
  if (e < sides) {
    const std::int32_t k = (e - horizontal) % m, l = (e - horizontal) / m;
    return {k > 0 ? k - 1 + (m - 1) * l : -1, k < m - 1 ? k + (m - 1) * l : -1};
  }
  return {(e - sides) % cells, -1};
}

std::array<std::int32_t, 6> SelfContact::cell_edges(std::int32_t c) const {
  const std::int32_t m = block_->m, n = block_->n, horizontal = (m - 1) * n;
  const std::int32_t diagonals = horizontal + m * (n - 1), cells = (m - 1) * (n - 1);
  const std::int32_t ck = c % (m - 1), cl = c / (m - 1);
  return {ck + (m - 1) * cl,
          ck + (m - 1) * (cl + 1),
          horizontal + ck + m * cl,
          horizontal + ck + 1 + m * cl,
          diagonals + c,
          diagonals + cells + c};
}

std::int32_t SelfContact::own_cell(std::int32_t e) const {
  const auto two = edge_cells(e);
  return cell_present(two[0]) ? two[0] : two[1];
}

// Both diagonals, each at half weight: no diagonal is preferred (docs/contact.md, "Symmetry").
SelfContact::Triangles SelfContact::cell_triangles(std::int32_t cell) const {
  const std::int32_t m = block_->m;
  const std::int32_t n00 = cell % (m - 1) + m * (cell / (m - 1));
  const std::int32_t n10 = n00 + 1, n01 = n00 + m, n11 = n01 + 1;
  return {{{n00, n10, n11}, {n00, n11, n01}, {n00, n10, n01}, {n10, n11, n01}}};
}

// Whether, at the step's start, the segment between nodes p and q passes through one of cell
// c's four triangles.
bool SelfContact::through_cell(std::int32_t p, std::int32_t q, std::int32_t c) const {
  if (c < 0) return false;
  const Vec3 &a = start_[static_cast<std::size_t>(p)], &b = start_[static_cast<std::size_t>(q)];
  for (const auto& tri : cell_triangles(c))
    if (through(a, b, start_[static_cast<std::size_t>(tri[0])],
                start_[static_cast<std::size_t>(tri[1])], start_[static_cast<std::size_t>(tri[2])]))
      return true;
  return false;
}

// Every cell's box over the step, grown by its leeway, goes into the buckets of a spatial hash
// whose spacing is the mean box, with eight buckets a cell; each node's box over the step, grown
// by the thickness and its own leeway, meets the cells of the buckets it covers. (Twice that
// spacing with two buckets a cell: 40 s against 33 s on scenes/hard/s6_loads_x5.toml, the same
// pairs.) Each node's cells are kept in increasing order, so that the pairs come in the same order
// whatever the build.
void SelfContact::build_candidates(double extent_sum) {
  const std::size_t cells = box_lo_.size();
  const std::size_t nodes = end_.size();
  const auto m = static_cast<std::size_t>(block_->m), cells_k = m - 1, cells_l = cells / cells_k;
  const std::size_t held_cells = std::max<std::size_t>(present_cells_.size(), 1);
  const double spacing = std::max(extent_sum / static_cast<double>(held_cells), thickness_);
  const double inverse = 1.0 / spacing;
  std::size_t buckets = 1;
  while (buckets < 8 * held_cells) buckets *= 2;
  const std::uint64_t mask = buckets - 1;
  auto range = [&](const Vec3& lo, const Vec3& hi, std::int64_t* first, std::int64_t* last,
                   long most) {
    long count = 1;
    for (int a = 0; a < 3; ++a) {
      first[a] = static_cast<std::int64_t>(std::floor(lo[a] * inverse));
      last[a] = static_cast<std::int64_t>(std::floor(hi[a] * inverse));
      count *= static_cast<long>(std::min<std::int64_t>(last[a] - first[a] + 1, most + 1));
    }
    return count;
  };

  // Each node's leeway (kLead) from its move in this step, and each cell's, the largest of its
  // corners': a cell's box then stays within its leeway of its box now while no node has gone
  // farther than its own.
  const double least = 0.5 * margin_, most = kMostLeeway * margin_;
#pragma omp parallel for schedule(static)
  for (std::size_t at = 0; at < present_nodes_.size(); ++at) {
    const auto p = static_cast<std::size_t>(present_nodes_[at]);
    double move = 0.0;
    for (int a = 0; a < 3; ++a) move = std::max(move, std::abs(end_[p][a] - start_[p][a]));
    leeway_[p] = std::clamp(kLead * move, least, most);
  }
  // Each cell's box grown by its leeway, once a build: the fill and every look-up read it.
  auto grown = [](const Vec3& x, double by) { return Vec3{x.x + by, x.y + by, x.z + by}; };
#pragma omp parallel for schedule(static)
  for (std::size_t at = 0; at < present_cells_.size(); ++at) {
    const auto c = static_cast<std::size_t>(present_cells_[at]);
    const std::size_t n00 = c % cells_k + m * (c / cells_k);
    const double leeway =
        std::max({leeway_[n00], leeway_[n00 + 1], leeway_[n00 + m], leeway_[n00 + m + 1]});
    reach_lo_[c] = grown(box_lo_[c], -leeway);
    reach_hi_[c] = grown(box_hi_[c], leeway);
  }

  bucket_start_.assign(buckets + 1, 0);
  large_cells_.clear();
  std::int64_t first[3], last[3];
  for (int pass = 0; pass < 2; ++pass) {
    for (const std::int32_t cell : present_cells_) {
      const auto c = static_cast<std::size_t>(cell);
      if (range(reach_lo_[c], reach_hi_[c], first, last, kMostBuckets) > kMostBuckets) {
        if (pass == 0) large_cells_.push_back(static_cast<std::int32_t>(c));
        continue;
      }
      for (std::int64_t i = first[0]; i <= last[0]; ++i)
        for (std::int64_t j = first[1]; j <= last[1]; ++j)
          for (std::int64_t k = first[2]; k <= last[2]; ++k) {
            const std::uint64_t bucket = bucket_of(i, j, k, mask);
            if (pass == 0)
              ++bucket_start_[bucket + 1];
            else
              bucket_cells_[bucket_start_[bucket]++] = static_cast<std::uint32_t>(c);
          }
    }
    if (pass == 0) {
      for (std::size_t i = 0; i < buckets; ++i) bucket_start_[i + 1] += bucket_start_[i];
      bucket_cells_.resize(bucket_start_[buckets]);
    } else {
      // The fill advanced each bucket's start to the next one's: shift back.
      for (std::size_t i = buckets; i > 0; --i) bucket_start_[i] = bucket_start_[i - 1];
      bucket_start_[0] = 0;
    }
  }

  // Calls consider(c) for every cell c in the buckets the box from lo to hi covers (some more
  // than once), or for every cell where it covers too many, and for every large cell.
  auto each_cell_near = [&](const Vec3& lo, const Vec3& hi, long most, auto&& consider) {
    std::int64_t from[3], to[3];
    if (range(lo, hi, from, to, most) > most) {
      for (const std::int32_t c : present_cells_) consider(static_cast<std::size_t>(c));
    } else {
      for (std::int64_t i = from[0]; i <= to[0]; ++i)
        for (std::int64_t j = from[1]; j <= to[1]; ++j)
          for (std::int64_t kk = from[2]; kk <= to[2]; ++kk) {
            const std::uint64_t bucket = bucket_of(i, j, kk, mask);
            for (std::uint32_t e = bucket_start_[bucket]; e < bucket_start_[bucket + 1]; ++e)
              consider(bucket_cells_[e]);
          }
    }
    for (const std::int32_t c : large_cells_) consider(static_cast<std::size_t>(c));
  };

  // Appends to `found` the cells, in increasing order and each once, whose boxes grown by their
  // leeways meet the box from lo to hi and that `keep` keeps; returns how many. Every cell met is
  // written, and counted when kept: tests and no branches, which mispredicted on cells that pass
  // at random (42 % of those a node met in S6 x 5). `candidates` is the thread's scratch.
  auto cells_meeting = [&](const Vec3& lo, const Vec3& hi, long most, auto&& keep,
                           std::vector<std::int32_t>& candidates,
                           std::vector<std::int32_t>& found) {
    std::size_t kept = 0;
    each_cell_near(lo, hi, most, [&](std::size_t c) {
      if (kept == candidates.size()) candidates.resize(2 * kept + 64);
      candidates[kept] = static_cast<std::int32_t>(c);
      kept += static_cast<std::size_t>(boxes_meet(lo, hi, reach_lo_[c], reach_hi_[c]) & keep(c));
    });
    const auto listed = candidates.begin() + static_cast<std::ptrdiff_t>(kept);
    std::sort(candidates.begin(), listed);
    const auto last = std::unique(candidates.begin(), listed);
    found.insert(found.end(), candidates.begin(), last);
    return static_cast<std::uint32_t>(last - candidates.begin());
  };

  list_start_.assign(nodes + 1, 0);
  // Each thread lists a static chunk of the nodes, counting each node's cells into
  // list_start_; the chunks joined in thread order are the lists in node order, the same for
  // any count.
  const auto threads = static_cast<std::size_t>(omp_get_max_threads());
  thread_lists_.resize(threads);
  // Cleared here, not by each thread: a team smaller than the most threads leaves some unused.
  for (std::vector<std::int32_t>& found : thread_lists_) found.clear();
  thread_candidates_.resize(threads);
#pragma omp parallel
  {
    const auto me = static_cast<std::size_t>(omp_get_thread_num());
    std::vector<std::int32_t>& found = thread_lists_[me];
    std::vector<std::int32_t>& candidates = thread_candidates_[me];
#pragma omp for schedule(static)
    for (std::size_t at = 0; at < present_nodes_.size(); ++at) {
      const auto p = static_cast<std::size_t>(present_nodes_[at]);
      const double reach = thickness_ + leeway_[p];
      Vec3 lo = start_[p], hi = lo;
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], end_[p][a]) - reach;
        hi[a] = std::max(hi[a], end_[p][a]) + reach;
      }
      // The node's own cells (up to four; a missing one is a cell no index names).
      const std::size_t k = p % m, l = p / m, none = cells;
      std::size_t own[4];
      for (int corner = 0; corner < 4; ++corner) {
        const std::size_t ck = k - (corner & 1), cl = l - (corner >> 1);
        own[corner] = ck < cells_k && cl < cells_l ? ck + cells_k * cl : none;
      }
      auto other = [&](std::size_t c) {
        return (c != own[0]) & (c != own[1]) & (c != own[2]) & (c != own[3]);
      };
      list_start_[p + 1] = cells_meeting(lo, hi, kMostBuckets, other, candidates, found);
    }
  }
  for (std::size_t p = 0; p < nodes; ++p) list_start_[p + 1] += list_start_[p];
  list_cells_.clear();
  for (const std::vector<std::int32_t>& found : thread_lists_)
    list_cells_.insert(list_cells_.end(), found.begin(), found.end());
  built_ = end_;
  listed_mark_.assign(cells, 0);
  for (const std::int32_t c : list_cells_) listed_mark_[static_cast<std::size_t>(c)] = 1;
  listed_.clear();
  for (std::size_t c = 0; c < cells; ++c)
    if (listed_mark_[c] != 0) listed_.push_back(static_cast<std::int32_t>(c));

  // Each cell's near cells: those whose boxes, grown by their leeways, come within the thickness
  // of its own, grown by its leeway, and that are not next to it in the grid. Two edges come
  // within the thickness only in such a pair of cells, and every edge of a cell next to another
  // has a node within two of every edge of that one. One look-up a cell, on the rank's threads in
  // static chunks, the chunks joined in thread order: the lists in cell order, the same for any
  // count. A cell's box spans more buckets than a node's: up to kMostCellBuckets are visited
  // before every cell is taken.
  const std::int32_t mi = block_->m;
  near_start_.assign(cells + 1, 0);
  for (std::vector<std::int32_t>& found : thread_lists_) found.clear();
#pragma omp parallel
  {
    const auto me = static_cast<std::size_t>(omp_get_thread_num());
    std::vector<std::int32_t>& found = thread_lists_[me];
    std::vector<std::int32_t>& candidates = thread_candidates_[me];
#pragma omp for schedule(static)
    for (std::size_t at = 0; at < looked_up_.size(); ++at) {
      const auto c = static_cast<std::size_t>(looked_up_[at]);
      const Vec3 lo = grown(reach_lo_[c], -thickness_), hi = grown(reach_hi_[c], thickness_);
      const auto ck = static_cast<std::int64_t>(c % cells_k);
      const auto cl = static_cast<std::int64_t>(c / cells_k);
      auto apart = [&](std::size_t d) {
        const auto dk = static_cast<std::int64_t>(d % cells_k);
        const auto dl = static_cast<std::int64_t>(d / cells_k);
        return (std::abs(dk - ck) > 1) | (std::abs(dl - cl) > 1);
      };
      near_start_[c + 1] = cells_meeting(lo, hi, kMostCellBuckets, apart, candidates, found);
    }
  }
  // Marked: the cells with near cells and the cells near them, whose edges are the only ones
  // that can meet another edge.
  near_mark_.assign(cells, 0);
  for (std::size_t c = 0; c < cells; ++c) {
    if (near_start_[c + 1] != 0) near_mark_[c] = 1;
    near_start_[c + 1] += near_start_[c];
  }
  near_cells_.clear();
  for (const std::vector<std::int32_t>& found : thread_lists_)
    near_cells_.insert(near_cells_.end(), found.begin(), found.end());
  for (const std::int32_t c : near_cells_) near_mark_[static_cast<std::size_t>(c)] = 1;
  auto has_near = [&](std::int32_t c) {
    return c >= 0 &&
           near_start_[static_cast<std::size_t>(c) + 1] != near_start_[static_cast<std::size_t>(c)];
  };
  auto marked = [&](std::int32_t c) { return c >= 0 && near_mark_[static_cast<std::size_t>(c)]; };

  // Those edges' boxes over the step, grown by their nodes' larger leeway (a marked cell is held).
  const auto edges = static_cast<std::int32_t>(border_edge_.size());
#pragma omp parallel for schedule(static)
  for (std::int32_t e = 0; e < edges; ++e) {
    const auto own = edge_cells(e);
    if (!marked(own[0]) && !marked(own[1])) continue;
    const auto nodes = edge_nodes(e);
    const auto a = static_cast<std::size_t>(nodes[0]), b = static_cast<std::size_t>(nodes[1]);
    const double grow = std::max(leeway_[a], leeway_[b]);
    Vec3 lo, hi;
    for (int x = 0; x < 3; ++x) {
      lo[x] = std::min({start_[a][x], end_[a][x], start_[b][x], end_[b][x]}) - grow;
      hi[x] = std::max({start_[a][x], end_[a][x], start_[b][x], end_[b][x]}) + grow;
    }
    edge_lo_[static_cast<std::size_t>(e)] = lo;
    edge_hi_[static_cast<std::size_t>(e)] = hi;
  }

  // Each edge meets the edges of its own cell's near cells where their boxes meet, one grown by
  // the thickness too, and every node of one is more than two apart from every node of the other
  // in k or l. Nearer edges are the fold of a cell or two, which the bending holds, and which a
  // cloth hung from a corner makes there: held apart, the corner's edges and those two cells on
  // fought the fold and threw a node (scenes/hard/denim_square.toml stopped at 2.35 s with them).
  // An edge's own cell (own_cell) holds the edge's box, so two edges whose boxes meet have own
  // cells that are near each other, or next to each other in the grid, where every node of one is
  // within two of every node of the other: each pair is found once, from the first edge's own
  // cell and the second's. (From both cells of each edge and all six edges of their near cells,
  // most pairs were found two to four times.) The lower number's edge takes the pair, in
  // increasing order, on the rank's threads in static chunks of the edges, joined in thread order.
  thread_edge_candidates_.resize(threads);
  for (auto& found : thread_edge_candidates_) found.clear();
#pragma omp parallel
  {
    const auto me = static_cast<std::size_t>(omp_get_thread_num());
    std::vector<EdgeCandidate>& found = thread_edge_candidates_[me];
    std::vector<std::int32_t>& sides = thread_candidates_[me];
#pragma omp for schedule(static)
    for (std::size_t at = 0; at < present_edges_.size(); ++at) {
      const std::int32_t e = present_edges_[at];
      const std::int32_t own = own_cell(e);
      if (!has_near(own)) continue;
      const auto mine = edge_nodes(e);
      const std::int32_t ak = mine[0] % mi, al = mine[0] / mi, bk = mine[1] % mi, bl = mine[1] / mi;
      const Vec3 lo = grown(edge_lo_[static_cast<std::size_t>(e)], -thickness_);
      const Vec3 hi = grown(edge_hi_[static_cast<std::size_t>(e)], thickness_);
      sides.clear();
      const auto o = static_cast<std::size_t>(own);
      for (std::uint32_t at_near = near_start_[o]; at_near < near_start_[o + 1]; ++at_near) {
        const std::int32_t cell = near_cells_[at_near];
        const std::int32_t ck = cell % (mi - 1), cl = cell / (mi - 1);
        // The cell's edges, each with its nodes' offsets in kCellEdges.
        const auto numbers = cell_edges(cell);
        for (int j = 0; j < 6; ++j) {
          const std::int32_t f = numbers[static_cast<std::size_t>(j)];
          // Every pair once: from the lower number's edge where both are listed.
          if (f <= e && meets_others(f)) continue;
          bool near = false;
          for (int end = 0; end < 2; ++end) {
            const std::int32_t fk = ck + kCellEdges[j][end][0], fl = cl + kCellEdges[j][end][1];
            near = near || (std::abs(ak - fk) <= 2 && std::abs(al - fl) <= 2) ||
                   (std::abs(bk - fk) <= 2 && std::abs(bl - fl) <= 2);
          }
          if (near) continue;
          const auto fi = static_cast<std::size_t>(f);
          if (boxes_meet(lo, hi, edge_lo_[fi], edge_hi_[fi]) && own_cell(f) == cell)
            sides.push_back(f);
        }
      }
      std::sort(sides.begin(), sides.end());
      for (const std::int32_t f : sides) {
        const auto theirs = edge_nodes(f);
        const bool inside = border_edge_[static_cast<std::size_t>(e)] == 0 &&
                            border_edge_[static_cast<std::size_t>(f)] == 0;
        found.push_back({e, f, {mine[0], mine[1], theirs[0], theirs[1]}, inside});
      }
    }
  }
  edge_candidates_.clear();
  for (const auto& found : thread_edge_candidates_)
    edge_candidates_.insert(edge_candidates_.end(), found.begin(), found.end());
}

// A cell's box over the step; its largest side.
double SelfContact::cell_box(std::size_t c) {
  const auto m = static_cast<std::size_t>(block_->m), cells_k = m - 1;
  const std::size_t n00 = c % cells_k + m * (c / cells_k);
  Vec3 lo = start_[n00], hi = lo;
  for (const std::size_t i : {n00, n00 + 1, n00 + m, n00 + m + 1})
    for (const Vec3& x : {start_[i], end_[i]})
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], x[a]);
        hi[a] = std::max(hi[a], x[a]);
      }
  box_lo_[c] = lo;
  box_hi_[c] = hi;
  return std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
}

// A cell's four triangles' planes at both ends of the step, in the order of find_pairs'
// triangles.
void SelfContact::cell_planes(std::size_t c) {
  const Triangles triangles = cell_triangles(static_cast<std::int32_t>(c));
  for (std::size_t j = 0; j < 4; ++j) {
    const auto a = static_cast<std::size_t>(triangles[j][0]);
    const auto b = static_cast<std::size_t>(triangles[j][1]);
    const auto d = static_cast<std::size_t>(triangles[j][2]);
    Plane& plane = planes_[4 * c + j];
    const Vec3 &a0 = start_[a], &b0 = start_[b], &c0 = start_[d];
    const Vec3 &a1 = end_[a], &b1 = end_[b], &c1 = end_[d];
    plane.normal0 = cross(b0 - a0, c0 - a0);
    const Vec3 normal1 = cross(b1 - a1, c1 - a1);
    plane.area0 = norm(plane.normal0);
    plane.area1 = norm(normal1);
    plane.normal1 = normal1 / plane.area1;
    // A triangle that turned over in the step (a cell collapsing through itself) has no side
    // to keep: every node near it would seem to have crossed it, by as much as the triangle's
    // size, and be thrown that far. find_pairs passes over a plane of no area at the start;
    // found here once for the cell's hits.
    if (!(plane.area1 > 0.0) || !(dot(plane.normal0, plane.normal1) > 0.0)) plane.area0 = 0.0;
  }
}

// Each node meets the cells its list holds whose box over the step its own box, grown by the
// thickness, meets: every cell it is not a corner of. A crease that folds the cloth back onto
// itself is held at the thickness as two layers anywhere else are, from one cell beyond the
// crease's nodes; within a cell the bending holds the fold (docs/contact.md, "Self-contact").
void SelfContact::find_pairs() {
  // The candidates of the last build serve while no node has moved more than its leeway from
  // where it was then (in any coordinate): a cell's box over any later step then lies within
  // the cell's leeway of its box at the build, and a node's within its own of the node then,
  // so a cell that a node's box grown by the thickness meets later was met, both boxes at the
  // build grown by their leeways, the node's by the thickness too. Which steps rebuild, and
  // which leeways, change no pair: the lists only hold more cells than the test below keeps.
  // Only the cells in some node's list need their box and planes between builds: in a sheet
  // that does not touch itself, none. The boxes, the planes and the pairs on the rank's threads
  // in static chunks; the threads' pairs joined in thread order are the pairs in row order, the
  // same for any count.
  if (!(drift_ <= 0.0)) {
    cell_extents_.resize(present_cells_.size());
#pragma omp parallel for schedule(static)
    for (std::size_t e = 0; e < present_cells_.size(); ++e)
      cell_extents_[e] = cell_box(static_cast<std::size_t>(present_cells_[e]));
    double extent_sum = 0.0;
    for (const double extent : cell_extents_) extent_sum += extent;
    build_candidates(extent_sum);
  } else {
#pragma omp parallel for schedule(static)
    for (std::size_t e = 0; e < listed_.size(); ++e) cell_box(static_cast<std::size_t>(listed_[e]));
  }
  planes_.resize(4 * box_lo_.size());

  // First the boxes: each node's hits, the cells of its list whose box meets its own, in list
  // order; then the planes of the cells some node hit (in S6 with its loads x 5, three in five
  // of the cells listed); then each thread tests the triangles of the hits it found, so that
  // its pairs come in its nodes' order as before.
  const double t = thickness_;
  const auto threads = static_cast<std::size_t>(omp_get_max_threads());
  thread_pairs_.resize(threads);
  thread_hits_.resize(threads);
  for (std::vector<Pair>& found : thread_pairs_) found.clear();
  for (std::vector<Hit>& hits : thread_hits_) hits.clear();
#pragma omp parallel
  {
    const auto me = static_cast<std::size_t>(omp_get_thread_num());
    std::vector<Hit>& hits = thread_hits_[me];
#pragma omp for schedule(static)
    for (std::size_t at = 0; at < present_nodes_.size(); ++at) {
      const auto p = static_cast<std::size_t>(present_nodes_[at]);
      if (list_start_[p] == list_start_[p + 1]) continue;
      Vec3 lo = start_[p], hi = lo;
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], end_[p][a]) - t;
        hi[a] = std::max(hi[a], end_[p][a]) + t;
      }
      for (std::uint32_t e = list_start_[p]; e < list_start_[p + 1]; ++e) {
        const std::int32_t c = list_cells_[e];
        bool apart = false;
        for (int a = 0; a < 3; ++a) apart = apart || box_hi_[c][a] < lo[a] || box_lo_[c][a] > hi[a];
        if (apart) continue;
        hits.push_back({static_cast<std::int32_t>(p), c});
        std::atomic_ref<char>(needed_[static_cast<std::size_t>(c)])
            .store(1, std::memory_order_relaxed);
      }
    }
#pragma omp for schedule(static)
    for (std::size_t e = 0; e < listed_.size(); ++e) {
      const auto c = static_cast<std::size_t>(listed_[e]);
      if (needed_[c] != 0) cell_planes(c);
    }
    std::vector<Pair>& found = thread_pairs_[me];
    std::size_t first = 0;
    for (std::size_t h = 0; h < hits.size(); ++h) {
      const auto p = static_cast<std::size_t>(hits[h].node);
      const std::int32_t c = hits[h].cell;
      if (h == 0 || hits[h - 1].node != hits[h].node) first = found.size();
      const Triangles triangles = cell_triangles(c);
      for (int j = 0; j < 4; ++j) {
        const auto& tri = triangles[j];
        const Plane& plane = planes_[4 * static_cast<std::size_t>(c) + static_cast<std::size_t>(j)];
        // No area at the start: a triangle that turned over in the step (cell_planes).
        if (!(plane.area0 > 0.0)) continue;
        const Vec3 &a0 = start_[tri[0]], &b0 = start_[tri[1]], &c0 = start_[tri[2]];
        const Vec3 &a1 = end_[tri[0]], &b1 = end_[tri[1]], &c1 = end_[tri[2]];
        const double d0 = dot(plane.normal0, start_[p] - a0) / plane.area0;
        const double side = d0 >= 0.0 ? 1.0 : -1.0;
        const Vec3& normal = plane.normal1;
        const double area1 = plane.area1;
        const double d1 = dot(normal, end_[p] - a1);
        if (side * d1 >= t) continue;
        // Crossed over the step: where the node met the plane (linearly between the two
        // distances) must lie in the triangle, or within the thickness of its edges, or it
        // passed beside it; it goes back to its side along the triangle's normal. Still on
        // its side: a foot in the triangle holds it along the normal; a foot beside it (a
        // node at the cloth's border, which has no triangle beyond the edge) is held the
        // thickness from the triangle's nearest point, along the line from that point:
        // beyond the triangle the plane's distance is not the triangle's.
        const double slack = t / std::sqrt(area1);
        const Foot at_end = foot(end_[p], a1, b1, c1);
        Foot on = at_end;
        double pair_side = side;
        Vec3 direction = normal;
        bool beside = false;
        if (side * d1 < 0.0) {
          const double s = d0 / (d0 - d1);
          const Foot crossing =
              foot(lerp(start_[p], end_[p], s), lerp(a0, a1, s), lerp(b0, b1, s), lerp(c0, c1, s));
          if (!crossing.near(slack) || !at_end.near(1.0)) continue;
          on = at_end.clamped();
        } else if (!at_end.near(0.0)) {
          if (!at_end.near(slack)) continue;
          on = at_end.clamped();
          beside = true;
          const Vec3 away = end_[p] - (on.a * a1 + on.b * b1 + on.c * c1);
          const double distance = norm(away);
          if (distance >= t) continue;
          if (distance > 0.0) {
            direction = away / distance;
            pair_side = 1.0;
          }
        }
        found.push_back(Pair{{static_cast<std::int32_t>(p), tri[0], tri[1], tri[2]},
                             {1.0, -on.a, -on.b, -on.c},
                             pair_side,
                             0.5,
                             direction,
                             beside});
      }
      if (h + 1 == hits.size() || hits[h + 1].node != hits[h].node) drop_covered(found, first);
    }
  }
  for (const std::int32_t c : listed_) needed_[static_cast<std::size_t>(c)] = 0;
  pairs_.clear();
  for (const std::vector<Pair>& found : thread_pairs_)
    pairs_.insert(pairs_.end(), found.begin(), found.end());
  find_edge_pairs();
}

// A pair of node p and a triangle beside which its foot lies pushes along the line from the
// triangle's nearest point F, on an edge or at a corner. Where p also pairs along the normal with a
// triangle that holds that edge or corner, or whose plane holds F (to 1e-6 t: in a flat layer F can
// lie on an edge that no triangle holding p's foot has), the pair beside adds nothing: held t from
// that triangle's plane, p is at least t from F. And it takes away: a node resting over a node of a
// flat layer below, its foot in the triangles on one side and beside those on the other, was pushed
// along the line from the node below, sideways as much as it stood off it, and rolled off it as off
// a ball; with frictionless layers the napkin's stacked rows swung from node to node
// (docs/contact.md, "Self-contact", item 1). Removes those pairs from p's, found[first...].
void SelfContact::drop_covered(std::vector<Pair>& found, std::size_t first) {
  const double level = kOnFloor * thickness_;
  const auto covered = [&](const Pair& b) {
    if (!b.beside) return false;
    Vec3 nearest{};
    for (int i = 1; i < 4; ++i)
      nearest -= b.weights[i] * end_[static_cast<std::size_t>(b.nodes[i])];
    for (std::size_t a = first; a < found.size(); ++a) {
      const Pair& along = found[a];
      if (along.beside) continue;
      bool holds = true;
      for (int i = 1; i < 4 && holds; ++i)
        holds = b.weights[i] == 0.0 ||
                std::find(along.nodes + 1, along.nodes + 4, b.nodes[i]) != along.nodes + 4;
      const Vec3& corner = end_[static_cast<std::size_t>(along.nodes[1])];
      if (holds || std::abs(dot(along.normal, nearest - corner)) <= level) return true;
    }
    return false;
  };
  // Only pairs beside are dropped and only pairs along a normal are read, so compacting in
  // place reads every one of those.
  std::size_t kept = first;
  for (std::size_t a = first; a < found.size(); ++a)
    if (!covered(found[a])) found[kept++] = found[a];
  found.resize(kept);
}

// Two edges that cross over the step, or, where one is on the border, end it closer than the
// thickness, are held the thickness apart along their common normal on the side they started
// on: long edges crossed as the bars of an X, and a border sliding past another part of the
// cloth, meet no node and no triangle, and would pass through each other between their nodes
// (docs/contact.md, "Self-contact").
void SelfContact::find_edge_pairs() {
  const double t = thickness_;
  const std::int32_t diagonals = (block_->m - 1) * block_->n + block_->m * (block_->n - 1);
  // The parameters of the nearest points of the lines through a0 + s ea and b0 + u eb; false
  // for lines so near parallel that their common normal has no direction.
  auto nearest = [](const Vec3& a0, const Vec3& ea, const Vec3& b0, const Vec3& eb, double& s,
                    double& u) {
    const Vec3 w = a0 - b0;
    const double aa = dot(ea, ea), ab = dot(ea, eb), bb = dot(eb, eb);
    const double denominator = aa * bb - ab * ab;
    if (!(denominator > 1e-6 * aa * bb)) return false;
    const double d = dot(ea, w), e = dot(eb, w);
    s = (ab * e - bb * d) / denominator;
    u = (aa * e - ab * d) / denominator;
    return true;
  };
  // On the rank's threads in static chunks, the chunks' pairs joined in thread order: the pairs
  // in the candidates' order, the same for any count.
  for (std::vector<Pair>& found : thread_pairs_) found.clear();
#pragma omp parallel
  {
    std::vector<Pair>& found = thread_pairs_[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static)
    for (std::size_t at = 0; at < edge_candidates_.size(); ++at) {
      const EdgeCandidate& candidate = edge_candidates_[at];
      const std::int32_t e = candidate.e, f = candidate.f;
      const std::array<std::int32_t, 2> ea{candidate.nodes[0], candidate.nodes[1]};
      const std::array<std::int32_t, 2> eb{candidate.nodes[2], candidate.nodes[3]};
      const auto a0 = static_cast<std::size_t>(ea[0]), a1 = static_cast<std::size_t>(ea[1]);
      const auto b0 = static_cast<std::size_t>(eb[0]), b1 = static_cast<std::size_t>(eb[1]);
      const Vec3 normal0 = cross(start_[a1] - start_[a0], start_[b1] - start_[b0]);
      const Vec3 edge_a = end_[a1] - end_[a0], edge_b = end_[b1] - end_[b0];
      const Vec3 normal1 = cross(edge_a, edge_b);
      // Edges that turned through parallel in the step keep no side.
      if (!(dot(normal0, normal1) > 0.0)) continue;
      const double volume0 = dot(normal0, start_[a0] - start_[b0]);
      const double volume1 = dot(normal1, end_[a0] - end_[b0]);
      const double side = volume0 >= 0.0 ? 1.0 : -1.0;
      // Two edges inside the cloth are held only where they crossed: near, they lie in layers
      // whose nodes the node pairs hold at t, and held there too they would push such layers
      // twice (docs/contact.md, "Self-contact").
      if (candidate.inside && side * volume1 >= 0.0) continue;
      const double length = norm(normal1);
      const double d1 = side * volume1 / length;  // the lines' distance, on the starting side
      if (d1 >= t) continue;
      // The lines' nearest points at the step's end, which the pair holds apart.
      double s, u;
      if (!nearest(end_[a0], edge_a, end_[b0], edge_b, s, u)) continue;
      if (d1 < 0.0) {
        // The lines met within the step (the volume passed through zero, linearly between its
        // ends): where they met must lie within both edges, or within the thickness of them, or
        // the edges passed beside each other.
        const double at = volume0 / (volume0 - volume1);
        const Vec3 p0 = lerp(start_[a0], end_[a0], at), q0 = lerp(start_[b0], end_[b0], at);
        const Vec3 pa = lerp(start_[a1], end_[a1], at) - p0,
                   qb = lerp(start_[b1], end_[b1], at) - q0;
        double s_met, u_met;
        if (!nearest(p0, pa, q0, qb, s_met, u_met)) continue;
        const double slack_a = t / norm(pa), slack_b = t / norm(qb);
        if (s_met < -slack_a || s_met > 1.0 + slack_a || u_met < -slack_b || u_met > 1.0 + slack_b)
          continue;
      } else if (!(s > 0.0 && s < 1.0) || !(u > 0.0 && u < 1.0)) {
        // Near where the lines are, but the edges' nearest points lie beyond an end: a node near
        // an edge, which the node's pairs with the edge's triangles hold.
        continue;
      }
      // Edges that start the step with one through a cell of the other are tangled already (from
      // before self-contact was on, a fix that drove them through, or passes that did not
      // converge): held on the sides they start on, the tangle could never come undone.
      const auto cells_a = edge_cells(e), cells_b = edge_cells(f);
      if (through_cell(ea[0], ea[1], cells_b[0]) || through_cell(ea[0], ea[1], cells_b[1]) ||
          through_cell(eb[0], eb[1], cells_a[0]) || through_cell(eb[0], eb[1], cells_a[1]))
        continue;
      s = std::clamp(s, 0.0, 1.0);
      u = std::clamp(u, 0.0, 1.0);
      // A diagonal is one of a cell's two, each at half weight as the triangles are.
      const double share = (e >= diagonals ? 0.5 : 1.0) * (f >= diagonals ? 0.5 : 1.0);
      found.push_back(Pair{{ea[0], ea[1], eb[0], eb[1]},
                           {1.0 - s, s, -(1.0 - u), -u},
                           side,
                           share,
                           normal1 / length});
    }
  }
  for (const std::vector<Pair>& found : thread_pairs_)
    pairs_.insert(pairs_.end(), found.begin(), found.end());
}

// Σ w_i x_i over a pair's nodes is the first point's offset from the second, and Σ w_i² / m_i
// the inverse of the mass the pair moves as one.
Vec3 SelfContact::across(const Pair& q, const std::vector<Vec3>& x) const {
  Vec3 sum{};
  for (int i = 0; i < 4; ++i) sum += q.weights[i] * x[static_cast<std::size_t>(q.nodes[i])];
  return sum;
}

double SelfContact::inverse_mass(const Pair& q, const std::vector<double>& inverse) const {
  double sum = 0.0;
  for (int i = 0; i < 4; ++i)
    sum += q.weights[i] * q.weights[i] * inverse[static_cast<std::size_t>(q.nodes[i])];
  return sum;
}

// Adds the pair's `amount` (a move or an impulse, per unit of inverse mass) along
// `sign` × `direction` to each of its nodes' `sums`, by weight and `inverse` mass, with the
// pair's share and relaxation. The weights sum to zero, so a pair's moves and impulses keep the
// momentum of its nodes (a node that does not move takes what the others give).
// Inlined: called for every pair in every pass, its call cost as much as its work.
[[gnu::always_inline]] inline void SelfContact::share_out(const Pair& q, double amount, double sign,
                                                          const Vec3& direction,
                                                          const std::vector<double>& inverse,
                                                          std::vector<Vec3>& sums) {
  const double scale = q.share * q.relaxation * amount * sign;
  for (int i = 0; i < 4; ++i) {
    const auto node = static_cast<std::size_t>(q.nodes[i]);
    if (pending_mark_[node] == 0) {
      pending_mark_[node] = 1;
      pending_.push_back(q.nodes[i]);
    }
    sums[node] += (scale * q.weights[i] * inverse[node]) * direction;
  }
}

// Each pair's relaxation: 1 over the largest total share, over its moving nodes, of the pairs
// they are in, so that all a node's pairs together never move it more than one pair's worth.
// The same factor for all of a pair's nodes keeps action and reaction equal, which a node's mean
// of its pairs' moves did not (docs/contact.md, "Self-contact", item 2).
void SelfContact::relax() {
  for (const Pair& q : pairs_)
    for (int i = 0; i < 4; ++i)
      share_[static_cast<std::size_t>(q.nodes[i])] += q.share * std::abs(q.weights[i]);
  for (Pair& q : pairs_) {
    double most = 1.0;
    for (int i = 0; i < 4; ++i) {
      const auto node = static_cast<std::size_t>(q.nodes[i]);
      if (slide_inverse_mass_[node] > 0.0) most = std::max(most, share_[node]);
    }
    q.relaxation = 1.0 / most;
  }
  for (const Pair& q : pairs_)
    for (int i = 0; i < 4; ++i) share_[static_cast<std::size_t>(q.nodes[i])] = 0.0;
}

// Each node its pairs reached takes its sum, which is cleared, and joins moved_ the first time:
// pending_ holds a pass's nodes in the order its pairs reached them, so moved_ lists them in the
// order the passes first reached them.
template <class Take>
void SelfContact::take_sums(std::vector<Vec3>& sums, Take take) {
  for (const std::int32_t node : pending_) {
    const auto i = static_cast<std::size_t>(node);
    if (touched_[i] == 0) moved_.push_back(node);
    touched_[i] = 1;
    take(i, sums[i]);
    sums[i] = {};
    pending_mark_[i] = 0;
  }
  pending_.clear();
}

// Each pass moves every pair's node and triangle apart along the triangle's normal to the
// thickness, in inverse proportion to their masses (a held node does not move), relaxed so that
// no node moves more than one pair's worth.
void SelfContact::separate() {
  for (int pass = 0; pass < kPasses; ++pass) {
    bool any = false;
    for (const Pair& q : pairs_) {
      const double depth = thickness_ - q.side * dot(q.normal, across(q, end_));
      if (!(depth > 0.0)) continue;
      any = true;
      share_out(q, depth / q.stiffness, q.side, q.normal, inverse_mass_, move_);
    }
    if (!any) break;
    take_sums(move_, [&](std::size_t i, const Vec3& move) { end_[i] += move; });
  }
}

// Inelastic between the layers: the pairs' relative normal velocity is brought to zero where
// they approach, in passes as the positions; then Coulomb friction takes off the tangential
// relative velocity up to μ times each pair's normal impulse, and moves the nodes by Δt times
// that change, as the solids' friction does (docs/contact.md, "Response").
void SelfContact::stop_approach_and_slide(double dt) {
  for (int pass = 0; pass < kPasses; ++pass) {
    bool any = false;
    for (Pair& q : pairs_) {
      const double approach = -q.side * dot(q.normal, across(q, velocity_));
      if (!(approach > 0.0)) continue;
      any = true;
      const double impulse = approach / q.stiffness;
      q.impulse += q.share * impulse;
      share_out(q, impulse, q.side, q.normal, inverse_mass_, kick_);
    }
    if (!any) break;
    take_sums(kick_, [&](std::size_t i, const Vec3& kick) { velocity_[i] += kick; });
  }
  if (friction_ == 0.0) return;
  for (const Pair& q : pairs_) {
    if (!(q.impulse > 0.0)) continue;
    const Vec3 relative = across(q, velocity_);
    const Vec3 slide = relative - dot(relative, q.normal) * q.normal;
    const double speed = norm(slide);
    if (!(speed > 0.0)) continue;
    // Stick where μ times the normal impulse suffices, else slide with the largest; the
    // nodes on a floor take their share.
    const double stiffness = inverse_mass(q, slide_inverse_mass_);
    const double impulse = std::min(speed / stiffness, friction_ * q.impulse / q.share);
    share_out(q, -impulse, 1.0, slide / speed, slide_inverse_mass_, kick_);
  }
  take_sums(kick_, [&](std::size_t i, const Vec3& kick) {
    velocity_[i] += kick;
    end_[i] += dt * kick;
  });
}

SelfContactStats SelfContact::respond(double dt, const Field<Vec3>& current, Field<Vec3>& next,
                                      Field<Vec3>* next_velocities, const Field<Vec3>* starts,
                                      const std::vector<char>& held, NodeVelocities& corrected,
                                      std::vector<char>* moved_rows) {
  const Block& b = *block_;
  const auto m = static_cast<std::size_t>(b.m);
  SelfContactStats stats;
  // A step that left the grid's numbers (a blow-up) is the stability check's to stop.
  if (!gather(current, next, next_velocities, starts, dt, held)) return stats;
  find_pairs();
  // Each pair is counted by the rank that owns its first node: other ranks may hold it too.
  auto mine = [&](const Pair& q) {
    const auto i = static_cast<std::size_t>(q.nodes[0]);
    return ranks_ == 1 || b.owns(static_cast<int>(i % m), static_cast<int>(i / m));
  };
  stats.contacts = static_cast<long>(std::count_if(pairs_.begin(), pairs_.end(), mine));
  if (ranks_ == 1)
    for (const Pair& q : pairs_)
      for (const std::int32_t node : q.nodes) {
        const auto i = static_cast<std::size_t>(node);
        const int k = static_cast<int>(i % m);
        const int l = static_cast<int>(i / m);
        motion(i, velocity_of(k, l, dt, current, next, next_velocities, starts),
               held[static_cast<std::size_t>(l - b.l0) * static_cast<std::size_t>(b.owned_k()) +
                    static_cast<std::size_t>(k - b.k0)] != 0);
      }
  // A pair between held nodes only moves nothing.
  for (Pair& q : pairs_) q.stiffness = inverse_mass(q, inverse_mass_);
  std::erase_if(pairs_, [](const Pair& q) { return !(q.stiffness > 0.0); });
  if (!pairs_.empty()) {
    relax();
    separate();
    stop_approach_and_slide(dt);
    for (const Pair& q : pairs_)
      if (mine(q)) stats.closest = std::min(stats.closest, q.side * dot(q.normal, across(q, end_)));
    for (const std::int32_t node : moved_) {
      const auto i = static_cast<std::size_t>(node);
      touched_[i] = 0;
      const int k = static_cast<int>(i % m), l = static_cast<int>(i / m);
      if (!b.owns(k, l)) continue;
      next(k, l) = end_[i];
      if (next_velocities != nullptr)
        (*next_velocities)(k, l) = velocity_[i];
      else
        corrected.push_back({k, l, velocity_[i]});
      if (moved_rows != nullptr) (*moved_rows)[static_cast<std::size_t>(l - b.l0)] = 1;
    }
    moved_.clear();
  }
  if (ranks_ > 1) {
    MPI_Allreduce(MPI_IN_PLACE, &stats.contacts, 1, MPI_LONG, MPI_SUM, b.comm);
    MPI_Allreduce(MPI_IN_PLACE, &stats.closest, 1, MPI_DOUBLE, MPI_MIN, b.comm);
  }
  return stats;
}

}  // namespace cosserat
