#include "affordable.hpp"

#include <toml++/toml.h>

#include <cstdint>

#include "checked_toml.hpp"
#include "cosserat/scene/scene.hpp"
#include "overrides.hpp"

namespace cosserat::fuzz {

bool affordable(const std::string& text, const std::vector<std::string>& overrides) {
  constexpr long kMostNodesWithSets = 1L << 18;
  toml::table document;
  try {
    document = toml::parse(text, std::string("fuzz.toml"));
    const scene_detail::Origin origin("fuzz.toml");
    for (const auto& assignment : overrides) {
      scene_detail::apply_override(document, assignment, origin);
    }
  } catch (const toml::parse_error&) {
    return true;
  } catch (const SceneError&) {
    return true;
  }
  if (!document.contains("fix") && !document.contains("load")) return true;
  // value_exact: value<long> would convert a float such as 4.9e19 to long, which is undefined.
  const auto m = document["grid"]["nodes"][0].value_exact<std::int64_t>();
  const auto n = document["grid"]["nodes"][1].value_exact<std::int64_t>();
  if (!m || !n || *m < 1 || *n < 1) return true;
  return *m <= kMostNodesWithSets / *n;
}

}  // namespace cosserat::fuzz
