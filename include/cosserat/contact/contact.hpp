#pragma once
// Cloth against rigid solids (docs/contact.md, "Detection", "Response" and
// "Parallel runs, restarts and output"): the solids of a scene, their motion, and the
// detection and response applied to a proposed step. Works on this rank's block: contacts on
// owned nodes and owned cells, the free bodies' impulse sums exact and independent of the
// decomposition, so every rank moves every body identically.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cosserat/contact/geometry.hpp"
#include "cosserat/contact/solid.hpp"
#include "cosserat/grid/block.hpp"
#include "cosserat/model/node_mass.hpp"
#include "cosserat/grid/halo.hpp"
#include "cosserat/grid/wide_copy.hpp"

namespace cosserat {

// A node whose velocity contact changed: the scheme carries `velocity` into its next step.
struct NodeVelocity {
  int k, l;
  Vec3 velocity;
};

// The velocities a step's actions set, a node once. The contact's walk sets those of the nodes
// it settles on planes itself, in the scheme's r⁻ (RowReader::begin_walk).
class NodeVelocities {
 public:
  void clear() { own_.clear(); }
  void push_back(const NodeVelocity& v) { own_.push_back(v); }
  bool empty() const { return own_.empty(); }
  template <class Body>
  void for_each(Body&& body) const {
    for (const NodeVelocity& v : own_) body(v);
  }

 private:
  std::vector<NodeVelocity> own_;
};

// The state of a solid at one time.
struct SolidState {
  Pose pose;
  Vec3 velocity;          // of the frame's origin (the centre of mass of a free body)
  Vec3 angular_velocity;  // world frame
};

// What one step's response found, on all ranks.
struct ContactStats {
  double max_penetration = 0.0;  // deepest any owned node sat inside a solid after the response, m
  long contacts = 0;             // nodes the response moved
};

class Contact {
 public:
  // `node_mass` gives the lumped mass of each node (kg), `spacing` the smaller grid spacing.
  Contact(const std::vector<SolidSpec>& solids, const Block& block, Halo& halo,
          const NodeMass& node_mass, const Vec3& gravity, double spacing);
  ~Contact();
  Contact(const Contact&) = delete;
  Contact& operator=(const Contact&) = delete;

  // Upper bound of the memory a block's contact with `solids` takes, none without solids:
  // its per-node fields, the walk's records and each fixed bounded solid's remembered
  // clearances (docs/contact.md, "Cost").
  static double memory_bytes(const Block& block, const std::vector<SolidSpec>& solids);

  std::size_t size() const { return solids_.size(); }
  const SolidSpec& spec(std::size_t i) const { return solids_[i].spec; }
  const SolidGeometry& geometry(std::size_t i) const { return solids_[i].geometry; }
  // At the current (last accepted) time.
  const SolidState& state(std::size_t i) const { return solids_[i].state; }

  // The step from `time` to `time + dt` proposed `next` (owned nodes) from `current` (ghosts
  // valid), with `next_velocities` when the scheme carries velocities, else the velocity is
  // (next − current)/dt. Moves owned nodes of `next` out of every solid (its ghosts are left
  // stale: the caller exchanges them), lists the changed velocities in `corrected`, and
  // proposes the solids' state at time + dt. Collective over the block's ranks.
  // With `moved_rows` (per owned row), sets the rows it moved a node of since the walk, if
  // there was one (the walk's own moves come before the edge test reads the rows).
  ContactStats respond(double time, double dt, const Field<Vec3>& current, Field<Vec3>& next,
                       const Field<Vec3>* next_velocities, NodeVelocities& corrected,
                       std::vector<char>* moved_rows = nullptr);
  // While a scheme's row walk still has them in cache, for the step respond() is then called
  // for (from `time` by `dt`, velocities (next − current)/dt): row l meets the planes and
  // gives the broad phase its boxes, from any thread, each row once (docs/contact.md,
  // "Cost"). A step without a walk leaves both to respond(). With `starts` (RowReader), the
  // velocities of the nodes the walk moves onto planes go there as r⁺ − Δt v, and
  // respond() lists only those of nodes it moves again.
  void begin_walk(double time, double dt, Field<Vec3>* starts = nullptr);
  void walk_row(int l, const Field<Vec3>& current, Field<Vec3>& next);
  // Whether a walk sets velocities: with a plane.
  bool walk_sets_velocities() const { return planes_ > 0; }
  // Whether the walk meets the planes in its AVX2 copy, with the same bits (grid/wide_copy.hpp):
  // where the build has one and the CPU runs it. Settable for the test that holds the copies
  // to the same bits.
  bool wide_walk() const { return wide_walk_; }
  void set_wide_walk(bool wide) { wide_walk_ = wide && wide_copies_available(); }

