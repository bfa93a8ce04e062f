#include "toml_values.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace mpmvv::app::suite_file {

std::string where_in(const std::string& file, const toml::node& n) {
  return fmt::format("{}:{}", file, n.source().begin.line);
}

std::optional<Value> to_value(const toml::node& n) {
  if (n.is_integer()) return Value(n.as_integer()->get());
  if (n.is_floating_point()) return Value(n.as_floating_point()->get());
  if (n.is_string()) return Value(n.as_string()->get());
  if (n.is_array()) {
    std::vector<double> list;
    for (const toml::node& item : *n.as_array()) {
      if (item.is_integer()) list.push_back(double(item.as_integer()->get()));
      else if (item.is_floating_point()) list.push_back(item.as_floating_point()->get());
      else return std::nullopt;
    }
    return Value(list);
  }
  return std::nullopt;
}

bool same_value(const Value& a, const Value& b) {
  auto number = [](const Value& v) -> std::optional<double> {
    if (const auto* i = std::get_if<std::int64_t>(&v)) return double(*i);
    if (const auto* d = std::get_if<double>(&v)) return *d;
    return std::nullopt;
  };
  if (number(a) && number(b)) return *number(a) == *number(b);
  return a == b;
}

std::string id_part(const Value& v) {
  std::string s = as_setting(v);
  std::replace(s.begin(), s.end(), ' ', '_');
  std::replace(s.begin(), s.end(), '/', '_');
  return s;
}

std::string row_text(const std::vector<std::string>& columns, const std::vector<Value>& values) {
  std::string text;
  for (std::size_t i = 0; i < columns.size(); ++i) text += (i ? ", " : "") + columns[i] + "=" + as_setting(values[i]);
  return text.empty() ? "(every case)" : text;
}

namespace {

// The entries of a table in the order the file gives them (toml++ keeps keys sorted).
std::vector<std::pair<std::string, const toml::node*>> in_file_order(const toml::table& table) {
  std::vector<std::pair<std::string, const toml::node*>> entries;
  for (const auto& [k, node] : table) entries.emplace_back(std::string(k.str()), &node);
  std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    const auto& pa = a.second->source().begin;
    const auto& pb = b.second->source().begin;
    return pa.line != pb.line ? pa.line < pb.line : pa.column < pb.column;
  });
  return entries;
}

void require_key(const std::vector<KeySpec>& specs, const std::string& key, const toml::node& node,
                 const std::string& file, const std::string& scene, const std::string& what) {
  if (std::none_of(specs.begin(), specs.end(), [&](const KeySpec& s) { return s.name == key; }))
    throw ConfigError(fmt::format("{}: {}: unknown key '{}' for scene '{}' (mpmvv scenes lists them)",
                                  where_in(file, node), what, key, scene));
}

}  // namespace

void expect_only(const toml::table& table, std::initializer_list<const char*> allowed, const std::string& file,
                 const std::string& what) {
  for (const auto& [k, node] : table) {
    bool known = false;
    for (const char* a : allowed) known = known || k.str() == a;
    if (!known) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      throw ConfigError(fmt::format("{}: unknown key '{}' in {} (known: {})", where_in(file, node), k.str(), what, list));
    }
  }
}

const toml::table& table_at(const toml::node& n, const std::string& file, const std::string& what) {
  if (!n.is_table()) throw ConfigError(fmt::format("{}: '{}' must be a table", where_in(file, n), what));
  return *n.as_table();
}

std::vector<Setting> settings_of(const toml::table& table, const std::string& file, const std::vector<KeySpec>& specs,
                                 const std::string& scene, const std::string& what) {
  std::vector<Setting> out;
  for (const auto& [key, node_pointer] : in_file_order(table)) {
    const toml::node& node = *node_pointer;
    require_key(specs, key, node, file, scene, what);
    const std::optional<Value> v = to_value(node);
    if (!v) throw ConfigError(fmt::format("{}: {}: key '{}' has a value of an unsupported type", where_in(file, node), what, key));
    out.push_back({key, *v, where_in(file, node)});
  }
  return out;
}

std::vector<Axis> axes_of(const toml::table& table, const std::string& file, const std::vector<KeySpec>& specs,
                          const std::string& scene, const std::string& what) {
  std::vector<Axis> axes;
  for (const auto& [key, node_pointer] : in_file_order(table)) {
    const toml::node& node = *node_pointer;
    require_key(specs, key, node, file, scene, what);
    if (!node.is_array() || node.as_array()->empty())
      throw ConfigError(fmt::format("{}: {}: '{}' must be a non-empty list of values", where_in(file, node), what, key));
    Axis axis{key, {}, where_in(file, node)};
    for (const toml::node& item : *node.as_array()) {
      const std::optional<Value> v = to_value(item);
      if (!v) throw ConfigError(fmt::format("{}: {}: '{}' holds a value of an unsupported type", where_in(file, node), what, key));
      if (what == "sweep")
        for (const Value& seen : axis.values)
          if (same_value(seen, *v))
            throw ConfigError(fmt::format("{}: {}: '{}' lists {} twice", where_in(file, node), what, key, format_value(*v)));
      axis.values.push_back(*v);
    }
    axes.push_back(std::move(axis));
  }
  return axes;
}

const toml::node* non_finite(const toml::node& node) {
  if (const toml::table* t = node.as_table()) {
    for (const auto& [k, v] : *t)
      if (const toml::node* n = non_finite(v)) return n;
  } else if (const toml::array* a = node.as_array()) {
    for (const toml::node& v : *a)
      if (const toml::node* n = non_finite(v)) return n;
  } else if (const auto* f = node.as_floating_point()) {
    if (!std::isfinite(f->get())) return &node;
  }
  return nullptr;
}

}  // namespace mpmvv::app::suite_file
