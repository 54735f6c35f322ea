#pragma once
// The cloth against its own cells (docs/contact.md, "Self-contact"): a node is kept on the side
// of every triangle of the grid outside its own four cells where it started the step, and an
// edge of the cloth's border on the side of every edge more than two nodes away, at least the
// cloth's thickness away, with inelastic normal velocities and Coulomb friction between layers.

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "cosserat/contact/contact.hpp"
#include "cosserat/contact/solid.hpp"
#include "cosserat/grid/block.hpp"
#include "cosserat/grid/vec3.hpp"
#include "cosserat/model/node_mass.hpp"

namespace cosserat {

// What one step's response found; the same on every rank.
struct SelfContactStats {
  // Node–triangle and edge–edge pairs closer than the thickness, or crossed, before the response.
  long contacts = 0;
  // The smallest distance of a pair it held, after the response, m (infinite: none).
  double closest = std::numeric_limits<double>::infinity();
};

class SelfContact {
 public:
  // `thickness` (m), `friction` (μ between layers) and `every_edge` (every edge against every
  // other where they cross, else the border's edges alone) from the scene's [self_contact] and
  // material.thickness; `spacing` the smaller grid spacing (m); `solids` the scene's, whose
  // fixed planes support the layers on them.
  SelfContact(double thickness, double friction, bool every_edge, double spacing,
              const Block& block, const NodeMass& mass, const std::vector<SolidSpec>& solids);

  // The step from `current` to `next` (owned nodes) of length dt, with `next_velocities` when
  // the scheme carries velocities, else (next − starts)/dt, or (next − current)/dt without
  // `starts` (ProposedStep::starts). `held` marks, per owned node in row order, the nodes a fix
  // holds: they move no other node's way. Moves owned nodes of `next`; writes the velocities it
  // changed into `next_velocities`, or lists them in `corrected` for the schemes that carry r⁻;
  // marks the rows it moved in `moved_rows` when given. Collective over the block's ranks.
  SelfContactStats respond(double dt, const Field<Vec3>& current, Field<Vec3>& next,
                           Field<Vec3>* next_velocities, const Field<Vec3>* starts,
                           const std::vector<char>& held, NodeVelocities& corrected,
                           std::vector<char>* moved_rows);

  // How many nodes' state of the step this rank holds: its own and those other ranks sent it
  // when it last built its candidate lists (all of them on one rank).
  std::size_t nodes_held() const { return present_nodes_.size(); }

  // About what one rank holds for an m x n grid: arrays over the whole grid for the state of
  // the step of the nodes it holds, six positions or velocities a node and, at most, 11 numbers
  // received for each (410 bytes with the candidate lists and the leeway), and each cell's box,
  // the box grown by its leeway, four planes and eight buckets (420 bytes), and each of the four
  // edges a node has about, its box and marks (240 bytes); the pairs come on top, a few per node
  // in contact.
  static double memory_bytes(int m, int n) { return 1070.0 * m * n; }

 private:
  // Two points of the grid held at the thickness apart along `normal`, each a weighted sum of
  // nodes: a node p on one side of a cell's triangle (a, b, c), weights 1 and minus p's foot's
  // barycentric coordinates; or a point of one border edge against a point of another, weights
  // (1 − s, s) and −(1 − u, −u). Σ weights × positions is the first point's offset from the
  // second.
  struct Pair {
    std::int32_t nodes[4];  // global node numbers, k + m l
    double weights[4];
    double side;   // ±1: the side of the normal the first point started the step on
    double share;  // of the cell's two diagonals for a node; 1 for two edges
    Vec3 normal;   // the triangle's at the proposed step, or the edges' common normal, or the
                   // line from the triangle's nearest point where p's foot lies beside it
    bool beside = false;     // a node whose foot lies beside the triangle (find_pairs)
    double impulse = 0.0;    // the normal velocity impulse it gave, per unit of mass
    double stiffness = 0.0;  // the inverse of the mass it moves as one (inverse_mass)
    double relaxation = 1.0;  // of its moves and impulses (relax)
  };
  // A cell's four triangles, node numbers k + m l: both diagonals' pairs, in the order of its
  // planes (planes_).
  using Triangles = std::array<std::array<std::int32_t, 3>, 4>;
  Triangles cell_triangles(std::int32_t cell) const;