  // Whether a solid moves (kinematic or free).
  bool any_moving() const;
  // The longest step over which no moving solid, at its speed at the last accepted time, brings
  // its surface more than `reach` into the box [lo, hi] of the cloth's nodes: the least over
  // those solids of (gap + reach) / speed, the speed bounding every point of the surface that
  // can meet the box; +∞ with none moving (docs/stability.md, "Adaptive steps").
  double approach_step(const Vec3& lo, const Vec3& hi, double reach) const;

  // The proposed step was accepted: the solids take their proposed state.
  void accept();
  // How many tile bands the next walk finds far from every solid (docs/contact.md, "Cost").
  int far_bands() const {
    return static_cast<int>(std::count(band_far_.begin(), band_far_.end(), 1));
  }

  // Every solid's state (and the pushes still on) as numbers, for roll-backs and checkpoints;
  // restore() takes what state_vector() gave.
  std::vector<double> state_vector() const;
  void restore(const std::vector<double>& values);

 private:
  struct Solid {
    SolidSpec spec;
    SolidGeometry geometry;
    Vec3 inertia_per_mass;  // free bodies: principal moments / mass, body frame
    SolidState state;       // at the last accepted time
    SolidState proposed;    // at the end of the step being proposed
    bool pushing = false;   // free bodies: the constant push still acts
    bool proposed_pushing = false;
    Vec3 local_lo, local_hi;    // bounded shapes: the box holding it in its frame
    Vec3 reach_lo, reach_hi;    // and in the world at the proposed pose (the broad phase)
    Vec3 plane_normal;          // a plane's world normal at the proposed pose
  };
  // One node's change by one solid, for a free body's sums (see contact.cpp).
  struct Exchange;
  // A cell triangle's correction (see cell_pass).
  struct CellPush;
  // Where a tile's nodes are (see the broad phase in contact.cpp).
  struct Box {
    Vec3 lo, hi;
    double moved = 0.0;  // the largest move of a node over the step
  };
  // The owned nodes in square tiles of kTile; tile (i, j) holds k in k0 + kTile [i, i + 1).
  static constexpr int kTile = 8;
  struct TileRange {
    int k0, k1, l0, l1;
  };
  TileRange tile_nodes(int i, int j) const;
  // The nodes of the cells tile (i, j) answers for, ghosts included, inclusive bounds.
  TileRange tile_cell_nodes(int i, int j) const;
  std::size_t tile(int i, int j) const { return static_cast<std::size_t>(i + j * tiles_k_); }
  // Sets near_ and spare_ of tile t from its box.
  void classify(std::size_t t);
  void make_box(int i, int j, const Field<Vec3>& current, const Field<Vec3>& next);
  // The same from the rows walk_row() saw.
  void merge_rows(int i, int j);
  // A far band's tile box: its box when the band was found far, grown by the band's travel
  // and this step's move, `moved` (far_band_move).
  void far_box(int i, int j, double moved);
  double far_band_move(int j) const;
  // After a walked response: which bands are far for the next step's walk.
  void mark_far_bands();
  [[gnu::always_inline]] inline void grow_box(std::size_t t, int k, int l,
                                              const Field<Vec3>& current,
                                              const Field<Vec3>& next);
  // Sets a tile's velocities from the proposed step, once a response.
  void prepare(int i, int j, const Field<Vec3>& current, Field<Vec3>& next);

