// How --set arguments become values of the document. Values parsed from an argument carry the
// source name "--set" rather than the scene's path, which is how Origin tells them apart.

#include "overrides.hpp"

#include <fmt/format.h>

#include <string_view>
#include <utility>
#include <vector>

#include "cosserat/scene/scene.hpp"

namespace cosserat::scene_detail {
namespace {

// Source name of values parsed from --set arguments.
constexpr std::string_view kSetSource = "--set";

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

[[noreturn]] void bad_override(const Origin& origin, const std::string& assignment,
                               std::string_view what) {
  throw SceneError(fmt::format("{}: --set '{}': {}", origin.path(), assignment, what));
}

std::vector<std::string> dotted_components(const Origin& origin, const std::string& assignment,
                                           std::string_view key) {
  std::vector<std::string> components;
  std::size_t begin = 0;
  while (true) {
    const auto dot = key.find('.', begin);
    const auto component =
        trim(key.substr(begin, dot == std::string_view::npos ? dot : dot - begin));
    if (component.empty()) bad_override(origin, assignment, "empty key; expected dotted.key=value");
    components.emplace_back(component);
    if (dot == std::string_view::npos) return components;
    begin = dot + 1;
  }
}

// The value as TOML, or else as the bare text, so `time.integrator=rk4` needs no quotes. Text
// that opens like an array, table or quoted string was meant as TOML, so a typo in it is an
// error rather than a string. Parsed under the --set source name so messages about the value
// say where it came from.
toml::table override_value(const Origin& origin, const std::string& assignment,
                           std::string_view text) {
  try {
    auto parsed = toml::parse(fmt::format("value = {}", text), std::string(kSetSource));
    if (parsed.size() == 1 && parsed.contains("value")) return parsed;
  } catch (const toml::parse_error& error) {
    if (!text.empty() && std::string_view("[{\"'").find(text.front()) != std::string_view::npos) {
      bad_override(origin, assignment, fmt::format("not a TOML value: {}", error.description()));
    }
  }
  toml::table bare;
  bare.insert("value", std::string(text));
  return bare;
}

}  // namespace

void apply_override(toml::table& document, const std::string& assignment, const Origin& origin) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos) bad_override(origin, assignment, "expected dotted.key=value");
  const auto components =
      dotted_components(origin, assignment, std::string_view(assignment).substr(0, equals));

  toml::table* table = &document;
  std::string prefix;
  for (std::size_t i = 0; i + 1 < components.size(); ++i) {
    prefix += (i == 0 ? "" : ".") + components[i];
    toml::node* node = table->get(components[i]);
    if (node == nullptr) node = &table->insert(components[i], toml::table{}).first->second;
    table = node->as_table();
    if (table == nullptr) {
      bad_override(origin, assignment,
                   fmt::format("'{}' is {}, not a table", prefix, describe(*node)));
    }
  }
  auto value =
      override_value(origin, assignment, trim(std::string_view(assignment).substr(equals + 1)));
  table->insert_or_assign(components.back(), std::move(*value.get("value")));
}

}  // namespace cosserat::scene_detail
