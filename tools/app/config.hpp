// Scene configuration: every key a scene accepts is declared once with its kind,
// range, default and meaning. A scene file and `--set key=value` overrides are
// checked against those declarations before anything runs; a mistake is one
// ConfigError naming the file, line and key.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace mpmvv::app {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class KeyKind { integer, real, text, real_list };

using Value = std::variant<std::int64_t, double, std::string, std::vector<double>>;

struct KeySpec {
  std::string name;
  KeyKind kind;
  Value default_value;
  std::string help;
  double min = -std::numeric_limits<double>::infinity();  // integer and real, and list entries
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;
  bool max_exclusive = false;
  std::vector<std::string> choices;  // text: the allowed values, if restricted

  std::string describe_range() const;
};

// Where a value came from, for messages.
struct Origin {
  std::string source;  // "ring.toml:12" or "--set"
};

class Config {
 public:
  Config(std::string scene, std::vector<KeySpec> specs);

  const std::string& scene() const { return scene_; }
  const std::vector<KeySpec>& specs() const { return specs_; }

  std::int64_t integer(const std::string& key) const;
  double real(const std::string& key) const;
  const std::string& text(const std::string& key) const;
  const std::vector<double>& reals(const std::string& key) const;
  const Value& value(const std::string& key) const;
  const Origin& origin(const std::string& key) const;
  // Whether the scene declares the key.
  bool has(const std::string& key) const;

  // Checks `value` against the key's declaration and stores it.
  void set(const std::string& key, Value value, Origin origin);
  // Parses the text of a `--set key=value` argument; `how` names where it came
  // from in a message ("--set" on the command line, "setting" in the C library).
  void set_from_text(const std::string& assignment, const std::string& how = "--set");

  // The resolved configuration as TOML text (all keys, in declaration order).
  std::string to_toml() const;
  // A ConfigError naming the key and where its value came from.
  [[noreturn]] void reject(const std::string& key, const std::string& why) const;

 private:
  const KeySpec& spec(const std::string& key) const;
  std::string scene_;
  std::vector<KeySpec> specs_;
  std::map<std::string, Value> values_;
  std::map<std::string, Origin> origins_;
};

std::string format_value(const Value& v);
// The value as `mpmvv run --set` reads it: text as it stands, the rest as format_value.
std::string as_setting(const Value& v);

// Reads a scene file. `specs_for_scene` returns the declarations of the scene
// named by the file's `scene` key, or nothing when there is no such scene.
Config load_scene_file(const std::string& path,
                       const std::function<std::optional<std::vector<KeySpec>>(const std::string&)>& specs_for_scene,
                       const std::vector<std::string>& overrides);

}  // namespace mpmvv::app
