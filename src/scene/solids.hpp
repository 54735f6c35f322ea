#pragma once
// [[solid]] blocks (docs/scene-format.md "Solids"): rigid solids the cloth meets, read into
// SolidSpec. Private to src/scene.

#include <vector>

#include "checked_toml.hpp"
#include "cosserat/contact/solid.hpp"
#include "cosserat/scene/scene.hpp"

namespace cosserat::scene_detail {

// The solids of the top-level `solid` entry, in file order. Reads the grid of `scene` (the
// default thickness is a fraction of its spacing) and its path (a mesh file is relative to the
// scene file's directory), so the grid must be read first.
std::vector<SolidSpec> read_solids(const Entry& blocks, const Scene& scene);

}  // namespace cosserat::scene_detail
