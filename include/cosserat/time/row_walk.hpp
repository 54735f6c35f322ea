#pragma once
// What reads the rows of r⁺ while a scheme's row walk still has them in cache: the stability
// check's edge test and the step actions that ask for them (the contact with planes and its
// broad phase). A scheme without a row walk calls none of them, and each does that work in a
// pass of its own.

#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat {

class RowReader {
 public:
  virtual ~RowReader() = default;
  // Once before the walk of the step from `time` by `dt`, on one thread.
  virtual void begin_walk(double time, double dt) = 0;
  // Row l of r and r⁺, held by the constraints, from the thread that finished it: each thread
  // hands over its rows in ascending order, the threads' rows in bands. A reader may move the
  // row's nodes of r⁺ (the contact response on planes): the readers after it see them moved.
  virtual void walk_row(int l, const Field<Vec3>& r, Field<Vec3>& next) = 0;
};

// The readers of one step's walk, in the order added.
class RowWalk {
 public:
  void clear() { readers_.clear(); }
  void add(RowReader& reader) { readers_.push_back(&reader); }
  bool empty() const { return readers_.empty(); }
  void begin_walk(double time, double dt) {
    for (RowReader* reader : readers_) reader->begin_walk(time, dt);
  }
  void walk_row(int l, const Field<Vec3>& r, Field<Vec3>& next) {
    for (RowReader* reader : readers_) reader->walk_row(l, r, next);
  }

 private:
  std::vector<RowReader*> readers_;
};

}  // namespace cosserat