  void propose_free(Solid& s, double dt) const;
  // Every solid's state at time + dt and what the broad phase needs of it.
  void propose(double time, double dt);
  // A plane met by a node whose proposed end is r, moving at v, with `scheme_offset`
  // (slip_correction): r goes onto its offset surface and v takes the response (docs/contact.md,
  // "Response"), `surface` the plane's velocity there. False, and nothing changed, when r is clear
  // of it.
  [[gnu::always_inline]] inline bool meet_plane(const Solid& s, Vec3& r, Vec3& v, Vec3& surface,
                                                const Vec3& scheme_offset) const;
  // The planes for kLanes nodes at once, in lanes of doubles (see contact.cpp): the walk's.
  struct PlaneLanes;
  template <bool OneStill>
  [[gnu::always_inline]] inline void meet_planes(PlaneLanes& lanes) const;
  // The height of r over plane s, along its normal.
  static double plane_height(const Solid& s, const Vec3& r) {
    return dot(r - s.proposed.pose.position, s.plane_normal);
  }
  // Whether a node at signed distance d sits inside a solid's offset layer: round-off of the
  // projection onto the offset surface is not inside.
  bool inside_offset(double d, double offset) const { return d < inside_level(offset); }
  double inside_level(double offset) const { return offset - 1e-9 * (offset + spacing_); }
  // The walk's two parts (walk_row); the planes' wide copy (grid/wide_copy.hpp).
  void walk_planes(int l, const Field<Vec3>& current, Field<Vec3>& next);
  template <bool OneStill>
  void walk_planes_of(int l, const Field<Vec3>& current, Field<Vec3>& next);
  void walk_planes_wide(int l, const Field<Vec3>& current, Field<Vec3>& next);
  void walk_boxes(int l, const Field<Vec3>& current, const Field<Vec3>& next);
  // An owned node's place in walk_met_ and walk_velocity_.
  std::size_t walk_index(int k, int l) const {
    return static_cast<std::size_t>(l - block_->l0) * static_cast<std::size_t>(block_->owned_k()) +
           static_cast<std::size_t>(k - block_->k0);
  }
  // Inline, with remember() and settled_velocity(): run for every node in contact, their
  // Vec3 arguments passed through memory cost more than their arithmetic.
  [[gnu::always_inline]] inline Vec3 velocity_change(const Solid& s, const Vec3& surface,
                                                     const Vec3& normal,
                                                     const Vec3& velocity) const;
  [[gnu::always_inline]] inline Vec3 slip_correction(const Vec3& change, const Vec3& normal,
                                                     const Vec3& scheme_offset) const;
  // A node's scheme offset (scheme_offset_; zero for the Verlet family), and the same, used up
  // by the response that corrects the node's move.
  Vec3 scheme_offset_at(int k, int l) const;
  Vec3 take_offset(int k, int l);
  void record(std::size_t solid, int pass, int phase, int k, int l, const Vec3& r_before,
              const Vec3& v_before, const Vec3& r_after, std::vector<Exchange>& out) const;
  // Node (k, l) met solid s with world normal n, arriving at `velocity` against a surface
  // moving at `surface`: what settled_velocity() needs to make its velocity consistent.
  [[gnu::always_inline]] inline void remember(const Solid& s, int k, int l, const Vec3& n,
                                              const Vec3& surface, const Vec3& velocity);
  // The velocity touched node (k, l) leaves with (docs/contact.md, "Velocities").
  [[gnu::always_inline]] inline Vec3 settled_velocity(int k, int l, const Field<Vec3>& current,
                                                      const Field<Vec3>& next) const;
  // Its formula, from the node's move over the step `moved` (as a velocity), the contact's
  // normal n, the surface's velocity and the normal speed the response leaves it
  // (leaving_speed(): e times the approach, or a leaving node's own).
  [[gnu::always_inline]] static inline Vec3 settled(const Vec3& moved, const Vec3& n,
                                                    const Vec3& surface, double speed);
  [[gnu::always_inline]] static inline double leaving_speed(const Solid& s, const Vec3& n,
                                                            const Vec3& surface,
                                                            const Vec3& velocity);
  void node_pass(int pass, const Field<Vec3>& current, Field<Vec3>& next,
                 std::vector<Exchange>& out);
  void cell_pass(int pass, std::size_t solid, const Field<Vec3>& current, Field<Vec3>& next,
                 std::vector<Exchange>& out);
  // Whether an owned node still sits inside a solid's offset layer (any rank); the deepest
  // any owned node sits inside a solid itself goes to `penetration`.
  bool any_inside(int pass, const Field<Vec3>& next, double& penetration) const;
  void apply_impulses(std::vector<Exchange>& exchanges);

