#pragma once
// What the sheet looks like where the stability monitor (docs/equations.md §4.2) stopped a run, so
// that the message says what happened instead of only that a node moved too far.

#include <string>

#include "cosserat/grid/block.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat {

// Looks at the positions `r` (the last good state; ghosts current) within a few nodes of the
// node (k, l) where the run failed: node pairs far apart in the grid but closer than h/2 in
// space (the sheet passes through itself), adjacent cells whose normals oppose (folded fully
// over), cells whose metric determinant collapsed. h1, h2: the rest spacings. Collective over
// the block's communicator: the rank that owns (k, l) looks, every rank gets its sentence.
std::string diagnose_failure(const Field<Vec3>& r, int k, int l, double h1, double h2);

}  // namespace cosserat
