#include "config.hpp"
#include "toml_file.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>

namespace mpmvv::app {

namespace {

const char* kind_name(KeyKind k) {
  switch (k) {
    case KeyKind::integer: return "an integer";
    case KeyKind::real: return "a number";
    case KeyKind::text: return "a string";
    case KeyKind::real_list: return "a list of numbers";
  }
  return "?";
}

std::string number(double x) { return fmt::format("{:g}", x); }

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::optional<double> parse_real(const std::string& text) {
  const std::string t = trim(text);
  if (t.empty()) return std::nullopt;
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec != std::errc() || ptr != t.data() + t.size()) return std::nullopt;
  return v;
}

std::optional<std::int64_t> parse_integer(const std::string& text) {
  const std::string t = trim(text);
  if (t.empty()) return std::nullopt;
  std::int64_t v = 0;
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec != std::errc() || ptr != t.data() + t.size()) return std::nullopt;
  return v;
}

}  // namespace

std::string KeySpec::describe_range() const {
  if (kind == KeyKind::text) {
    if (choices.empty()) return "a string";
    std::string s = "one of";
    for (std::size_t i = 0; i < choices.size(); ++i) s += (i ? ", " : " ") + choices[i];
    return s;
  }
  std::string what = kind == KeyKind::real_list ? "a list of numbers, each" : kind_name(kind);
  const bool has_min = std::isfinite(min), has_max = std::isfinite(max);
  if (has_min && has_max)
    return fmt::format("{} in {}{}, {}{}", what, min_exclusive ? "(" : "[", number(min), number(max),
                       max_exclusive ? ")" : "]");
  if (has_min) return fmt::format("{} {} {}", what, min_exclusive ? ">" : ">=", number(min));
  if (has_max) return fmt::format("{} {} {}", what, max_exclusive ? "<" : "<=", number(max));
  return what;
}

// The shortest text that reads back as the same double, with a decimal point
// so that TOML and JSON readers see a real number (1.0, not 1).
std::string real_text(double x) {
  std::string s = fmt::format("{}", x);
  if (std::isfinite(x) && s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

namespace {

// A string as a TOML basic string, escaped by toml++ (quotes, backslashes,
// control and non-ASCII characters), so that the text reads back as the same
// string. Numbers are written above rather than by toml++, which gives a
// double seventeen digits (0.1 as 0.10000000000000001): the shortest text is
// the one a person wrote in the scene file.
std::string toml_string(const std::string& x) {
  std::ostringstream s;
  s << toml::toml_formatter{toml::value<std::string>(x), toml::format_flags::none};
  return s.str();
}

}  // namespace

std::string format_value(const Value& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::int64_t>) return std::to_string(x);
        else if constexpr (std::is_same_v<T, double>) return real_text(x);
        else if constexpr (std::is_same_v<T, std::string>) return toml_string(x);
        else {
          std::string s = "[";
          for (std::size_t i = 0; i < x.size(); ++i) s += (i ? ", " : "") + real_text(x[i]);
          return s + "]";
        }
      },
      v);
}

std::string as_setting(const Value& v) {
  if (const auto* s = std::get_if<std::string>(&v)) return *s;
  return format_value(v);
}

Config::Config(std::string scene, std::vector<KeySpec> specs) : scene_(std::move(scene)), specs_(std::move(specs)) {
  for (const KeySpec& s : specs_) {
    values_[s.name] = s.default_value;
    origins_[s.name] = Origin{"default"};
  }
}

const KeySpec& Config::spec(const std::string& key) const {
  for (const KeySpec& s : specs_)
    if (s.name == key) return s;
  std::string known;
  for (const KeySpec& s : specs_) known += (known.empty() ? "" : ", ") + s.name;
  throw ConfigError(fmt::format("unknown key '{}' for scene '{}' (known keys: {})", key, scene_, known));
}

void Config::reject(const std::string& key, const std::string& why) const {
  const auto it = origins_.find(key);
  const std::string where = it == origins_.end() ? "" : it->second.source + ": ";
  throw ConfigError(fmt::format("{}key '{}': {}", where, key, why));
}

void Config::set(const std::string& key, Value value, Origin origin) {
  const KeySpec& s = spec(key);
  auto bad = [&](const std::string& got) {
    throw ConfigError(fmt::format("{}: key '{}' must be {}, got {}", origin.source, key, s.describe_range(), got));
  };
  auto in_range = [&](double x) {
    if (!std::isfinite(x)) return false;
    if (s.min_exclusive ? !(x > s.min) : !(x >= s.min)) return false;
    if (s.max_exclusive ? !(x < s.max) : !(x <= s.max)) return false;
    return true;
  };
  switch (s.kind) {
    case KeyKind::integer: {
      if (!std::holds_alternative<std::int64_t>(value)) bad(format_value(value));
      if (!in_range(double(std::get<std::int64_t>(value)))) bad(format_value(value));
      break;
    }
    case KeyKind::real: {
      if (std::holds_alternative<std::int64_t>(value)) value = double(std::get<std::int64_t>(value));
      if (!std::holds_alternative<double>(value)) bad(format_value(value));
      if (!in_range(std::get<double>(value))) bad(format_value(value));
      break;
    }
    case KeyKind::text: {
      if (!std::holds_alternative<std::string>(value)) bad(format_value(value));
      const std::string& t = std::get<std::string>(value);
      if (!s.choices.empty() && std::find(s.choices.begin(), s.choices.end(), t) == s.choices.end())
        bad(format_value(value));
      break;
    }
    case KeyKind::real_list: {
      if (std::holds_alternative<double>(value)) value = std::vector<double>{std::get<double>(value)};
      if (std::holds_alternative<std::int64_t>(value)) value = std::vector<double>{double(std::get<std::int64_t>(value))};
      if (!std::holds_alternative<std::vector<double>>(value)) bad(format_value(value));
      const auto& list = std::get<std::vector<double>>(value);
      if (list.empty()) bad("an empty list");
      for (double x : list)
        if (!in_range(x)) bad(format_value(value));
      break;
    }
  }
  values_[key] = std::move(value);
  origins_[key] = std::move(origin);
}