  bool gather(const Field<Vec3>& current, const Field<Vec3>& next,
              const Field<Vec3>* next_velocities, const Field<Vec3>* starts, double dt,
              const std::vector<char>& held);
  void present_cells();
  bool cell_present(std::int32_t c) const;
  void motion(std::size_t i, const Vec3& velocity, bool held);
  bool on_floor(const Vec3& x) const;
  double cell_box(std::size_t c);
  void cell_planes(std::size_t c);
  void build_candidates(double extent_sum);
  void find_pairs();
  void drop_covered(std::vector<Pair>& found, std::size_t first);
  void find_edge_pairs();
  Vec3 across(const Pair& q, const std::vector<Vec3>& x) const;
  double inverse_mass(const Pair& q, const std::vector<double>& inverse) const;
  void share_out(const Pair& q, double amount, double sign, const Vec3& direction,
                 const std::vector<double>& inverse, std::vector<Vec3>& sums);
  void relax();
  template <class Take>
  void take_sums(std::vector<Vec3>& sums, Take take);
  void separate();
  void stop_approach_and_slide(double dt);

  // A fixed plane's offset surface: the points x with normal · x = level.
  struct Floor {
    Vec3 normal;
    double level;
  };

  double thickness_;
  double friction_;
  bool every_edge_;  // every edge meets others where they cross; else the border's alone
  double margin_;  // m: how far the candidate lists look beyond the thickness
  std::vector<Floor> floors_;
  const Block* block_;
  int ranks_;
  // With several ranks only: what each rank's nodes reach (gather), and the nodes sent to and
  // received from each rank.
  std::vector<double> reach_;
  std::vector<int> send_counts_, send_offsets_, receive_counts_, receive_offsets_;
  std::vector<double> send_, receive_;

  // The nodes this rank holds the step's state of (all of them on one rank), in increasing
  // k + m l and marked in present_: its own and those other ranks sent it when it last built its
  // candidate lists; and the cells whose four corners it holds. Every rank finds the pairs among
  // its nodes and moves them as one rank would move its own, so any decomposition gives the
  // same bits.
  std::vector<char> present_;
  std::vector<std::int32_t> present_nodes_, present_cells_;

  // Arrays over the whole grid, k + m l; only the nodes held are read.
  std::vector<Vec3> start_, end_, velocity_;
  std::vector<double> inverse_mass_;       // this step's: none for a held node or one on a floor
  std::vector<double> slide_inverse_mass_;  // along the layers (friction): none for a held node
  std::vector<double> node_inverse_mass_;  // 1 / m of every node
  std::vector<Vec3> move_, kick_;
  std::vector<double> share_;  // a node's total share in the step's pairs (relax); else zero
  std::vector<char> pending_mark_;
  std::vector<char> touched_;
  std::vector<std::int32_t> moved_;    // the nodes touched_ marks, in the order first reached
  std::vector<std::int32_t> pending_;  // the nodes with a share in this pass's sums
  std::vector<Pair> pairs_;
  std::vector<std::vector<Pair>> thread_pairs_;  // each thread's, in its rows' order
  std::vector<double> cell_extents_;             // the largest side of each held cell's box

  // A triangle's plane: its normal times twice its area at the step's start, and its unit
  // normal at the end; area0 is 0 for a triangle that turned over in the step (cell_planes).
  struct Plane {
    Vec3 normal0;
    double area0;
    Vec3 normal1;
    double area1;
  };
  std::vector<Plane> planes_;  // four a cell, in the order of find_pairs' triangles; hit only
  std::vector<char> needed_;   // a listed cell some node's box meets this step (find_pairs)
  struct Hit {
    std::int32_t node, cell;
  };
  std::vector<std::vector<Hit>> thread_hits_;  // each thread's, in its nodes' order

