// A TOML file parsed whole, or a ConfigError naming the file, line and
// column of its syntax error (scene files and suite files alike).
#pragma once

#include <string>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "config.hpp"

namespace mpmvv::app {

inline toml::table parse_toml_file(const std::string& path) {
  try {
    return toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw ConfigError(fmt::format("{}:{}:{}: TOML syntax error: {}", path, e.source().begin.line,
                                  e.source().begin.column, e.description()));
  }
}

}  // namespace mpmvv::app
