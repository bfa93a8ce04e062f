// A suite file's TOML read as scene values: where a node sits in its file,
// its value as a configuration value (config.hpp), and the checks every table
// of a suite makes of its keys (suites/README.md).
#pragma once

#include <initializer_list>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "tools/app/config.hpp"
#include "tools/app/json.hpp"

namespace mpmvv::app::suite_file {

// "file:line" of a node, for messages.
std::string where_in(const std::string& file, const toml::node& n);

// A TOML value as a configuration value, or nothing for a type no key takes.
std::optional<Value> to_value(const toml::node& n);

// Numbers compare by value (1 equals 1.0); other values by equality.
bool same_value(const Value& a, const Value& b);

// The value as a part of a case id (no spaces, no slashes).
std::string id_part(const Value& v);

// The text of a row's key values, "cells=300, amplitude=1", for messages.
std::string row_text(const std::vector<std::string>& columns, const std::vector<Value>& values);

// A ConfigError naming the first key of `table` not in `allowed`.
void expect_only(const toml::table& table, std::initializer_list<const char*> allowed, const std::string& file,
                 const std::string& what);

const toml::table& table_at(const toml::node& n, const std::string& file, const std::string& what);

struct Setting {
  std::string key;
  Value value;
  std::string origin;  // file:line
};

// key = value pairs of a table in the file's order, each checked to name a key of the scene.
std::vector<Setting> settings_of(const toml::table& table, const std::string& file, const std::vector<KeySpec>& specs,
                                 const std::string& scene, const std::string& what);

// Lists of a sweep or zip table: key -> values, each value with its origin.
struct Axis {
  std::string key;
  std::vector<Value> values;
  std::string origin;
};

// A sweep list names each value once; a zip list may repeat a value when the
// zipped tuples differ (solver = ["explicit", "explicit", "implicit"] beside
// dilatation = ["particle", "cell-averaged", "particle"]); each tuple once.
std::vector<Axis> axes_of(const toml::table& table, const std::string& file, const std::vector<KeySpec>& specs,
                          const std::string& scene, const std::string& what);

// The first floating-point value in `node` (a table, an array or a value)
// that is not finite, which JSON cannot hold (toml++ writes it as a string).
const toml::node* non_finite(const toml::node& node);

}  // namespace mpmvv::app::suite_file
