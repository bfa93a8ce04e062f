// What a suite run leaves in its directory (suites/README.md): each case's
// results file, log and state file (cases/<id>.json), and manifest.json, which
// gathers every case's state with the suite's expectations for the gate and
// the report. A results file already on disk counts as a finished case only
// when it was made with the configuration the case asks for now.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "suite.hpp"
#include "tools/app/json.hpp"

namespace mpmvv::app::suite_file {

// The files of a suite's output directory.
struct SuiteDirectory {
  std::filesystem::path root;
  std::filesystem::path cases() const { return root / "cases"; }
  std::filesystem::path results(const SuiteCase& c) const { return cases() / (c.id + ".h5"); }
  std::filesystem::path state(const SuiteCase& c) const { return cases() / (c.id + ".json"); }
  std::filesystem::path log(const SuiteCase& c) const { return cases() / (c.id + ".log"); }
  std::filesystem::path manifest() const { return root / "manifest.json"; }
  // As the manifest names it, relative to the root.
  static std::string relative_results(const SuiteCase& c) { return "cases/" + c.id + ".h5"; }
};

// What happened to a case: "pending", "running", the status its results file
// records ("completed", "failed", "lost"), or what the runner saw ("crashed",
// "timeout", "error").
struct CaseState {
  std::string status = "pending";
  int exit_code = -1;
  double wall = 0.0;
  std::string detail;
};

// Member `key` of object j where it holds a T, else `fallback`.
template <class T>
T member(const Json& j, const char* key, T fallback) {
  if (!j.is_object()) return fallback;
  const auto at = j.find(key);
  if (at == j.end()) return fallback;
  if constexpr (std::is_same_v<T, std::string>) {
    if (at->is_string()) return at->template get<std::string>();
  } else {
    if (at->is_number()) return at->template get<T>();
  }
  return fallback;
}

// Written whole under a partial name, then renamed over `path`: a full disk
// leaves the file as it was (io::write_file throws, naming the reason).
void write_atomically(const std::filesystem::path& path, const std::string& text);

std::string read_text(const std::filesystem::path& path);

// A file's JSON, or null where it is missing or does not parse (a case file
// cut short by a full disk).
Json read_json(const std::filesystem::path& path);

// Writes the case's state file.
void record_case(const SuiteDirectory& dir, const SuiteCase& c, const CaseState& s);

// Writes manifest.json from every case's state file (a case without one is
// pending), so that each rank's cases are in it.
void write_manifest(const SuiteDirectory& dir, const Suite& suite);

// What a results file says of its run, or nothing when it is not a finished
// results file of this case's configuration (made with another, interrupted,
// damaged, from before the health verdict, or made with a deliberate fault
// other than the one asked for now).
std::optional<CaseState> finished_state(const std::filesystem::path& results, const SuiteCase& c);

// The first error column at the last output time, for the summary.
std::string headline_error(const std::filesystem::path& results);

}  // namespace mpmvv::app::suite_file
