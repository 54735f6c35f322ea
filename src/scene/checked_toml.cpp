// The typed readers of checked_toml.hpp. Each rejection goes through Origin::fail, so that every
// message about a value has the shape "file:line: key 'a.b': what is allowed".

#include "checked_toml.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cosserat/scene/scene.hpp"

namespace cosserat::scene_detail {

std::string describe(const toml::node& node) {
  if (const auto* text = node.as_string()) return fmt::format("the string \"{}\"", text->get());
  if (const auto* integer = node.as_integer()) return fmt::format("the integer {}", integer->get());
  if (const auto* real = node.as_floating_point()) return fmt::format("the number {}", real->get());
  if (const auto* boolean = node.as_boolean()) return fmt::format("the boolean {}", boolean->get());
  if (const auto* array = node.as_array()) {
    return fmt::format("an array of {} entries", array->size());
  }
  if (node.is_table()) return "a table";
  return "a date or time";
}

std::string Origin::locate(const toml::node* node) const {
  if (node == nullptr) return path_;
  const auto& source = node->source();
  if (!source.path || *source.path != path_) return path_ + " (from --set)";
  return fmt::format("{}:{}", path_, source.begin.line);
}

void Origin::fail(const toml::node* node, std::string_view key, std::string_view what) const {
  throw SceneError(fmt::format("{}: key '{}': {}", locate(node), key, what));
}

// toml++ parses a dotted key by recursion and runs out of stack somewhere past 30 000 parts; no
// scene key has more than four. Keys are what stands before '=' or inside a [header].
constexpr int kMostKeyParts = 64;

void refuse_absurd_nesting(const std::string& text, const Origin& origin) {
  std::size_t line_start = 0;
  for (int line = 1; line_start <= text.size(); ++line) {
    const std::size_t line_end = std::min(text.find('\n', line_start), text.size());
    std::string_view content(text.data() + line_start, line_end - line_start);
    content.remove_prefix(std::min(content.find_first_not_of(" \t"), content.size()));
    // A [header] up to its ']' (a line of an array of numbers has commas), or the key of a
    // key = value line; comments and lines that continue a value have none.
    std::string_view key;
    if (content.starts_with('#'))
      key = {};
    else if (content.starts_with('['))
      key = content.substr(0, content.find(']'));
    else if (const auto equals = content.find('='); equals != std::string_view::npos)
      key = content.substr(0, equals);
    if (key.find(',') != std::string_view::npos) key = {};
    const auto parts = std::count(key.begin(), key.end(), '.') + 1;
    if (parts > kMostKeyParts)
      throw SceneError(fmt::format("{}:{}: a key of {} dotted parts; scene keys have at most {}",
                                   origin.path(), line, parts, kMostKeyParts));
    line_start = line_end + 1;
  }
}

toml::table parse_toml(const std::string& text, const Origin& origin) {
  refuse_absurd_nesting(text, origin);
  try {
    return toml::parse(text, origin.path());
  } catch (const toml::parse_error& error) {
    throw SceneError(fmt::format("{}:{}:{}: not valid TOML: {}", origin.path(),
                                 error.source().begin.line, error.source().begin.column,
                                 error.description()));
  }
}

double Entry::number() const {
  double value = 0.0;
  if (const auto* integer = node_->as_integer()) {
    value = static_cast<double>(integer->get());
  } else if (const auto* real = node_->as_floating_point()) {
    value = real->get();
  } else {
    fail(fmt::format("must be a number, got {}", describe(*node_)));
  }
  if (!std::isfinite(value)) fail(fmt::format("must be a finite number, got {}", value));
  return value;
}

long Entry::integer() const {
  const auto* integer = node_->as_integer();
  if (integer == nullptr) fail(fmt::format("must be an integer, got {}", describe(*node_)));
  return integer->get();
}

std::string Entry::string() const {
  const auto* text = node_->as_string();
  if (text == nullptr) fail(fmt::format("must be a string, got {}", describe(*node_)));
  return text->get();
}

bool Entry::boolean() const {
  const auto* flag = node_->as_boolean();
  if (flag == nullptr) fail(fmt::format("must be true or false, got {}", describe(*node_)));
  return flag->get();
}

std::vector<Entry> Entry::elements(std::size_t size, std::string_view what) const {
  const auto* array = node_->as_array();
  if (array == nullptr || (size != 0 && array->size() != size)) {
    fail(fmt::format("must be {}, got {}", what, describe(*node_)));
  }
  std::vector<Entry> entries;
  for (std::size_t i = 0; i < array->size(); ++i) {
    entries.emplace_back(*origin_, (*array)[i], fmt::format("{}[{}]", key_, i));
  }
  return entries;
}

Vec3 Entry::vector3() const {
  const auto entries = elements(3, "an array of 3 numbers [x, y, z]");
  return {entries[0].number(), entries[1].number(), entries[2].number()};
}

Sym2 Entry::tensor() const {
  if (node_->is_number()) {
    const double value = number();
    return {value, value, value};
  }
  if (!node_->is_array()) {
    fail(fmt::format("must be a number or an array of 3 numbers [t11, t12, t22], got {}",
                     describe(*node_)));
  }
  const auto entries = elements(3, "a number or an array of 3 numbers [t11, t12, t22]");
  return {entries[0].number(), entries[1].number(), entries[2].number()};
}

Table Entry::table() const {
  const auto* table = node_->as_table();
  if (table == nullptr) fail(fmt::format("must be a table, got {}", describe(*node_)));
  return Table(*origin_, *table, key_);
}

std::vector<Table> Entry::tables(std::string_view block) const {
  if (!node_->is_array_of_tables()) {
    fail(
        fmt::format("must be [[{}]] blocks (an array of tables), got {}", block, describe(*node_)));
  }
  std::vector<Table> blocks;
  for (const auto& element : elements(0, "")) blocks.push_back(element.table());
  return blocks;
}

std::string Table::key_of(std::string_view name) const {
  return key_.empty() ? std::string(name) : fmt::format("{}.{}", key_, name);
}

void Table::allow(std::initializer_list<std::string_view> allowed) const {
  for (auto&& [name, node] : *table_) {
    if (std::find(allowed.begin(), allowed.end(), name.str()) == allowed.end()) {
      Entry(*origin_, node, key_of(name.str()))
          .fail(fmt::format("unknown key; allowed here: {}", fmt::join(allowed, ", ")));
    }
  }
}

std::vector<std::string> Table::keys() const {
  std::vector<std::string> names;
  for (auto&& [name, node] : *table_) names.emplace_back(name.str());
  return names;
}

std::optional<Entry> Table::find(std::string_view name) const {
  const auto* node = table_->get(name);
  if (node == nullptr) return std::nullopt;
  return Entry(*origin_, *node, key_of(name));
}

std::optional<Table> Table::find_table(std::string_view name) const {
  if (const auto entry = find(name)) return entry->table();
  return std::nullopt;
}

void Table::missing(std::string_view name, std::string_view what) const {
  origin_->fail(locator(), key_of(name), fmt::format("required: {}", what));
}

Entry Table::require(std::string_view name, std::string_view what) const {
  if (auto entry = find(name)) return *entry;
  missing(name, what);
}

Table Table::require_table(std::string_view name, std::string_view what) const {
  if (auto table = find_table(name)) return *table;
  missing(name, what);
}

double positive(const Entry& entry) {
  const double value = entry.number();
  if (!(value > 0.0)) entry.fail(fmt::format("must be > 0, got {}", value));
  return value;
}

double non_negative(const Entry& entry) {
  const double value = entry.number();
  if (!(value >= 0.0)) entry.fail(fmt::format("must be >= 0, got {}", value));
  return value;
}

long integer_at_least(const Entry& entry, long lowest) {
  const long value = entry.integer();
  if (value < lowest) entry.fail(fmt::format("must be >= {}, got {}", lowest, value));
  return value;
}

}  // namespace cosserat::scene_detail
