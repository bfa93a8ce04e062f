// What the tests of whole suites through the built `mpmvv` share
// (suite_tests.cpp, fault_catalogue.cpp): scratch directories, files, shell
// commands.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

namespace mpmvv::suite_testing {

namespace fs = std::filesystem;

inline const std::string kScenes = std::string(MPMVV_SOURCE_DIR) + "/suites/scenes";

// An empty directory of this test process.
inline fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("mpmvv-suite-tests-" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

inline fs::path write(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

inline std::string read(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The command's exit status, its output discarded; -1 when a signal ended it.
inline int shell(const std::string& command) {
  const int status = std::system((command + " > /dev/null 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The cases of a manifest (its text) whose status is `status`; -1 where the
// text is no manifest.
inline int cases_with_status(const std::string& manifest, const std::string& status) {
  const nlohmann::json j = nlohmann::json::parse(manifest, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || !j.contains("cases") || !j["cases"].is_array()) return -1;
  int n = 0;
  for (const nlohmann::json& c : j["cases"]) n += c.is_object() && c.value("status", "") == status;
  return n;
}

}  // namespace mpmvv::suite_testing
