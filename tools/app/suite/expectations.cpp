#include "expectations.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "toml_values.hpp"

namespace mpmvv::app::suite_file {

namespace {

// Below this fraction of its largest over the output times, the exact signal
// an expectation reads measures little: a run without the motion would score
// nearly the same there (reports/gate.py: TRIVIAL_SIGNAL, the same rule after
// the run).
constexpr double kTrivialSignal = 0.05;

// A warning when expectation `e` reads its norm where the exact signal is
// trivial, judged on the first case of its study (the levels of a study share
// the motion).
void warn_of_a_trivial_read(const toml::table& e, const std::string& here, const SceneCase& scene,
                            std::vector<std::string>& warnings) {
  const std::string norm = e.get("norm")->as_string()->get();
  const double time = e.get("time") ? e.get("time")->value<double>().value_or(0.0) : std::numeric_limits<double>::quiet_NaN();
  const std::optional<double> fraction = scene.exact_signal_fraction(norm, time);
  if (fraction && *fraction < kTrivialSignal)
    warnings.push_back(fmt::format(
        "{}: [[expect]] reads {} {} where the exact signal is {:.3g} % of its largest over the output times: a run "
        "without the motion would score nearly the same; read it where the motion is large",
        here, norm, std::isnan(time) ? std::string("at the end time") : fmt::format("at t = {:g}", time),
        100.0 * *fraction));
}

// Whether expectation `e` applies in `tier`: its `tier` names a tier or
// lists them ("full", "ci"); an expectation without one is the full study's.
bool in_tier(const toml::table& e, const std::string& path, const std::string& tier) {
  const toml::node* t = e.get("tier");
  if (!t) return tier == kFullTier;
  std::vector<std::string> tiers;
  if (t->is_string()) tiers.push_back(t->as_string()->get());
  if (t->is_array())
    for (const toml::node& n : *t->as_array())
      if (n.is_string()) tiers.push_back(n.as_string()->get());
  const bool well_formed = !tiers.empty() && (t->is_string() || tiers.size() == t->as_array()->size()) &&
                           std::all_of(tiers.begin(), tiers.end(), [](const std::string& s) { return s == kFullTier || s == kCiTier; });
  if (!well_formed)
    throw ConfigError(fmt::format("{}: [[expect]]: 'tier' must be \"{}\", \"{}\" or a list of them", where_in(path, *t),
                                  kFullTier, kCiTier));
  return std::find(tiers.begin(), tiers.end(), tier) != tiers.end();
}

// The keys an order is observed against, each setting a size the gate fits
// ln E against (reports/series.py: REFINED_SIZES, and cells for h).
constexpr const char* kSizeKeys[] = {"cells", "particles_per_direction", "cfl", "load_steps"};

// Whether case `c` has every key value of `where` (numbers by value).
bool matches(const SuiteCase& c, const std::vector<Setting>& where) {
  return std::all_of(where.begin(), where.end(), [&](const Setting& w) {
    const auto key = c.keys.find(w.key);
    if (key == c.keys.end()) return false;
    const Json wanted = json_of(w.value);
    if (key->second.is_number() && wanted.is_number()) return key->second.get<double>() == wanted.get<double>();
    return key->second == wanted;
  });
}

// The norm must be a column some case it reads writes, and its time (when
// given) an output time of every such case: each, wrong, is found only after
// every case ran otherwise.
void check_norm_and_time(const toml::table& e, const std::string& path, const std::string& study,
                         const std::vector<const SuiteCase*>& matched) {
  const toml::node& norm_node = *e.get("norm");
  const std::string norm = norm_node.as_string()->get();
  std::vector<std::string> columns;
  for (const SuiteCase* c : matched)
    for (const std::string& column : c->error_columns)
      if (std::find(columns.begin(), columns.end(), column) == columns.end()) columns.push_back(column);
  if (!columns.empty() && std::find(columns.begin(), columns.end(), norm) == columns.end())
    throw ConfigError(fmt::format("{}: [[expect]]: study '{}' writes no /errors column '{}'; its columns: {}",
                                  where_in(path, norm_node), study, norm, fmt::join(columns, ", ")));
  const toml::node* t = e.get("time");
  if (!t) return;
  const double time = t->value<double>().value_or(-1.0);
  for (const SuiteCase* c : matched) {
    const auto outputs = c->keys.find("output_times");
    if (outputs == c->keys.end() || !outputs->second.is_array()) continue;
    // (An output time after the end time is dropped: the run ends first.)
    const auto end = c->keys.find("end_time");
    if (end != c->keys.end() && end->second.is_number() && time > end->second.get<double>() * (1.0 + 1e-9))
      throw ConfigError(fmt::format("{}: [[expect]]: t = {} is after the end time {} of case '{}'",
                                    where_in(path, *t), time, end->second.get<double>(), c->id));
    // The case's output times as the run takes them: those before the end
    // time, and the end time itself (scene.cpp).
    std::vector<double> taken;
    const double end_time = end != c->keys.end() && end->second.is_number() ? end->second.get<double>() : NAN;
    for (const Json& o : outputs->second)
      if (o.is_number() && !(o.get<double>() >= end_time)) taken.push_back(o.get<double>());
    if (std::isfinite(end_time)) taken.push_back(end_time);
    const bool output = std::any_of(taken.begin(), taken.end(), [&](double o) {
      return std::abs(o - time) <= 1e-9 * std::max(1.0, std::abs(time));
    });
    if (!output)
      throw ConfigError(fmt::format("{}: [[expect]]: t = {} is not an output time of case '{}' (its output times: {})",
                                    where_in(path, *t), time, c->id, fmt::join(taken, ", ")));
  }
}

}  // namespace

void read_expectations(const toml::table& top, const std::string& path, const std::map<std::string, Study>& studies,
                       Suite& suite) {
  // Expectations name a study, keys of its scene and levels it has.
  const toml::node* expects = top.get("expect");
  if (!expects) return;
  if (!expects->is_array_of_tables()) throw ConfigError(fmt::format("{}: 'expect' must be [[expect]] tables", where_in(path, *expects)));
  for (const toml::node& node : *expects->as_array()) {
    const toml::table& e = *node.as_table();
    const std::string here = where_in(path, node);
    expect_only(e, {"study", "where", "norm", "time", "refine", "levels", "order", "tolerance", "max_error_constant",
                    "max_error", "at_roundoff", "must_complete", "interval_within_band", "tier"},
                path, "[[expect]]");
    if (!in_tier(e, path, suite.tier)) continue;
    const toml::node* study = e.get("study");
    if (!study || !study->is_string()) throw ConfigError(fmt::format("{}: [[expect]] needs the study it checks", here));
    const std::string name = study->as_string()->get();
    if (!studies.count(name)) throw ConfigError(fmt::format("{}: [[expect]]: no study named '{}'", where_in(path, *study), name));
    if (!studies.at(name).in_tier)
      throw ConfigError(fmt::format("{}: [[expect]] applies in the {} tier, where study '{}' does not run (give the "
                                    "study a `ci` table)",
                                    here, suite.tier, name));
    const std::vector<KeySpec>& specs = studies.at(name).keys;
    auto is_key = [&](const std::string& k) {
      return std::any_of(specs.begin(), specs.end(), [&](const KeySpec& s) { return s.name == k; });
    };
    std::vector<Setting> where;
    if (const toml::node* w = e.get("where")) where = settings_of(table_at(*w, path, "where"), path, specs, name, "[[expect]] where");
    // The cases it reads, in the tier loaded: none is a typo the gate would
    // find only after every case ran.
    std::vector<const SuiteCase*> matched;
    for (const SuiteCase& c : suite.cases)
      if (c.study == name && matches(c, where)) matched.push_back(&c);
    if (matched.empty()) {
      std::vector<std::string> keys;
      std::vector<Value> values;
      for (const Setting& w : where) keys.push_back(w.key), values.push_back(w.value);
      throw ConfigError(fmt::format("{}: [[expect]]: where {} matches no case of study '{}'{}", here,
                                    row_text(keys, values), name, suite.tier == kCiTier ? " in the ci tier" : ""));
    }
    const toml::node* norm = e.get("norm");
    if (!norm || !norm->is_string()) throw ConfigError(fmt::format("{}: [[expect]] needs a norm (an /errors column, e.g. \"L1_theta0\")", here));
    check_norm_and_time(e, path, name, matched);
    // An order with its band, or a bound on the error itself (exact-solution
    // scenes whose error sits at round-off or settling level), or both; or
    // errors at round-off (a patch test: the method reproduces the motion).
    const toml::node* max_error = e.get("max_error");
    if (max_error && !(max_error->value<double>().value_or(-1.0) > 0.0))
      throw ConfigError(fmt::format("{}: [[expect]]: 'max_error' must be a positive number", where_in(path, *max_error)));
    for (const char* k : {"must_complete", "interval_within_band", "at_roundoff"})
      if (const toml::node* m = e.get(k); m && !m->is_boolean())
        throw ConfigError(fmt::format("{}: [[expect]]: '{}' must be true or false", where_in(path, *m), k));
    const bool at_roundoff = e.get("at_roundoff") && e.get("at_roundoff")->value<bool>().value_or(false);
    if (at_roundoff && (e.get("order") || e.get("tolerance")))
      throw ConfigError(fmt::format("{}: [[expect]]: 'at_roundoff' asks for errors at round-off, where no order can be "
                                    "observed: give it without 'order' and 'tolerance'", here));
    if ((!max_error && !at_roundoff) || e.get("order") || e.get("tolerance")) {
      for (const char* k : {"order", "tolerance"}) {
        const toml::node* n = e.get(k);
        if (!n || !(n->is_integer() || n->is_floating_point()))
          throw ConfigError(fmt::format("{}: [[expect]] needs '{}' (a number){}", here, k,
                                        max_error ? "" : ", or 'max_error' or 'at_roundoff = true' alone"));
      }
      if (const toml::node* t = e.get("tolerance"); !(t->value<double>().value_or(-1.0) > 0.0))
        throw ConfigError(fmt::format("{}: [[expect]]: 'tolerance' must be positive", where_in(path, *t)));
    }
    if (e.get("max_error_constant") && !e.get("order"))
      throw ConfigError(fmt::format("{}: [[expect]]: 'max_error_constant' needs an 'order'", here));
    if (const toml::node* m = e.get("max_error_constant"); m && !(m->value<double>().value_or(-1.0) > 0.0))
      throw ConfigError(fmt::format("{}: [[expect]]: 'max_error_constant' must be a positive number", where_in(path, *m)));
    if (const toml::node* t = e.get("time"); t && !(t->value<double>().value_or(-1.0) >= 0.0))
      throw ConfigError(fmt::format("{}: [[expect]]: 'time' must be a time >= 0", where_in(path, *t)));
    if (e.get("interval_within_band") && !e.get("order"))
      throw ConfigError(fmt::format("{}: [[expect]]: 'interval_within_band' needs an 'order'", here));
    std::string refine = "cells";
    if (const toml::node* r = e.get("refine")) {
      if (!r->is_string() || !is_key(r->as_string()->get()))
        throw ConfigError(fmt::format("{}: [[expect]]: 'refine' must name a key of study '{}'", where_in(path, *r), name));
      refine = r->as_string()->get();
      if (std::find(std::begin(kSizeKeys), std::end(kSizeKeys), refine) == std::end(kSizeKeys))
        throw ConfigError(fmt::format("{}: [[expect]]: 'refine' = \"{}\" sets no size an order is observed against; "
                                      "refine one of {}",
                                      where_in(path, *r), refine, fmt::join(kSizeKeys, ", ")));
    }
    warn_of_a_trivial_read(e, here, *studies.at(name).first, suite.warnings);
    if (const toml::node* l = e.get("levels")) {
      const std::optional<Value> v = to_value(*l);
      if (!v || !std::holds_alternative<std::vector<double>>(*v) || std::get<std::vector<double>>(*v).size() < 2)
        throw ConfigError(fmt::format("{}: [[expect]]: 'levels' must list two or more values of '{}'", where_in(path, *l), refine));
      for (double level : std::get<std::vector<double>>(*v)) {
        const bool present = std::any_of(suite.cases.begin(), suite.cases.end(), [&](const SuiteCase& c) {
          const auto key = c.keys.find(refine);
          return c.study == name && key != c.keys.end() && key->second.is_number() &&
                 std::abs(key->second.get<double>() - level) < 1e-12 * std::max(1.0, std::abs(level));
        });
        if (!present)
          throw ConfigError(fmt::format("{}: [[expect]]: study '{}' has no case with {} = {}", where_in(path, *l), name, refine, level));
      }
    }
    // Checked: as the manifest records it for the gate and the report,
    // which read it there and check nothing of it again.
    if (const toml::node* bad = non_finite(e))
      throw ConfigError(fmt::format("{}: [[expect]] holds a value that is not a finite number (nan or inf)",
                                    where_in(path, *bad)));
    std::ostringstream as_json;
    as_json << toml::json_formatter{e};
    suite.expectations.push_back(Json::parse(as_json.str()));
  }
}

}  // namespace mpmvv::app::suite_file
