#pragma once
// TOML as the scene loader reads it: every value keeps its full dotted key and where it came
// from, so that any rejection is one SceneError line naming the file, the line (or "(from
// --set)"), the key and what is allowed. The section readers then state only what they accept.
// Private to src/scene.

#include <toml++/toml.h>

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cosserat/model/material.hpp"
#include "cosserat/grid/vec3.hpp"

namespace cosserat::scene_detail {

// What a user wrote, for "got ..." in messages.
std::string describe(const toml::node& node);

// The file messages point into. Values whose source is not that file came from --set.
class Origin {
 public:
  explicit Origin(std::string path) : path_(std::move(path)) {}

  const std::string& path() const { return path_; }

  // "file:line", "file (from --set)", or "file" when there is no node to point at.
  std::string locate(const toml::node* node) const;

  [[noreturn]] void fail(const toml::node* node, std::string_view key, std::string_view what) const;

 private:
  std::string path_;
};

// The document in `text`; a syntax error is reported at its file, line and column.
toml::table parse_toml(const std::string& text, const Origin& origin);

class Table;

// One value of the scene with its full dotted key; the typed readers reject anything else.
class Entry {
 public:
  Entry(const Origin& origin, const toml::node& node, std::string key)
      : origin_(&origin), node_(&node), key_(std::move(key)) {}

  [[noreturn]] void fail(std::string_view what) const { origin_->fail(node_, key_, what); }

  const std::string& key() const { return key_; }
  // "file:line", or "file (from --set)": for a warning about this value.
  std::string where() const { return origin_->locate(node_); }

  // Integers are accepted where numbers are expected; inf and nan never are.
  double number() const;
  long integer() const;
  std::string string() const;
  bool boolean() const;

  // The elements of an array of `size` entries (any size when 0); `what` names the expected form.
  std::vector<Entry> elements(std::size_t size, std::string_view what) const;

  Vec3 vector3() const;

  // A material tensor: one number (isotropic) or [t11, t12, t22].
  Sym2 tensor() const;

  bool is_table() const { return node_->is_table(); }
  Table table() const;

  // The blocks of a [[block]] array, keyed block[0], block[1], ...
  std::vector<Table> tables(std::string_view block) const;

 private:
  const Origin* origin_;
  const toml::node* node_;
  std::string key_;
};

// One TOML table with its dotted key ("" for the top level).
class Table {
 public:
  Table(const Origin& origin, const toml::table& table, std::string key, bool top_level = false)
      : origin_(&origin), table_(&table), key_(std::move(key)), top_level_(top_level) {}

  std::string key_of(std::string_view name) const;

  // Rejects the first key not in `allowed`: a typo must not silently become a default.
  void allow(std::initializer_list<std::string_view> allowed) const;

  // The keys given, in TOML's (sorted) order: for readers whose allowed keys depend on other
  // keys, and which say why a known key does not belong.
  std::vector<std::string> keys() const;

  std::optional<Entry> find(std::string_view name) const;
  std::optional<Table> find_table(std::string_view name) const;

  // `what` says what the missing key should hold.
  [[noreturn]] void missing(std::string_view name, std::string_view what) const;

  Entry require(std::string_view name, std::string_view what) const;
  Table require_table(std::string_view name, std::string_view what) const;

  [[noreturn]] void fail(std::string_view what) const { origin_->fail(locator(), key_, what); }

 private:
  // The top-level table has no useful line, so messages about it name the file only.
  const toml::node* locator() const { return top_level_ ? nullptr : table_; }

  const Origin* origin_;
  const toml::table* table_;
  std::string key_;
  bool top_level_;
};

double positive(const Entry& entry);
double non_negative(const Entry& entry);
long integer_at_least(const Entry& entry, long lowest);

}  // namespace cosserat::scene_detail