  // The broad phase: every cell's box over the step in buckets of a spatial hash.
  std::vector<Vec3> box_lo_, box_hi_;
  std::vector<std::uint32_t> bucket_start_, bucket_cells_;
  std::vector<std::int32_t> large_cells_;
  std::vector<std::vector<std::int32_t>> thread_candidates_, thread_lists_;  // each thread's
  // Each node's candidate cells (list_cells_ from list_start_[p] to list_start_[p + 1]), found
  // with the nodes at built_.
  std::vector<std::uint32_t> list_start_;
  std::vector<std::int32_t> list_cells_;
  std::vector<Vec3> built_;
  // How far each node may go from built_ in a coordinate before the lists are built again
  // (find_pairs), m; and each cell's box at the build grown by the largest of its corners'.
  std::vector<double> leeway_;
  std::vector<Vec3> reach_lo_, reach_hi_;
  double drift_ = 0.0;  // how much farther than its leeway a node has gone from built_, m
  // The cells in some node's list, in increasing order: those whose box and planes a step
  // needs.
  std::vector<std::int32_t> listed_;
  std::vector<char> listed_mark_;

  // Edges against edges, whose crossings no node meets: edges are numbered (k, l)–(k + 1, l) as
  // k + (m − 1) l, then (k, l)–(k, l + 1) as (m − 1) n + k + m l, then each cell c's diagonals
  // from (k, l) and from (k + 1, l), after those, as c and (m − 1)(n − 1) + c. The candidates are
  // the pairs of edges, nodes more than two apart, whose boxes met at the last build (each pair
  // once, the lower number first where both are listed); those of two edges inside the cloth
  // are held only where they cross (find_edge_pairs).
  std::array<std::int32_t, 2> edge_nodes(std::int32_t edge) const;
  std::array<std::int32_t, 2> edge_cells(std::int32_t edge) const;
  // Cell c's six edges, in the order of kCellEdges (self_contact.cpp).
  std::array<std::int32_t, 6> cell_edges(std::int32_t c) const;
  // Whether an edge meets others under the rule (every edge, or the border's: every_edge_).
  bool meets_others(std::int32_t edge) const {
    return every_edge_ || border_edge_[static_cast<std::size_t>(edge)] != 0;
  }
  // An edge's own cell: the first of its two this rank holds. Each pair of edges is found from
  // the two own cells alone (build_candidates).
  std::int32_t own_cell(std::int32_t edge) const;
  bool through_cell(std::int32_t p, std::int32_t q, std::int32_t cell) const;
  std::vector<char> border_edge_;  // over every edge: 1 on the cloth's border
  // The edges of the cells held that meet others (every edge, or the border's: every_edge_), in
  // increasing number.
  std::vector<std::int32_t> present_edges_;
  // Each held cell's near cells (near_cells_ from near_start_[c] to near_start_[c + 1]), found
  // at the build: those whose boxes come within the thickness of its own, not next to it.
  std::vector<std::uint32_t> near_start_;
  std::vector<std::int32_t> near_cells_;
  std::vector<char> near_mark_;           // a cell with near cells, or near another's
  std::vector<std::int32_t> looked_up_;   // the own cells of present_edges_, in increasing order
  std::vector<Vec3> edge_lo_, edge_hi_;   // an edge's box over the step at the build (grown)
  struct EdgeCandidate {
    std::int32_t e, f;
    std::int32_t nodes[4];  // e's two, then f's
    bool inside;            // neither on the border: held only where they cross
  };
  std::vector<EdgeCandidate> edge_candidates_;
  std::vector<std::vector<EdgeCandidate>> thread_edge_candidates_;
};

}  // namespace cosserat
