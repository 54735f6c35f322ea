// How --set arguments become values of the document. Values parsed from an argument carry the
// source name "--set" rather than the scene's path, which is how Origin tells them apart.

#include "overrides.hpp"

#include <fmt/format.h>

#include <optional>
#include <string>
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

// One component of a dotted key: a key, or `key[i]`, element i of the array there.
struct Component {
  std::string key;
  std::optional<std::size_t> index;
  std::string text;  // as given, for messages
};

Component component_of(const Origin& origin, const std::string& assignment, std::string_view text) {
  Component component{std::string(text), std::nullopt, std::string(text)};
  const auto open = text.find('[');
  if (open == std::string_view::npos) return component;
  const auto digits = text.substr(open + 1, text.size() - open - 2);
  if (open == 0 || text.back() != ']' || digits.empty() ||
      digits.find_first_not_of("0123456789") != std::string_view::npos || digits.size() > 9) {
    bad_override(origin, assignment,
                 fmt::format("'{}' is not a key or key[index] with a whole number", text));
  }
  component.key = std::string(trim(text.substr(0, open)));
  component.index = std::stoul(std::string(digits));
  return component;
}

std::vector<Component> dotted_components(const Origin& origin, const std::string& assignment,
                                         std::string_view key) {
  std::vector<Component> components;
  std::size_t begin = 0;
  while (true) {
    const auto dot = key.find('.', begin);
    const auto component =
        trim(key.substr(begin, dot == std::string_view::npos ? dot : dot - begin));
    if (component.empty()) bad_override(origin, assignment, "empty key; expected dotted.key=value");
    components.push_back(component_of(origin, assignment, component));
    if (dot == std::string_view::npos) return components;
    begin = dot + 1;
  }
}

// The array at `component.key` in `table`, which must be there with element `component.index`:
// an override changes a [[block]] of the file (`solid[0].friction=0`, as messages name its
// keys) but adds or removes none, so what is simulated stays what the file lists.
toml::array& array_with_element(toml::table& table, const Component& component,
                                const std::string& prefix, const Origin& origin,
                                const std::string& assignment) {
  toml::node* node = table.get(component.key);
  toml::array* array = node == nullptr ? nullptr : node->as_array();
  if (array == nullptr) {
    bad_override(origin, assignment,
                 node == nullptr
                     ? fmt::format("'{}' names an element of '{}', which the scene does not have",
                                   prefix, component.key)
                     : fmt::format("'{}' names an element of '{}', which is {}, not an array",
                                   prefix, component.key, describe(*node)));
  }
  if (*component.index >= array->size()) {
    bad_override(origin, assignment,
                 fmt::format("'{}' is past the end: '{}' has {} element{}", prefix, component.key,
                             array->size(), array->size() == 1 ? "" : "s"));
  }
  return *array;
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
    const Component& component = components[i];
    prefix += (i == 0 ? "" : ".") + component.text;
    toml::node* node = component.index
                           ? array_with_element(*table, component, prefix, origin, assignment)
                                 .get(*component.index)
                           : table->get(component.key);
    if (node == nullptr) node = &table->insert(component.key, toml::table{}).first->second;
    table = node->as_table();
    if (table == nullptr) {
      bad_override(origin, assignment,
                   fmt::format("'{}' is {}, not a table", prefix, describe(*node)));
    }
  }
  auto value =
      override_value(origin, assignment, trim(std::string_view(assignment).substr(equals + 1)));
  const Component& last = components.back();
  if (last.index) {
    prefix += (components.size() == 1 ? "" : ".") + last.text;
    auto& array = array_with_element(*table, last, prefix, origin, assignment);
    array.replace(array.cbegin() + static_cast<std::ptrdiff_t>(*last.index),
                  std::move(*value.get("value")));
    return;
  }
  table->insert_or_assign(last.key, std::move(*value.get("value")));
}

}  // namespace cosserat::scene_detail
