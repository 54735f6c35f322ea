#pragma once
// The --set dotted.key=value arguments, applied to the parsed document before any section is
// read, so an override is checked by the same readers, with the same messages, as the file.
// Private to src/scene.

#include <toml++/toml.h>

#include <string>

#include "checked_toml.hpp"

namespace cosserat::scene_detail {

// Sets `assignment`'s key in `document`, making the tables on its path as needed. The value is
// TOML, or else the bare text. A malformed assignment is a SceneError that quotes it.
void apply_override(toml::table& document, const std::string& assignment, const Origin& origin);

}  // namespace cosserat::scene_detail