  std::vector<Solid> solids_;
  const Block* block_;
  Halo* halo_;
  NodeMass node_mass_;
  Vec3 gravity_;
  double spacing_;
  double dt_ = 0.0;           // of the step being proposed
  std::vector<double> shift_;  // node_pass: each solid's frame's move over the step (m)
  std::vector<double> turn_;   // and its turn (rad)
  bool any_free_ = false;
  Field<Vec3> velocity_;           // the nodes' velocities during a response
  Field<unsigned char> touched_;   // nodes the response changed: kTouched, kByFreeBody
  Field<Vec3> contact_normal_;     // their last contact's world normal
  Field<Vec3> surface_velocity_;   // and that surface's velocity there
  Field<double> normal_speed_;     // and the response's normal speed away from it
  // Schemes that carry velocities: each node's move over the step beyond Δt times the velocity
  // it ends with, until the response corrects its move (slip_correction). Allocated on the
  // first step of such a scheme.
  Field<Vec3> scheme_offset_;
  Field<double> distance_;         // cell_pass: a lower bound of each node's signed distance
  Field<Vec3> normal_;             // and the normal there (solid's frame), zero when far
  Field<Vec3> local_;              // cell_pass: each node's proposed end in the solid's frame
  std::vector<CellPush> cells_;    // cell_pass: the triangles pressed in
  // cell_pass: each node's sum over its pressed triangles, how many (x) and then how far their
  // pushes lift it; a Vec3 so that the halo carries it. With bounded solids only.
  Field<Vec3> node_sums_;
  std::vector<int> slot_;          // cell_pass: each triangle's index in cells_, or −1
  int tiles_k_ = 0, tiles_l_ = 0;
  std::vector<Box> boxes_;                   // per tile: its nodes at both ends of the step
  // Per owned row and tile column, from walk_row(): as boxes_ for the rows of its tile band
  // from its run's first to it, `moved` a bound of the largest squared move; only where
  // row_boxed_ says a run ended on that row (walk_boxes).
  std::vector<Box> row_boxes_;
  std::vector<unsigned char> row_boxed_;
  // Per tile band: its every tile was found far from every solid (near_ 0, none touched) from
  // the box kept in far_boxes_, and its nodes have moved at most band_travel_ since. For such
  // a band the walk finds only each row's largest squared move along an axis (row_move_), and
  // its tiles' boxes are the kept ones grown by the travel, until one is found near again
  // (docs/contact.md, "Cost"). A restore() forgets them.
  std::vector<unsigned char> band_far_;
  std::vector<double> band_travel_;
  std::vector<Box> far_boxes_;
  std::vector<double> row_move_;
  // Per thread: its run of rows of one tile band so far, each tile column's 3 kTile values
  // (x, y, z of each node slot) of the least, greatest and largest squared move of its nodes.
  struct BoxRun {
    int last = 0;
    bool open = false;
    std::vector<double> low, high, square;
  };
  std::vector<BoxRun> box_runs_;
  void close_box_run(BoxRun& run);
  // walk_row() saw every row of this step, and begin_walk() proposed the solids' states.
  bool walked_ = false;
  // The walk's `starts`, or null.
  Field<Vec3>* walk_starts_ = nullptr;
  bool wide_walk_ = wide_copies_available();
  // The planes, and then the other solids, each in scene order: the order a node meets them.
  std::vector<std::size_t> order_;
  std::size_t planes_ = 0;        // how many of order_ are planes
  // Whether the walk finds the tiles' boxes: only a bounded solid needs them in a first pass.
  bool walk_boxes_ = false;
  std::uint64_t plane_bits_ = 0;  // their bits (solid_bit)
  // Per owned node, from walk_row(): whether a plane moved it, and its velocity after the
  // planes, for the response's fields where it goes on (prepare); per owned row, how many it
  // moved, whether one was left inside a plane, and the deepest any sat inside one.
  std::vector<unsigned char> walk_met_;
  std::vector<Vec3> walk_velocity_;
  // Whether the walk keeps walk_velocity_. With one plane and nothing else, only a node left
  // inside it reads the velocities again (a later pass, which the walk's move onto the plane
  // leaves to round-off far from its coordinates); the velocity it leaves with stands in for
  // its velocity after the plane, which it equals but for rounding (docs/contact.md, "Cost").
  bool walk_after_ = true;
  std::vector<int> walk_count_;
  std::vector<char> walk_inside_;
  std::vector<double> walk_deepest_;
  std::vector<std::uint64_t> near_;          // per tile: the solids (bit i) its nodes can meet
  std::vector<double> spare_;                // per tile: how far a node can move and not
  std::vector<unsigned char> tile_touched_;  // per tile: the response moved one of its nodes
  std::vector<unsigned char> cells_near_;    // cell_pass: per tile, its cells may meet the solid
  std::vector<unsigned char> cells_live_;    // and one of them is not known to be clear
  std::vector<unsigned char> live_cells_;    // cell_pass: per cell, likewise (see there)
  // A fixed solid's cells found clear (docs/contact.md, "Cost"): per solid (empty for the
  // others) and cell of owned nodes, the bound of its distance found then, plus `since` of its
  // tile then (travelled_tile), or −∞. Per tile, the sum over the accepted steps of the
  // largest move of its nodes and of the next tiles'. A response not followed by accept() (a
  // step that failed), or a restore(), forgets them.
  std::vector<std::vector<double>> clear_;
  std::vector<std::vector<double>> node_clear_;  // and per owned node, its end's distance
  std::vector<double> travel_;
  bool unaccepted_ = false;
  void forget_clear();
  struct Travel {
    double since, until;
  };
  Travel travelled_tile(std::size_t t) const;
  double cell_reach_move(int i, int j) const;  // the largest move of tile (i, j) and the next
  std::vector<Travel> reach_;  // cell_pass: per tile, travelled_tile for its cells' nodes
  std::vector<unsigned char> pushed_;        // cell_pass: per tile, a triangle pushes its nodes
  std::vector<unsigned char> ready_;         // per tile: prepare() has set its velocities
  const Field<Vec3>* next_velocities_ = nullptr;  // of the step being proposed, or null
  std::vector<std::vector<Exchange>> exchange_rows_;  // per tile row, reused step to step
  std::vector<std::vector<CellPush>> push_rows_;
};

}  // namespace cosserat
