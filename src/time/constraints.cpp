#include "cosserat/time/constraints.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace cosserat {

namespace {
// Node s's held components to their held value at `time`.
void hold(const Constraints::NodeState& s, Field<Vec3>& positions, double time) {
  Vec3& r = positions(s.k, s.l);
  // A turning node holds all three components: one turn for the three.
  if (s.turns()) {
    r = s.turned(time);
    return;
  }
  for (int c = 0; c < 3; ++c)
    if (s.held & (1u << c)) r[c] = s.position(c, time);
}
bool same(const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
}  // namespace

Constraints::Constraints(const std::vector<Fix>& fixes, const Block& block) {
  // Several fixes may hold one node: gather them per node, in a fixed (l, k) order.
  std::map<std::pair<int, int>, std::vector<AxesWindow>> by_node;
  for (const Fix& fix : fixes) {
    std::uint8_t axes = 0;
    for (int c = 0; c < 3; ++c)
      if (fix.axes[static_cast<std::size_t>(c)]) axes |= static_cast<std::uint8_t>(1u << c);
    for (const NodeIndex& node : fix.nodes.nodes)
      if (block.owns(node.k, node.l))
        by_node[{node.l, node.k}].push_back(
            AxesWindow{axes, fix.window, fix.velocity, fix.angular_velocity, fix.center});
  }
  for (auto& [lk, windows] : by_node)
    nodes_.push_back(HeldNode{std::move(windows), NodeState{lk.second, lk.first, 0, {}}});
}

void Constraints::begin_step(long step, double time, const Field<Vec3>& positions) {
  for (HeldNode& node : nodes_) {
    NodeState& s = node.state;
    std::uint8_t held = 0;
    Vec3 velocity{}, spin{}, pivot{};
    // Of the fixes holding a component in this step, the last in the scene sets its velocity:
    // a fix that takes over from another at the end of its window then needs no gap. A turning
    // fix holds all three; a later fix that does not turn ends the turn.
    for (const AxesWindow& w : node.windows)
      if (w.window.contains(step, time)) {
        held |= w.axes;
        spin = w.spin;
        pivot = w.pivot;
        for (int c = 0; c < 3; ++c)
          if (w.axes & (1u << c)) velocity[c] = w.velocity[c];
      }
    const Vec3 now = positions(s.k, s.l);
    // Where a turn starts, ends or changes, every component is taken where it is now.
    const bool new_turn = !same(spin, s.spin) || !same(pivot, s.pivot);
    for (int c = 0; c < 3; ++c) {
      const bool newly_held = (held & ~s.held) & (1u << c);
      const bool held_on = (held & s.held) & (1u << c);
      // The held value is where the node is, so a change of velocity does not make it jump.
      if (newly_held || (held_on && (velocity[c] != s.velocity[c] || new_turn))) {
        s.value[c] = now[c];
        s.since[c] = time;
      }
      s.velocity[c] = (held & (1u << c)) ? velocity[c] : 0.0;
    }
    s.spin = spin;
    s.pivot = pivot;
    s.held = held;
  }
}

void Constraints::hold_positions(Field<Vec3>& positions, double time) const {
  for (const HeldNode& node : nodes_) hold(node.state, positions, time);
}

void Constraints::hold_row(Field<Vec3>& positions, int l, double time) const {
  auto node = std::lower_bound(nodes_.begin(), nodes_.end(), l,
                               [](const HeldNode& n, int row) { return n.state.l < row; });
  for (; node != nodes_.end() && node->state.l == l; ++node) hold(node->state, positions, time);
}

void Constraints::hold_velocities(Field<Vec3>& velocities, double time) const {
  for (const HeldNode& node : nodes_) {
    const NodeState& s = node.state;
    Vec3& v = velocities(s.k, s.l);
    if (s.turns()) {
      v = cross(s.spin, s.turned(time) - s.pivot);
      continue;
    }
    for (int c = 0; c < 3; ++c)
      if (s.held & (1u << c)) v[c] = s.velocity[c];
  }
}

Vec3 Constraints::NodeState::turned(double time) const {
  const double rate = norm(spin);
  const Vec3 axis = spin / rate;
  const double angle = rate * (time - since.x);
  const Vec3 offset = value - pivot;
  const double cosine = std::cos(angle), sine = std::sin(angle);
  return pivot + cosine * offset + sine * cross(axis, offset) +
         ((1.0 - cosine) * dot(axis, offset)) * axis;
}

std::vector<Constraints::NodeState> Constraints::state() const {
  std::vector<NodeState> states;
  states.reserve(nodes_.size());
  for (const HeldNode& node : nodes_) states.push_back(node.state);
  return states;
}

void Constraints::restore(const std::vector<NodeState>& states) {
  std::map<std::pair<int, int>, const NodeState*> by_node;
  for (const NodeState& s : states) by_node[{s.k, s.l}] = &s;
  for (HeldNode& node : nodes_)
    if (const auto found = by_node.find({node.state.k, node.state.l}); found != by_node.end())
      node.state = *found->second;
}

}  // namespace cosserat
