#pragma once
// Fixed nodes with axis masks, windows in steps and seconds and prescribed velocities
// (docs/equations.md §4.1, docs/scene-format.md "Fixes and loads"), for the nodes this block owns.

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
  // that becomes held, or whose held velocity changes, is held from the value it has now
  // (docs/equations.md §4.1), not its rest value.
  void begin_step(long step, double time, const Field<Vec3>& positions);

  // Held components to their held value / velocity at `time` (the time the field belongs to).
  void hold_positions(Field<Vec3>& positions, double time) const;
  // The same for the nodes of row l only, for a scheme that finishes a field row by row.
  void hold_row(Field<Vec3>& positions, int l, double time) const;
  void hold_velocities(Field<Vec3>& velocities, double time) const;

  bool empty() const { return nodes_.empty(); }

  // What begin_step carries from one step to the next, per constrained node of this block:
  // which components are held, and for each the value and time it was taken at and the
  // velocity it moves at since; for a turning node (all three held, taken at one time) the
  // angular velocity and the point of its axis. For checkpoints and the semi-implicit solve.
  struct NodeState {
    int k, l;
    std::uint8_t held;
    Vec3 value;
    Vec3 since{};     // s
    Vec3 velocity{};  // m/s
    Vec3 spin{};      // rad/s
    Vec3 pivot{};     // m

    bool turns() const { return spin.x != 0.0 || spin.y != 0.0 || spin.z != 0.0; }
    // Where held component c is at `time`: a function of the node and time alone, so the same
    // on every decomposition and after a restart.
    double position(int c, double time) const {
      if (turns()) return turned(time)[c];
      return velocity[c] == 0.0 ? value[c] : value[c] + velocity[c] * (time - since[c]);
    }
    // A turning node's position at `time`: its offset from the pivot when taken, turned by
    // Rodrigues' formula through |spin| (time − since) about spin.
    Vec3 turned(double time) const;
  };
  std::vector<NodeState> state() const;
  // Takes over the entries for this block's constrained nodes; others are ignored.
  void restore(const std::vector<NodeState>& states);

 private:
  struct AxesWindow {
    std::uint8_t axes;  // bit c set: component c held
    Window window;
    Vec3 velocity;
    Vec3 spin;
    Vec3 pivot;
  };
  struct HeldNode {
    std::vector<AxesWindow> windows;  // in the scene's order: a later fix wins
    NodeState state;
  };
  std::vector<HeldNode> nodes_;  // in (l, k) order
};

}  // namespace cosserat
