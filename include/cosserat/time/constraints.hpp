#pragma once
// Fixed nodes with axis masks and windows in steps and seconds (MODEL.md §4.1), for the nodes this block owns.

#include <cstdint>
#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/vec3.hpp"
#include "cosserat/scene/scene.hpp"

namespace cosserat {

class Constraints {
 public:
  Constraints(const std::vector<Fix>& fixes, const Block& block);

  // Switches the fixes acting during `step`, which starts at `time`, on and off. A component
  // that becomes held keeps the value it has now (MODEL.md §4.1), not its rest value.
  void begin_step(long step, double time, const Field<Vec3>& positions);

  // Held components back to their held value / to zero velocity.
  void hold_positions(Field<Vec3>& positions) const;
  void hold_velocities(Field<Vec3>& velocities) const;

  bool empty() const { return nodes_.empty(); }

  // What begin_step carries from one step to the next, per constrained node of this block:
  // which components are held and the values they are held at. For checkpoints.
  struct NodeState {
    int k, l;
    std::uint8_t held;
    Vec3 value;
  };
  std::vector<NodeState> state() const;
  // Takes over the entries for this block's constrained nodes; others are ignored.
  void restore(const std::vector<NodeState>& states);

 private:
  struct AxesWindow {
    std::uint8_t axes;  // bit c set: component c held
    Window window;
  };
  struct HeldNode {
    int k, l;
    std::vector<AxesWindow> windows;
    std::uint8_t held = 0;
    Vec3 value;
  };
  std::vector<HeldNode> nodes_;
};

}  // namespace cosserat
