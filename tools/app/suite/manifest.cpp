#include "manifest.hpp"

#include <ctime>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "solver/io/hdf5.hpp"
#include "solver/io/write_file.hpp"
#include "solver/time_loop.hpp"
#include "tools/app/config.hpp"
#include "tools/app/fault.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;

namespace {

// A resolved configuration's keys (Config::to_toml), or nothing where the
// text is no TOML.
std::optional<toml::table> configuration_table(const std::string& text) {
  try {
    return toml::parse(text);
  } catch (const toml::parse_error&) {
    return std::nullopt;
  }
}

}  // namespace

// Key by key, by value (toml++'s equality: 0.5 however it was written), so
// that a change in how values are written never runs a finished case again.
bool same_configuration(const std::string& stored, const std::string& wanted, const std::string& defaults,
                        std::vector<std::string>* added) {
  if (stored == wanted) return true;
  const auto old_keys = configuration_table(stored);
  const auto new_keys = configuration_table(wanted);
  const auto default_keys = configuration_table(defaults);
  if (!old_keys || !new_keys || !default_keys) return false;
  std::vector<std::string> missing;
  for (const auto& [key, value] : *old_keys)
    if (!new_keys->contains(key.str()) || toml::node_view(value) != (*new_keys)[key.str()]) return false;
  for (const auto& [key, value] : *new_keys) {
    if (old_keys->contains(key.str())) continue;
    if (!default_keys->contains(key.str()) || toml::node_view(value) != (*default_keys)[key.str()]) return false;
    missing.push_back(std::string(key.str()));
  }
  if (added) *added = missing;
  return true;
}

namespace suite_file {

namespace {

Json case_json(const SuiteCase& c, const CaseState& s, const std::string& results) {
  Json keys = Json::object();
  for (const auto& [k, v] : c.keys) keys[k] = v;
  return {{"id", c.id},
          {"study", c.study},
          {"scene", c.scene_file},
          {"keys", std::move(keys)},
          {"overrides", c.overrides},
          {"results", results},
          {"status", s.status},
          {"exit_code", s.exit_code},
          {"wall_time_s", s.wall},
          {"detail", s.detail}};
}

}  // namespace

void write_atomically(const fs::path& path, const std::string& text) {
  const fs::path partial = path.string() + ".partial";
  io::write_file(partial.string(), text);
  std::error_code ec;
  fs::rename(partial, path, ec);
  if (ec) throw std::runtime_error("cannot rename " + partial.string() + " to " + path.filename().string() + ": " + ec.message());
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Json read_json(const fs::path& path) {
  if (!fs::exists(path)) return nullptr;
  return Json::parse(read_text(path), nullptr, /*allow_exceptions=*/false);
}

void record_case(const SuiteDirectory& dir, const SuiteCase& c, const CaseState& s) {
  write_atomically(dir.state(c), json_text(case_json(c, s, SuiteDirectory::relative_results(c))) + "\n");
}

void write_manifest(const SuiteDirectory& dir, const Suite& suite) {
  Json cases = Json::array();
  for (const SuiteCase& c : suite.cases) {
    Json object = read_json(dir.state(c));
    if (!object.is_object()) object = case_json(c, CaseState{}, SuiteDirectory::relative_results(c));
    cases.push_back(std::move(object));
  }
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  const Json head = {{"suite", suite.name},
                     {"suite_file", suite.file},
                     {"suite_text", suite.text},
                     {"tier", suite.tier},
                     {"description", suite.description},
                     {"written", stamp},
                     {"expectations", suite.expectations}};
  // Each value written by nlohmann, a case a line, so that a manifest of
  // hundreds of cases reads (and greps) case by case.
  std::string text = "{";
  for (const auto& [key, value] : head.items()) text += json_text(key) + ": " + json_text(value) + ", ";
  text += "\"cases\": [";
  for (std::size_t i = 0; i < cases.size(); ++i) text += (i ? ",\n  " : "\n  ") + json_text(cases[i]);
  write_atomically(dir.manifest(), text + "\n]}\n");
}

std::optional<CaseState> finished_state(const fs::path& results, const SuiteCase& c) {
  if (!fs::exists(results)) return std::nullopt;
  try {
    const h5::File f = h5::File::open_read(results.string());
    const h5::Group root = f.root();
    std::vector<std::string> added;
    if (!same_configuration(root.attribute_string("configuration"), c.configuration, c.defaults, &added))
      return std::nullopt;
    // A file made with a deliberate fault other than the one asked for now
    // (tools/app/fault.hpp; none, outside a fault-injection test) is not this
    // case's result, and a file without its error table is damaged: both run
    // again.
    const std::string fault = root.has_attribute("fault_injected") ? root.attribute_string("fault_injected") : "";
    Fault now;
    try {
      now = injected_fault(results.string());
    } catch (const ConfigError&) {
      return std::nullopt;
    }
    if (fault != to_string(now) || !root.has("errors")) return std::nullopt;
    CaseState s;
    s.status = root.attribute_string("status");
    if (s.status == kInterrupted) return std::nullopt;  // stopped by a signal before its end: run it again
    // A run written before the health verdict (tools/app/scene/health.hpp) could
    // read "completed" with its solution lost: it runs again to be judged.
    if (!root.has_attribute("health")) return std::nullopt;
    s.exit_code = s.status == "completed" ? 0 : 1;
    s.wall = root.attribute_double("wall_time_s");
    if (s.status != "completed")
      s.detail = fmt::format("{} at t = {:.4g} s", root.attribute_string("failure_reason"), root.attribute_double("failure_time"));
    if (!added.empty())
      s.detail += fmt::format("{}written before {} existed (at {} now)", s.detail.empty() ? "" : "; ",
                              fmt::join(added, ", "), added.size() == 1 ? "its default" : "their defaults");
    return s;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::string headline_error(const fs::path& results) {
  try {
    const h5::File f = h5::File::open_read(results.string());
    const h5::Group errors = f.root().open_group("errors");
    for (const std::string& name : errors.members()) {
      if (name == "time") continue;
      const std::vector<double> v = errors.read_doubles(name);
      if (v.empty()) return "";
      return fmt::format("{} {:.3e}", name, v.back());
    }
  } catch (const std::exception&) {
  }
  return "";
}

}  // namespace suite_file

}  // namespace mpmvv::app
