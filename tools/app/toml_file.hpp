// A TOML file parsed whole, or a ConfigError naming the file, line and
// column of its syntax error (scene files and suite files alike). Only a
// regular file is read: a FIFO would block, a device or directory is no
// file, and a symlink loop is refused at once with what it is.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "config.hpp"

namespace mpmvv::app {

// The whole text of `path`, a regular file (what= names it: "scene file").
inline std::string read_regular_file(const std::string& path, const char* what) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory)
    throw ConfigError(fmt::format("{}: cannot read this {}: {}", path, what, ec.message()));
  if (!std::filesystem::exists(status)) throw ConfigError(fmt::format("{}: no such {}", path, what));
  if (!std::filesystem::is_regular_file(status))
    throw ConfigError(fmt::format("{}: not a regular file (a FIFO, device or folder is no {})", path, what));
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw ConfigError(fmt::format("{}: cannot read this {}", path, what));
  return text.str();
}

inline toml::table parse_toml_text(const std::string& text, const std::string& path) {
  try {
    return toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    throw ConfigError(fmt::format("{}:{}:{}: TOML syntax error: {}", path, e.source().begin.line,
                                  e.source().begin.column, e.description()));
  }
}

inline toml::table parse_toml_file(const std::string& path, const char* what) {
  return parse_toml_text(read_regular_file(path, what), path);
}

}  // namespace mpmvv::app
