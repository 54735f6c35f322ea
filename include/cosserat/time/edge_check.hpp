#pragma once
// The edge test of the stability check (docs/equations.md §4.2): which rows hold a node with an
// edge that changed by more than the limit in one step, found either while a scheme's row walk
// still has the rows in cache, or in a pass of its own.

#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/vec3.hpp"
#include "cosserat/time/row_walk.hpp"

namespace cosserat {

class EdgeCheck final : public RowReader {
 public:
  // limit: the largest change of an edge that passes (half the smaller grid spacing).
  EdgeCheck(const Block& block, double limit);

  // Whether a scheme may test rows during its walk in this step: not when a step action (a
  // contact response) moves nodes after the scheme and before the check without saying which
  // rows it moved.
  bool armed() const { return armed_; }
  void arm(bool on) {
    armed_ = on;
    walked_ = false;
  }

  // A walk, in which each thread hands over the rows of r and r⁺ it has just finished, in
  // ascending order, held by the constraints. Tests the edges within the row's owned columns
  // and, if the same thread handed over the row below, the edges between the two.
  void begin_walk();
  void walk_row(int l, const Field<Vec3>& r, const Field<Vec3>& next);
  void begin_walk(double /*time*/, double /*dt*/, Field<Vec3>* /*starts*/) override {
    begin_walk();
  }
  void walk_row(int l, const Field<Vec3>& r, Field<Vec3>& next) override {
    walk_row(l, r, static_cast<const Field<Vec3>&>(next));
  }

  // After the exchange of r⁺'s ghosts: per owned row, whether some edge of one of its nodes
  // may have changed too much (a NaN or infinity changes every edge of its node). What the walk
  // left untested (edges between threads' bands, to ghost rows and columns) is tested now; with
  // no walk in this step, everything is. `moved`, per owned row, the rows a step action moved
  // nodes of after the walk: their edges, and those to the rows either side, are tested again.
  const std::vector<char>& flag_rows(const Field<Vec3>& r, const Field<Vec3>& next,
                                     const std::vector<char>* moved = nullptr);

 private:
  bool edge(int ka, int la, int kb, int lb, const Field<Vec3>& r, const Field<Vec3>& next) const;
  bool vertical(int la, int ka, int kb, const Field<Vec3>& r, const Field<Vec3>& next) const;
  bool horizontal(int l, const Field<Vec3>& r, const Field<Vec3>& next) const;
  bool runs_changed(const Vec3* p, const Vec3* q, const Vec3* p2, const Vec3* q2,
                    int count) const;

  const Block* block_;
  double limit2_;
  bool armed_ = false;
  bool walked_ = false;
  // Per thread: the row it handed over last, and the moves r⁺ − r of that row and of the
  // current one, x, y and z each contiguous, so that the tests read them with unit stride.
  struct alignas(64) Walker {
    int last = 0;
    std::vector<double> moves;  // two rows of three components
  };
  std::vector<Walker> walkers_;
  std::vector<char> may_fail_;     // per owned row
  std::vector<char> below_done_;   // per owned row: its edges to the row below were tested
};

}  // namespace cosserat
