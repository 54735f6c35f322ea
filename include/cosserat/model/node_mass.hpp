#pragma once
// The lumped node masses of a discretisation (docs/model.md, "Energy quadrature"): μ0 h1 h2
// times the node's share of the dual area, the weight the trapezoidal quadrature gives it
// (1 inside, ½ on a border, ¼ at a corner), or the same mass at every node.

namespace cosserat {

struct NodeMass {
  double interior = 0.0;  // kg, the mass of a node with all four neighbours
  int m = 0, n = 0;       // the grid
  bool dual_areas = false;  // false: every node carries `interior`

  // The node's share of the dual area; the factors ½ and ¼ are exact in floating point.
  double weight(int k, int l) const {
    if (!dual_areas) return 1.0;
    const double wk = (k == 0 || k == m - 1) ? 0.5 : 1.0;
    const double wl = (l == 0 || l == n - 1) ? 0.5 : 1.0;
    return wk * wl;
  }
  double operator()(int k, int l) const { return interior * weight(k, l); }
};

}  // namespace cosserat
