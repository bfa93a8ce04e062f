// Reading a suite file whole before anything runs (STYLE.md principle 7): its
// own keys, each [[study]] expanded into cases, its expectations and its
// references.
#include <filesystem>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "expectations.hpp"
#include "references.hpp"
#include "study.hpp"
#include "suite.hpp"
#include "toml_values.hpp"
#include "tools/app/toml_file.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;
using namespace suite_file;

Suite load_suite(const std::string& path) {
  if (!fs::exists(path)) throw ConfigError(fmt::format("{}: no such suite file", path));
  const toml::table top = parse_toml_file(path);
  expect_only(top, {"description", "timeout", "checkpoint_every", "study", "expect", "reference"}, path, "the suite");
  Suite suite;
  suite.file = path;
  suite.name = fs::path(path).stem().string();
  if (const toml::node* d = top.get("description")) {
    if (!d->is_string()) throw ConfigError(fmt::format("{}: 'description' must be a string", where_in(path, *d)));
    suite.description = d->as_string()->get();
  }
  // A key of seconds: a positive number, when given.
  auto seconds_of = [&](const char* key, double& seconds) {
    const toml::node* t = top.get(key);
    if (!t) return;
    const std::optional<Value> v = to_value(*t);
    seconds = v && std::holds_alternative<std::int64_t>(*v) ? double(std::get<std::int64_t>(*v))
              : v && std::holds_alternative<double>(*v)     ? std::get<double>(*v)
                                                            : -1.0;
    if (!(seconds > 0.0))
      throw ConfigError(fmt::format("{}: '{}' must be a positive number of seconds", where_in(path, *t), key));
  };
  seconds_of("timeout", suite.timeout_seconds);
  seconds_of("checkpoint_every", suite.checkpoint_seconds);
  const toml::node* studies_node = top.get("study");
  if (!studies_node || !studies_node->is_array_of_tables() || studies_node->as_array()->empty())
    throw ConfigError(fmt::format("{}: a suite needs at least one [[study]]", path));

  std::map<std::string, Study> studies;
  for (const toml::node& node : *studies_node->as_array()) studies.insert(expand_study(node, path, studies, suite));
  read_expectations(top, path, studies, suite);
  check_references(top, path, studies, suite);
  return suite;
}

}  // namespace mpmvv::app
