#pragma once
// Per-node measures of the deformed sheet that a run writes beside its positions (docs/output.md,
// "Fields"), from the per-node geometry of docs/equations.md §2.1 at the owned nodes of a block. A
// node's value depends on its 3 × 3 box alone (the ghosts one node beyond the owned range must be
// current), so every decomposition and thread count gives the same bits.

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/reduce.hpp"
#include "cosserat/grid/vec3.hpp"
#include "cosserat/model/material.hpp"

namespace cosserat {

// The metric A_αβ of the flat rest sheet spanned by the grid directions u and v.
inline Sym2 flat_metric(const Vec3& u, const Vec3& v) { return {dot(u, u), dot(u, v), dot(v, v)}; }

// √(a/A), a = det a_αβ and A = det A_αβ of the rest metric (docs/equations.md §1), with the
// tangents of §2.1 rule 1: the area of the surface element at the node over its rest area.
void area_ratio(const Field<Vec3>& positions, double h1, double h2, const Sym2& rest_metric,
                Field<double>& ratio);

// The mean curvature H = ½ a^{αβ} b_αβ (1/m), b_αβ = n · r_,αβ with n and r_,αβ of §2.1 rules
// 2 and 3: positive where the sheet bends towards n (the side a₁ × a₂ points to).
void mean_curvature(const Field<Vec3>& positions, double h1, double h2, Field<double>& curvature);

// This block's share of the total area S: the two triangles of every cell whose lower-left
// node it owns (docs/equations.md §3), each cell counted in multiples of `quantum` so that the
// global total does not depend on the decomposition. Reads the ghosts at k + 1 and l + 1.
QuantizedSum block_area(const Field<Vec3>& positions, double quantum);

}  // namespace cosserat
