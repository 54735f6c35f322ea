#pragma once
// Which fuzz inputs to skip. The loader accepts grids up to INT_MAX x INT_MAX nodes and expands
// every [[fix]] and [[load]] region into one entry per node, so a valid scene can ask for more
// memory than the machine has: the machine's limit, not a defect of the loader, and libFuzzer
// would stop at it as "out of memory" (ASan's operator new reports instead of throwing).

#include <string>
#include <vector>

namespace cosserat::fuzz {

// False when the scene, after `overrides`, has node sets on a grid of more than 2^18 nodes.
// Anything the loader would refuse anyway (bad TOML, a bad --set) counts as affordable.
bool affordable(const std::string& text, const std::vector<std::string>& overrides);

}  // namespace cosserat::fuzz
