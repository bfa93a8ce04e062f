// Reading a suite file whole before anything runs (STYLE.md principle 7): its
// own keys, each [[study]] expanded into cases, its expectations and its
// references.
#include <cmath>
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

namespace {

// The suite's [ci] table: `covers`, what its ci tier checks that no other
// tier does (suites/README.md's table says it for every suite), or `skip`,
// why the suite has no ci tier. Asking a skipped suite for its ci tier
// throws SuiteSkipped with that reason.
void read_ci_table(const toml::table& top, const std::string& path, Suite& suite) {
  const toml::node* node = top.get("ci");
  if (!node) return;
  const toml::table& ci = table_at(*node, path, "ci");
  expect_only(ci, {"covers", "skip"}, path, "[ci]");
  for (const auto& [key, value] : ci) {
    if (!value.is_string() || value.as_string()->get().empty())
      throw ConfigError(fmt::format("{}: [ci] '{}' must be a sentence (a string)", where_in(path, value), key.str()));
    (key.str() == "covers" ? suite.ci_covers : suite.ci_skip) = value.as_string()->get();
  }
  if (suite.ci_covers.empty() && suite.ci_skip.empty())
    throw ConfigError(fmt::format("{}: [ci] gives neither 'covers' nor 'skip': say what the ci tier checks that no "
                                  "other tier does, or why the suite has none",
                                  where_in(path, *node)));
  if (!suite.ci_covers.empty() && !suite.ci_skip.empty())
    throw ConfigError(fmt::format("{}: [ci] gives both 'covers' and 'skip': a suite has a ci tier or says why not",
                                  where_in(path, *node)));
  if (suite.tier == kCiTier && !suite.ci_skip.empty())
    throw SuiteSkipped(fmt::format("{}: no ci tier: {}", path, suite.ci_skip));
}

}  // namespace

Suite load_suite(const std::string& path, const std::string& tier) {
  if (tier != kFullTier && tier != kCiTier)
    throw ConfigError(fmt::format("--tier {}: a suite has the tiers '{}' and '{}'", tier, kFullTier, kCiTier));
  std::string text = read_regular_file(path, "suite file");
  const toml::table top = parse_toml_text(text, path);
  expect_only(top, {"description", "timeout", "checkpoint_every", "ci", "study", "expect", "reference"}, path,
              "the suite");
  Suite suite;
  suite.file = path;
  suite.text = std::move(text);
  suite.name = fs::path(path).stem().string();
  suite.tier = tier;
  read_ci_table(top, path, suite);
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
    if (!(seconds > 0.0) || !std::isfinite(seconds))
      throw ConfigError(fmt::format("{}: '{}' must be a positive, finite number of seconds", where_in(path, *t), key));
  };
  seconds_of("timeout", suite.timeout_seconds);
  seconds_of("checkpoint_every", suite.checkpoint_seconds);
  const toml::node* studies_node = top.get("study");
  if (!studies_node || !studies_node->is_array_of_tables() || studies_node->as_array()->empty())
    throw ConfigError(fmt::format("{}: a suite needs at least one [[study]]", path));

  std::map<std::string, Study> studies;
  for (const toml::node& node : *studies_node->as_array()) studies.insert(expand_study(node, path, studies, suite));
  if (suite.cases.empty())  // only the ci tier can leave every study out
    throw ConfigError(fmt::format("{}: no study has a ci tier (a `ci` table: `ci = {{}}` runs the study as it is "
                                  "there, `ci = {{ sweep = {{ cells = [16, 32] }} }}` on fewer levels)",
                                  path));
  read_expectations(top, path, studies, suite);
  // Published numbers sit beside the full study's levels; the ci tier's
  // report leaves them out (the full tier's load checks them).
  if (tier == kFullTier) check_references(top, path, studies, suite);
  return suite;
}

}  // namespace mpmvv::app
