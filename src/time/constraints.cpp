#include "cosserat/time/constraints.hpp"

#include <map>

namespace cosserat {

Constraints::Constraints(const std::vector<Fix>& fixes, const Block& block) {
  // Several fixes may hold one node: gather them per node, in a fixed (l, k) order.
  std::map<std::pair<int, int>, std::vector<AxesWindow>> by_node;
  for (const Fix& fix : fixes) {
    std::uint8_t axes = 0;
    for (int c = 0; c < 3; ++c)
      if (fix.axes[static_cast<std::size_t>(c)]) axes |= static_cast<std::uint8_t>(1u << c);
    for (const NodeIndex& node : fix.nodes.nodes)
      if (block.owns(node.k, node.l))
        by_node[{node.l, node.k}].push_back(AxesWindow{axes, fix.window});
  }
  for (auto& [lk, windows] : by_node)
    nodes_.push_back(HeldNode{lk.second, lk.first, std::move(windows), 0, {}});
}

void Constraints::begin_step(long step, double time, const Field<Vec3>& positions) {
  for (HeldNode& node : nodes_) {
    std::uint8_t held = 0;
    for (const AxesWindow& w : node.windows)
      if (w.window.contains(step, time)) held |= w.axes;
    const std::uint8_t newly_held = held & static_cast<std::uint8_t>(~node.held);
    const Vec3 now = positions(node.k, node.l);
    for (int c = 0; c < 3; ++c)
      if (newly_held & (1u << c)) node.value[c] = now[c];
    node.held = held;
  }
}

void Constraints::hold_positions(Field<Vec3>& positions) const {
  for (const HeldNode& node : nodes_) {
    Vec3& r = positions(node.k, node.l);
    for (int c = 0; c < 3; ++c)
      if (node.held & (1u << c)) r[c] = node.value[c];
  }
}

void Constraints::hold_velocities(Field<Vec3>& velocities) const {
  for (const HeldNode& node : nodes_) {
    Vec3& v = velocities(node.k, node.l);
    for (int c = 0; c < 3; ++c)
      if (node.held & (1u << c)) v[c] = 0.0;
  }
}

std::vector<Constraints::NodeState> Constraints::state() const {
  std::vector<NodeState> states;
  states.reserve(nodes_.size());
  for (const HeldNode& node : nodes_) states.push_back({node.k, node.l, node.held, node.value});
  return states;
}

void Constraints::restore(const std::vector<NodeState>& states) {
  std::map<std::pair<int, int>, const NodeState*> by_node;
  for (const NodeState& s : states) by_node[{s.k, s.l}] = &s;
  for (HeldNode& node : nodes_)
    if (const auto found = by_node.find({node.k, node.l}); found != by_node.end()) {
      node.held = found->second->held;
      node.value = found->second->value;
    }
}

}  // namespace cosserat
