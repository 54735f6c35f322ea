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
  // Whether it sets the velocity some nodes of r⁺ move on with (the contact's response on
  // planes).
  virtual bool sets_velocities() const { return false; }
  // Once before the walk of the step from `time` by `dt`, on one thread. `starts`, for the
  // one reader that sets velocities, under a scheme that carries r⁻ rather than velocities
  // (the Verlet family): the field that becomes the next step's r⁻. The reader writes each
  // row it is handed there in full: r⁺ − Δt v for a node it gives the velocity v, r for the
  // others; it reports those velocities nowhere else. The velocities copied into r⁻ after the
  // step had cost as much as the response on a plane itself (docs/contact.md, "Cost"). Null
  // otherwise.
  virtual void begin_walk(double time, double dt, Field<Vec3>* starts) = 0;
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
  bool sets_velocities() const {
    for (const RowReader* reader : readers_)
      if (reader->sets_velocities()) return true;
    return false;
  }
  void begin_walk(double time, double dt, Field<Vec3>* starts) {
    for (RowReader* reader : readers_)
      reader->begin_walk(time, dt, reader->sets_velocities() ? starts : nullptr);
  }
  void walk_row(int l, const Field<Vec3>& r, Field<Vec3>& next) {
    for (RowReader* reader : readers_) reader->walk_row(l, r, next);
  }

 private:
  std::vector<RowReader*> readers_;
};

}  // namespace cosserat