void Config::set_from_text(const std::string& assignment, const std::string& how) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError(fmt::format("{} {}: expected key=value", how, assignment));
  const std::string key = trim(assignment.substr(0, eq));
  const std::string text = trim(assignment.substr(eq + 1));
  const KeySpec* found = nullptr;
  try {
    found = &spec(key);
  } catch (const ConfigError& e) {
    throw ConfigError(fmt::format("{} {}: {}", how, assignment, e.what()));
  }
  const KeySpec& s = *found;
  const Origin origin{how + " " + assignment};
  auto bad = [&]() {
    throw ConfigError(fmt::format("{} {}: key '{}' must be {}", how, assignment, key, s.describe_range()));
  };
  switch (s.kind) {
    case KeyKind::integer: {
      const auto v = parse_integer(text);
      if (!v) bad();
      set(key, *v, origin);
      break;
    }
    case KeyKind::real: {
      const auto v = parse_real(text);
      if (!v) bad();
      set(key, *v, origin);
      break;
    }
    case KeyKind::text: set(key, text, origin); break;
    case KeyKind::real_list: {
      std::string body = text;
      if (!body.empty() && body.front() == '[' && body.back() == ']') body = body.substr(1, body.size() - 2);
      std::vector<double> list;
      std::stringstream ss(body);
      std::string item;
      while (std::getline(ss, item, ',')) {
        const auto v = parse_real(item);
        if (!v) bad();
        list.push_back(*v);
      }
      set(key, list, origin);
      break;
    }
  }
}

const Value& Config::value(const std::string& key) const {
  spec(key);
  return values_.at(key);
}

bool Config::has(const std::string& key) const {
  return std::any_of(specs_.begin(), specs_.end(), [&key](const KeySpec& s) { return s.name == key; });
}

const Origin& Config::origin(const std::string& key) const {
  spec(key);
  return origins_.at(key);
}

std::int64_t Config::integer(const std::string& key) const { return std::get<std::int64_t>(value(key)); }
double Config::real(const std::string& key) const { return std::get<double>(value(key)); }
const std::string& Config::text(const std::string& key) const { return std::get<std::string>(value(key)); }
const std::vector<double>& Config::reals(const std::string& key) const {
  return std::get<std::vector<double>>(value(key));
}

std::string Config::to_toml() const {
  std::string out = fmt::format("scene = {}\n", toml_string(scene_));
  for (const KeySpec& s : specs_) out += fmt::format("{} = {}\n", s.name, format_value(values_.at(s.name)));
  return out;
}

Config load_scene_file(const std::string& path,
                       const std::function<std::optional<std::vector<KeySpec>>(const std::string&)>& specs_for_scene,
                       const std::vector<std::string>& overrides) {
  const toml::table table = parse_toml_file(path, "scene file");
  auto where = [&](const toml::node& n) { return fmt::format("{}:{}", path, n.source().begin.line); };

  const toml::node* scene_node = table.get("scene");
  if (!scene_node)
    throw ConfigError(fmt::format("{}: missing key 'scene' (the name of the scene, a string such as \"ring\")", path));
  if (!scene_node->is_string())
    throw ConfigError(fmt::format("{}: 'scene' must be the name of a scene, a string such as \"ring\"",
                                  where(*scene_node)));
  const std::string scene = scene_node->as_string()->get();
  const auto specs = specs_for_scene(scene);
  if (!specs) throw ConfigError(fmt::format("{}: key 'scene': unknown scene '{}'", where(*scene_node), scene));
  Config config(scene, *specs);

  for (const auto& [k, node] : table) {
    const std::string key(k.str());
    if (key == "scene") continue;
    const Origin origin{where(node)};
    bool known = false;
    for (const KeySpec& s : *specs) known = known || s.name == key;
    if (!known) {
      std::string list;
      for (const KeySpec& s : *specs) list += (list.empty() ? "" : ", ") + s.name;
      throw ConfigError(fmt::format("{}: unknown key '{}' for scene '{}' (known keys: {})", origin.source, key,
                                    scene, list));
    }
    Value v;
    if (node.is_integer()) v = node.as_integer()->get();
    else if (node.is_floating_point()) v = node.as_floating_point()->get();
    else if (node.is_string()) v = node.as_string()->get();
    else if (node.is_array()) {
      std::vector<double> list;
      for (const toml::node& item : *node.as_array()) {
        if (item.is_integer()) list.push_back(double(item.as_integer()->get()));
        else if (item.is_floating_point()) list.push_back(item.as_floating_point()->get());
        else throw ConfigError(fmt::format("{}: key '{}': list entries must be numbers", origin.source, key));
      }
      v = list;
    } else {
      throw ConfigError(fmt::format("{}: key '{}': unsupported value type", origin.source, key));
    }
    config.set(key, std::move(v), origin);
  }
  for (const std::string& o : overrides) config.set_from_text(o);
  return config;
}

}  // namespace mpmvv::app
