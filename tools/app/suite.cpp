#include "suite.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <toml++/toml.h>

#ifdef MPMVV_HAVE_MPI
// The C API only; OpenMPI's header would pull in its deprecated C++ bindings.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

#include "config.hpp"
#include "fault.hpp"
#include "solver/io/write_file.hpp"
#include "scene.hpp"
#include "solver/io/hdf5.hpp"
#include "solver/time_loop.hpp"

extern char** environ;

namespace mpmvv::app {

namespace fs = std::filesystem;

namespace {

// ------------------------------------------------------------------ reading the suite

std::string where_in(const std::string& file, const toml::node& n) {
  return fmt::format("{}:{}", file, n.source().begin.line);
}

// A TOML value as a configuration value, or nothing for a type no key takes.
std::optional<Value> to_value(const toml::node& n) {
  if (n.is_integer()) return Value(n.as_integer()->get());
  if (n.is_floating_point()) return Value(n.as_floating_point()->get());
  if (n.is_string()) return Value(n.as_string()->get());
  if (n.is_array()) {
    std::vector<double> list;
    for (const toml::node& item : *n.as_array()) {
      if (item.is_integer()) list.push_back(double(item.as_integer()->get()));
      else if (item.is_floating_point()) list.push_back(item.as_floating_point()->get());
      else return std::nullopt;
    }
    return Value(list);
  }
  return std::nullopt;
}

// The value as `mpmvv run --set` reads it.
std::string as_setting(const Value& v) {
  if (const auto* s = std::get_if<std::string>(&v)) return *s;
  return format_value(v);
}

bool same_value(const Value& a, const Value& b) {
  auto number = [](const Value& v) -> std::optional<double> {
    if (const auto* i = std::get_if<std::int64_t>(&v)) return double(*i);
    if (const auto* d = std::get_if<double>(&v)) return *d;
    return std::nullopt;
  };
  if (number(a) && number(b)) return *number(a) == *number(b);
  return a == b;
}

// The entries of a table in the order the file gives them (toml++ keeps keys sorted).
std::vector<std::pair<std::string, const toml::node*>> in_file_order(const toml::table& table) {
  std::vector<std::pair<std::string, const toml::node*>> entries;
  for (const auto& [k, node] : table) entries.emplace_back(std::string(k.str()), &node);
  std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    const auto& pa = a.second->source().begin;
    const auto& pb = b.second->source().begin;
    return pa.line != pb.line ? pa.line < pb.line : pa.column < pb.column;
  });
  return entries;
}

void expect_only(const toml::table& table, std::initializer_list<const char*> allowed, const std::string& file,
                 const std::string& what) {
  for (const auto& [k, node] : table) {
    bool known = false;
    for (const char* a : allowed) known = known || k.str() == a;
    if (!known) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      throw ConfigError(fmt::format("{}: unknown key '{}' in {} (known: {})", where_in(file, node), k.str(), what, list));
    }
  }
}

const toml::table& table_at(const toml::node& n, const std::string& file, const std::string& what) {
  if (!n.is_table()) throw ConfigError(fmt::format("{}: '{}' must be a table", where_in(file, n), what));
  return *n.as_table();
}

struct Setting {
  std::string key;
  Value value;
  std::string origin;  // file:line
};

// key = value pairs of a table, each checked to name a key of the scene.
std::vector<Setting> settings_of(const toml::table& table, const std::string& file, const std::vector<KeySpec>& specs,
                                 const std::string& scene, const std::string& what) {
  std::vector<Setting> out;
  for (const auto& [key, node_pointer] : in_file_order(table)) {
    const toml::node& node = *node_pointer;
    const bool known = std::any_of(specs.begin(), specs.end(), [&](const KeySpec& s) { return s.name == key; });
    if (!known)
      throw ConfigError(fmt::format("{}: {}: unknown key '{}' for scene '{}' (mpmvv scenes lists them)",
                                    where_in(file, node), what, key, scene));
    const std::optional<Value> v = to_value(node);
    if (!v) throw ConfigError(fmt::format("{}: {}: key '{}' has a value of an unsupported type", where_in(file, node), what, key));
    out.push_back({key, *v, where_in(file, node)});
  }
  return out;
}

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
                          const std::string& scene, const std::string& what) {
  std::vector<Axis> axes;
  for (const auto& [key, node_pointer] : in_file_order(table)) {
    const toml::node& node = *node_pointer;
    const bool known = std::any_of(specs.begin(), specs.end(), [&](const KeySpec& s) { return s.name == key; });
    if (!known)
      throw ConfigError(fmt::format("{}: {}: unknown key '{}' for scene '{}'", where_in(file, node), what, key, scene));
    if (!node.is_array() || node.as_array()->empty())
      throw ConfigError(fmt::format("{}: {}: '{}' must be a non-empty list of values", where_in(file, node), what, key));
    Axis axis{key, {}, where_in(file, node)};
    for (const toml::node& item : *node.as_array()) {
      const std::optional<Value> v = to_value(item);
      if (!v) throw ConfigError(fmt::format("{}: {}: '{}' holds a value of an unsupported type", where_in(file, node), what, key));
      if (what == "sweep")
        for (const Value& seen : axis.values)
          if (same_value(seen, *v))
            throw ConfigError(fmt::format("{}: {}: '{}' lists {} twice", where_in(file, node), what, key, format_value(*v)));
      axis.values.push_back(*v);
    }
    axes.push_back(std::move(axis));
  }
  return axes;
}

// The first floating-point value in `node` (a table, an array or a value)
// that is not finite, which JSON cannot hold (toml++ writes it as a string).
const toml::node* non_finite(const toml::node& node) {
  if (const toml::table* t = node.as_table()) {
    for (const auto& [k, v] : *t)
      if (const toml::node* n = non_finite(v)) return n;
  } else if (const toml::array* a = node.as_array()) {
    for (const toml::node& v : *a)
      if (const toml::node* n = non_finite(v)) return n;
  } else if (const auto* f = node.as_floating_point()) {
    if (!std::isfinite(f->get())) return &node;
  }
  return nullptr;
}

Json json_of(const Value& v) {
  return std::visit([](const auto& x) { return Json(x); }, v);
}

std::string id_part(const Value& v) {
  std::string s = as_setting(v);
  std::replace(s.begin(), s.end(), ' ', '_');
  std::replace(s.begin(), s.end(), '/', '_');
  return s;
}


// The text of a row's key values, "cells=300, amplitude=1", for messages.
std::string row_text(const std::vector<std::string>& columns, const std::vector<Value>& values) {
  std::string text;
  for (std::size_t i = 0; i < columns.size(); ++i) text += (i ? ", " : "") + columns[i] + "=" + as_setting(values[i]);
  return text.empty() ? "(every case)" : text;
}

// Whether case c has `value` for `key` (numbers compare by value: 1 equals 1.0).
bool case_has(const SuiteCase& c, const std::string& key, const Value& value) {
  const auto found = c.keys.find(key);
  if (found == c.keys.end()) return false;
  if (std::holds_alternative<std::int64_t>(value) || std::holds_alternative<double>(value)) {
    const double wanted = std::holds_alternative<double>(value) ? std::get<double>(value) : double(std::get<std::int64_t>(value));
    return found->second.is_number() && found->second.get<double>() == wanted;
  }
  return found->second == json_of(value);
}

// [[reference]] tables: published numbers the report sets beside the suite's
// own (suites/README.md), e.g. the time each run of another code reached, the
// error it reached, or the order it observed. They check nothing; the gate ignores them. Each names
// studies of the suite, keys of their scenes, and rows that match cases.
void check_references(const toml::table& top, const std::string& path,
                      const std::map<std::string, std::vector<KeySpec>>& study_keys, const Suite& suite) {
  const toml::node* references = top.get("reference");
  if (!references) return;
  if (!references->is_array_of_tables())
    throw ConfigError(fmt::format("{}: 'reference' must be [[reference]] tables", where_in(path, *references)));
  for (const toml::node& node : *references->as_array()) {
    const toml::table& r = *node.as_table();
    const std::string here = where_in(path, node);
    expect_only(r, {"source", "study", "quantity", "columns", "rows", "norm", "time"}, path, "[[reference]]");
    const toml::node* source = r.get("source");
    if (!source || !source->is_string() || source->as_string()->get().empty())
      throw ConfigError(fmt::format("{}: [[reference]] needs a source (a string: where its numbers come from)", here));

    std::vector<std::string> studies;
    const toml::node* study = r.get("study");
    if (study && study->is_string()) studies.push_back(study->as_string()->get());
    if (study && study->is_array())
      for (const toml::node& s : *study->as_array())
        if (s.is_string()) studies.push_back(s.as_string()->get());
    if (!study || studies.empty() || (study->is_array() && studies.size() != study->as_array()->size()))
      throw ConfigError(fmt::format("{}: [[reference]] needs 'study': a study name or a list of them", here));
    for (const std::string& s : studies)
      if (!study_keys.count(s)) throw ConfigError(fmt::format("{}: [[reference]]: no study named '{}'", where_in(path, *study), s));

    const toml::node* quantity = r.get("quantity");
    const std::string what = quantity && quantity->is_string() ? quantity->as_string()->get() : "";
    if (what != "time_reached" && what != "order" && what != "error")
      throw ConfigError(fmt::format("{}: [[reference]] needs 'quantity': \"time_reached\", \"error\" or \"order\"",
                                    quantity ? where_in(path, *quantity) : here));
    const toml::node* norm = r.get("norm");
    const toml::node* time = r.get("time");
    if (what != "time_reached" && (!norm || !norm->is_string()))
      throw ConfigError(fmt::format("{}: [[reference]]: an {} needs 'norm' (an /errors column)", here, what));
    if (what == "time_reached" && (norm || time))
      throw ConfigError(fmt::format("{}: [[reference]]: 'norm' and 'time' belong to an error or an order, not to "
                                    "time_reached", where_in(path, norm ? *norm : *time)));
    if (time && !(time->value<double>().value_or(-1.0) >= 0.0))
      throw ConfigError(fmt::format("{}: [[reference]]: 'time' must be a time >= 0", where_in(path, *time)));

    std::vector<std::string> columns;
    const toml::node* columns_node = r.get("columns");
    if (columns_node) {
      if (!columns_node->is_array())
        throw ConfigError(fmt::format("{}: [[reference]]: 'columns' must be a list of scene keys", where_in(path, *columns_node)));
      for (const toml::node& c : *columns_node->as_array()) {
        if (!c.is_string()) throw ConfigError(fmt::format("{}: [[reference]]: 'columns' must be a list of scene keys", where_in(path, c)));
        const std::string key = c.as_string()->get();
        if (std::find(columns.begin(), columns.end(), key) != columns.end())
          throw ConfigError(fmt::format("{}: [[reference]]: column '{}' is listed twice", where_in(path, c), key));
        for (const std::string& s : studies) {
          const std::vector<KeySpec>& specs = study_keys.at(s);
          if (!std::any_of(specs.begin(), specs.end(), [&](const KeySpec& k) { return k.name == key; }))
            throw ConfigError(fmt::format("{}: [[reference]]: column '{}' is not a key of study '{}'", where_in(path, c), key, s));
        }
        columns.push_back(key);
      }
    }
    const toml::node* rows = r.get("rows");
    if (!rows || !rows->is_array() || rows->as_array()->empty())
      throw ConfigError(fmt::format("{}: [[reference]] needs 'rows': a list of [key values..., {}]", here, what));
    for (const toml::node& row : *rows->as_array()) {
      const std::string at = where_in(path, row);
      if (!row.is_array() || row.as_array()->size() != columns.size() + 1)
        throw ConfigError(fmt::format("{}: [[reference]]: each row holds a value for each of the {} columns, then the {}",
                                      at, columns.size(), what));
      const toml::array& cells = *row.as_array();
      std::vector<Value> values;
      for (std::size_t i = 0; i < columns.size(); ++i) {
        const std::optional<Value> v = to_value(*cells.get(i));
        if (!v || std::holds_alternative<std::vector<double>>(*v))
          throw ConfigError(fmt::format("{}: [[reference]]: the value of '{}' must be a number or a string", at, columns[i]));
        values.push_back(*v);
      }
      const toml::node& last = *cells.get(columns.size());
      const double value = last.value<double>().value_or(std::nan(""));
      const bool non_negative = what != "order";
      if (!(last.is_integer() || last.is_floating_point()) || !std::isfinite(value) || (non_negative && value < 0.0))
        throw ConfigError(fmt::format("{}: [[reference]]: the last value of a row is the {}, a {}number", at, what,
                                      non_negative ? "non-negative " : ""));
      const bool matched = std::any_of(suite.cases.begin(), suite.cases.end(), [&](const SuiteCase& c) {
        if (std::find(studies.begin(), studies.end(), c.study) == studies.end()) return false;
        for (std::size_t i = 0; i < columns.size(); ++i)
          if (!case_has(c, columns[i], values[i])) return false;
        return true;
      });
      if (!matched)
        throw ConfigError(fmt::format("{}: [[reference]]: the row {} matches no case of {}", at, row_text(columns, values),
                                      studies.size() == 1 ? "study '" + studies.front() + "'" : "its studies"));
    }
  }
}

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

}  // namespace

Suite load_suite(const std::string& path) {
  if (!fs::exists(path)) throw ConfigError(fmt::format("{}: no such suite file", path));
  toml::table top;
  try {
    top = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw ConfigError(fmt::format("{}:{}:{}: TOML syntax error: {}", path, e.source().begin.line,
                                  e.source().begin.column, e.description()));
  }
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
  const toml::node* studies = top.get("study");
  if (!studies || !studies->is_array_of_tables() || studies->as_array()->empty())
    throw ConfigError(fmt::format("{}: a suite needs at least one [[study]]", path));

  const fs::path base = fs::path(path).parent_path();
  const std::regex name_pattern("[A-Za-z0-9_-]+");
  std::map<std::string, std::vector<KeySpec>> study_keys;
  std::map<std::string, std::unique_ptr<SceneCase>> first_of_study;  // built, for what is known before a run
  std::map<std::string, std::vector<const SuiteCase*>> study_cases;

  for (const toml::node& node : *studies->as_array()) {
    const toml::table& study = *node.as_table();
    const std::string here = where_in(path, node);
    expect_only(study, {"name", "scene", "set", "sweep", "zip", "override"}, path, "[[study]]");
    const toml::node* name_node = study.get("name");
    if (!name_node || !name_node->is_string())
      throw ConfigError(fmt::format("{}: [[study]] needs a name (a string)", here));
    const std::string name = name_node->as_string()->get();
    if (!std::regex_match(name, name_pattern))
      throw ConfigError(fmt::format("{}: study name '{}' may hold only letters, digits, '-' and '_'", where_in(path, *name_node), name));
    if (study_keys.count(name)) throw ConfigError(fmt::format("{}: a second study named '{}'", where_in(path, *name_node), name));
    const toml::node* scene_node = study.get("scene");
    if (!scene_node || !scene_node->is_string())
      throw ConfigError(fmt::format("{}: study '{}' needs a scene (a scene file, relative to the suite)", here, name));
    const std::string scene_file = (base / scene_node->as_string()->get()).lexically_normal().string();
    if (!fs::exists(scene_file))
      throw ConfigError(fmt::format("{}: study '{}': no such scene file {}", where_in(path, *scene_node), name, scene_file));

    // The scene's own file decides the scene type and its keys.
    Config scene_config("", {});
    try {
      scene_config = load_scene_file(
          scene_file,
          [](const std::string& n) -> std::optional<std::vector<KeySpec>> {
            const SceneType* t = find_scene_type(n);
            if (!t) return std::nullopt;
            return t->keys();
          },
          {});
    } catch (const ConfigError& e) {
      throw ConfigError(fmt::format("{}: study '{}': {}", where_in(path, *scene_node), name, e.what()));
    }
    const std::vector<KeySpec> specs = scene_config.specs();
    study_keys[name] = specs;

    std::vector<Setting> fixed;
    if (const toml::node* s = study.get("set")) fixed = settings_of(table_at(*s, path, "set"), path, specs, scene_config.scene(), "set");
    std::vector<Axis> sweep, zip;
    if (const toml::node* s = study.get("sweep")) sweep = axes_of(table_at(*s, path, "sweep"), path, specs, scene_config.scene(), "sweep");
    if (const toml::node* s = study.get("zip")) zip = axes_of(table_at(*s, path, "zip"), path, specs, scene_config.scene(), "zip");
    std::size_t zip_length = zip.empty() ? 1 : zip.front().values.size();
    for (const Axis& a : zip)
      if (a.values.size() != zip_length)
        throw ConfigError(fmt::format("{}: zip: '{}' has {} values but '{}' has {}: zipped lists must be equally long",
                                      a.origin, a.key, a.values.size(), zip.front().key, zip_length));
    // Every zipped tuple once: the same tuple twice would be the same case twice.
    for (std::size_t i = 0; i < zip_length; ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (std::all_of(zip.begin(), zip.end(), [&](const Axis& a) { return same_value(a.values[i], a.values[j]); })) {
          std::vector<std::string> keys;
          std::vector<Value> values;
          for (const Axis& a : zip) keys.push_back(a.key), values.push_back(a.values[i]);
          throw ConfigError(fmt::format("{}: zip: entries {} and {} are the same ({})", zip.front().origin, j + 1, i + 1,
                                        row_text(keys, values)));
        }
    // A key belongs to one of set, sweep, zip.
    std::vector<std::string> seen;
    auto claim = [&](const std::string& key, const std::string& origin) {
      if (std::find(seen.begin(), seen.end(), key) != seen.end())
        throw ConfigError(fmt::format("{}: study '{}': key '{}' is given twice (in set, sweep or zip)", origin, name, key));
      seen.push_back(key);
    };
    for (const Setting& s : fixed) claim(s.key, s.origin);
    for (const Axis& a : sweep) claim(a.key, a.origin);
    for (const Axis& a : zip) claim(a.key, a.origin);

    struct Override {
      std::vector<Setting> where, set;
    };
    std::vector<Override> overrides;
    if (const toml::node* o = study.get("override")) {
      if (!o->is_array_of_tables()) throw ConfigError(fmt::format("{}: 'override' must be [[study.override]] tables", where_in(path, *o)));
      for (const toml::node& item : *o->as_array()) {
        const toml::table& t = *item.as_table();
        expect_only(t, {"where", "set"}, path, "[[study.override]]");
        Override ov;
        if (const toml::node* w = t.get("where")) ov.where = settings_of(table_at(*w, path, "where"), path, specs, scene_config.scene(), "override where");
        if (const toml::node* s = t.get("set")) ov.set = settings_of(table_at(*s, path, "set"), path, specs, scene_config.scene(), "override set");
        if (ov.set.empty()) throw ConfigError(fmt::format("{}: [[study.override]] needs a 'set' table", where_in(path, item)));
        overrides.push_back(std::move(ov));
      }
    }

    // The product of the sweep lists, times the zipped tuples.
    std::vector<std::size_t> counter(sweep.size(), 0);
    for (bool more = true; more;) {
      for (std::size_t z = 0; z < zip_length; ++z) {
        Config config = scene_config;
        SuiteCase c;
        c.study = name;
        c.scene_file = scene_file;
        c.id = name;
        auto apply = [&](const std::string& key, const Value& v, const std::string& origin) {
          config.set(key, v, Origin{origin});
          c.overrides.push_back(key + "=" + as_setting(v));
        };
        for (const Setting& s : fixed) apply(s.key, s.value, s.origin);
        for (std::size_t a = 0; a < sweep.size(); ++a) {
          const Value& v = sweep[a].values[counter[a]];
          apply(sweep[a].key, v, sweep[a].origin);
          c.id += "-" + sweep[a].key + "=" + id_part(v);
        }
        for (const Axis& a : zip) {
          apply(a.key, a.values[z], a.origin);
          c.id += "-" + a.key + "=" + id_part(a.values[z]);
        }
        for (const Override& ov : overrides) {
          const bool match = std::all_of(ov.where.begin(), ov.where.end(),
                                         [&](const Setting& w) { return same_value(config.value(w.key), w.value); });
          if (match)
            for (const Setting& s : ov.set) apply(s.key, s.value, s.origin);
        }
        // The scene's own rules between keys, before anything runs.
        std::unique_ptr<SceneCase> built = find_scene_type(config.scene())->build(config);
        if (!first_of_study.count(name)) first_of_study[name] = std::move(built);
        c.configuration = config.to_toml();
        c.defaults = Config(config.scene(), specs).to_toml();
        for (const KeySpec& k : specs) c.keys[k.name] = json_of(config.value(k.name));
        for (const SuiteCase& other : suite.cases)
          if (other.id == c.id) throw ConfigError(fmt::format("{}: two cases have the id '{}'", here, c.id));
        // The id names the case's files (cases/<id>.h5.partial the longest),
        // and a file name holds at most 255 bytes.
        if (constexpr std::size_t longest_suffix = std::char_traits<char>::length(".h5.partial");
            c.id.size() + longest_suffix > 255)
          throw ConfigError(fmt::format("{}: the case id '{}...' is {} characters long, more than the {} a file name "
                                        "leaves it: shorten the study name or the swept values",
                                        here, c.id.substr(0, 60), c.id.size(), 255 - longest_suffix));
        suite.cases.push_back(std::move(c));
      }
      // Next combination of the sweep lists, the last key fastest.
      more = false;
      for (std::size_t a = sweep.size(); a-- > 0;) {
        if (++counter[a] < sweep[a].values.size()) {
          more = true;
          break;
        }
        counter[a] = 0;
      }
    }
  }

  // Expectations name a study, keys of its scene and levels it has.
  if (const toml::node* expects = top.get("expect")) {
    if (!expects->is_array_of_tables()) throw ConfigError(fmt::format("{}: 'expect' must be [[expect]] tables", where_in(path, *expects)));
    for (const toml::node& node : *expects->as_array()) {
      const toml::table& e = *node.as_table();
      const std::string here = where_in(path, node);
      expect_only(e, {"study", "where", "norm", "time", "refine", "levels", "order", "tolerance", "max_error_constant",
                      "max_error", "must_complete", "interval_within_band"},
                  path, "[[expect]]");
      const toml::node* study = e.get("study");
      if (!study || !study->is_string()) throw ConfigError(fmt::format("{}: [[expect]] needs the study it checks", here));
      const std::string name = study->as_string()->get();
      if (!study_keys.count(name)) throw ConfigError(fmt::format("{}: [[expect]]: no study named '{}'", where_in(path, *study), name));
      const std::vector<KeySpec>& specs = study_keys[name];
      auto is_key = [&](const std::string& k) {
        return std::any_of(specs.begin(), specs.end(), [&](const KeySpec& s) { return s.name == k; });
      };
      if (const toml::node* w = e.get("where")) settings_of(table_at(*w, path, "where"), path, specs, name, "[[expect]] where");
      const toml::node* norm = e.get("norm");
      if (!norm || !norm->is_string()) throw ConfigError(fmt::format("{}: [[expect]] needs a norm (an /errors column, e.g. \"L1_theta0\")", here));
      // An order with its band, or a bound on the error itself (exact-solution
      // scenes whose error sits at round-off or settling level), or both.
      const toml::node* max_error = e.get("max_error");
      if (max_error && !(max_error->value<double>().value_or(-1.0) > 0.0))
        throw ConfigError(fmt::format("{}: [[expect]]: 'max_error' must be a positive number", where_in(path, *max_error)));
      if (!max_error || e.get("order") || e.get("tolerance")) {
        for (const char* k : {"order", "tolerance"}) {
          const toml::node* n = e.get(k);
          if (!n || !(n->is_integer() || n->is_floating_point()))
            throw ConfigError(fmt::format("{}: [[expect]] needs '{}' (a number){}", here, k,
                                          max_error ? "" : ", or 'max_error' alone"));
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
      for (const char* k : {"must_complete", "interval_within_band"})
        if (const toml::node* m = e.get(k); m && !m->is_boolean())
          throw ConfigError(fmt::format("{}: [[expect]]: '{}' must be true or false", where_in(path, *m), k));
      if (e.get("interval_within_band") && !e.get("order"))
        throw ConfigError(fmt::format("{}: [[expect]]: 'interval_within_band' needs an 'order'", here));
      std::string refine = "cells";
      if (const toml::node* r = e.get("refine")) {
        if (!r->is_string() || !is_key(r->as_string()->get()))
          throw ConfigError(fmt::format("{}: [[expect]]: 'refine' must name a key of study '{}'", where_in(path, *r), name));
        refine = r->as_string()->get();
      }
      warn_of_a_trivial_read(e, here, *first_of_study.at(name), suite.warnings);
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
  check_references(top, path, study_keys, suite);
  return suite;
}

// ------------------------------------------------------------------ running

namespace {

volatile sig_atomic_t interrupted = 0;
void on_interrupt(int) { interrupted = 1; }

struct CaseState {
  std::string status = "pending";
  int exit_code = -1;
  double wall = 0.0;
  std::string detail;
};

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

// A file's JSON, or null where it is missing or does not parse (a case file
// cut short by a full disk).
Json read_json(const fs::path& path) {
  if (!fs::exists(path)) return nullptr;
  return Json::parse(read_text(path), nullptr, /*allow_exceptions=*/false);
}

// The last non-empty line of a log: the one-line message of a refused run.
std::string last_line(const fs::path& log) {
  std::istringstream in(read_text(log));
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

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

namespace {

// What a results file says of its run, or nothing when it is not a
// finished results file of this configuration.
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
    // A run written before the health verdict (tools/app/health.hpp) could
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

std::string self_executable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find the mpmvv executable (/proc/self/exe): " + ec.message());
  return p.string();
}

struct Running {
  std::size_t index;
  pid_t pid;
  std::chrono::steady_clock::time_point start;
  bool timed_out = false;
};

// Starts `mpmvv run` for a case in a process group of its own, with its output
// in the case's log.
pid_t spawn_case(const std::string& exe, const SuiteCase& c, const fs::path& results, const fs::path& log, int threads,
                 bool passive_wait, double checkpoint_seconds) {
  std::vector<std::string> args = {exe, "run", c.scene_file};
  for (const std::string& o : c.overrides) {
    args.push_back("--set");
    args.push_back(o);
  }
  for (const std::string& a : {std::string("-o"), results.string(), std::string("--quiet"), std::string("--threads"),
                               std::to_string(threads)})
    args.push_back(a);
  // A case the suite stopped goes on from its saved state.
  if (checkpoint_seconds > 0.0)
    for (const std::string& a : {std::string("--checkpoint-every"), fmt::format("{}", checkpoint_seconds),
                                 std::string("--resume-if-same")})
      args.push_back(a);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  std::vector<std::string> env_strings;
  for (char** e = environ; *e; ++e) {
    const std::string entry(*e);
    if (entry.rfind("OMP_WAIT_POLICY=", 0) != 0 && entry.rfind(std::string(kSuiteParent) + "=", 0) != 0)
      env_strings.push_back(entry);
  }
  // Cases share the cores: waiting threads must not spin on them.
  if (passive_wait) env_strings.emplace_back("OMP_WAIT_POLICY=passive");
  // The case ends with the suite, however the suite ends (run_case.cpp).
  env_strings.push_back(fmt::format("{}={}", kSuiteParent, ::getpid()));
  std::vector<char*> envp;
  for (std::string& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attributes;
  if (posix_spawn_file_actions_init(&actions) != 0 || posix_spawnattr_init(&attributes) != 0)
    throw std::runtime_error("posix_spawn initialisation failed");
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, exe.c_str(), &actions, &attributes, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (rc != 0) throw std::runtime_error(fmt::format("posix_spawn {} failed: {}", exe, std::strerror(rc)));
  return pid;
}

std::string duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  if (seconds < 60) return fmt::format("{:.0f}s", seconds);
  if (seconds < 3600) return fmt::format("{}m{:02d}s", int(seconds) / 60, int(seconds) % 60);
  return fmt::format("{}h{:02d}m", int(seconds) / 3600, (int(seconds) % 3600) / 60);
}

// The first error column at the last output time, for the summary.
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

}  // namespace

int run_suite(const SuiteRequest& request, std::ostream& out, std::ostream& err) {
  int rank = 0, ranks = 1;
#ifdef MPMVV_HAVE_MPI
  // Under mpirun the ranks share out the cases; run alone, MPI stays out.
  const bool under_mpi = std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
  if (under_mpi) {
    if (MPI_Init(nullptr, nullptr) != MPI_SUCCESS) {
      fmt::print(err, "mpmvv suite: MPI_Init failed\n");
      return 2;
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  }
  auto finish_mpi = [&](int status) {
    if (under_mpi) MPI_Finalize();
    return status;
  };
#else
  auto finish_mpi = [](int status) { return status; };
#endif

  Suite suite;
  try {
    suite = load_suite(request.suite_file);
  } catch (const ConfigError& e) {
    if (rank == 0) fmt::print(err, "mpmvv suite: {}\n", e.what());
    return finish_mpi(2);
  }
  if (rank == 0)
    for (const std::string& w : suite.warnings) fmt::print(err, "mpmvv suite: warning: {}\n", w);
  std::regex only;
  try {
    only = std::regex(request.only.empty() ? std::string(".") : request.only);
  } catch (const std::regex_error& e) {
    if (rank == 0) fmt::print(err, "mpmvv suite: --only '{}': not a regular expression ({})\n", request.only, e.what());
    return finish_mpi(2);
  }
  // --only: the cases the request selects; the others stay as an earlier run left them.
  auto selected = [&](const SuiteCase& c) { return request.only.empty() || std::regex_search(c.id, only); };
  if (std::none_of(suite.cases.begin(), suite.cases.end(), selected)) {
    if (rank == 0)
      fmt::print(err, "mpmvv suite: --only '{}' matches no case of {} (its ids look like '{}'; --list shows them)\n",
                 request.only, suite.file, suite.cases.empty() ? std::string() : suite.cases.front().id);
    return finish_mpi(2);
  }
  if (request.list) {
    if (rank == 0) {
      fmt::print(out, "suite {}: {} cases, timeout {} s{}\n", suite.file, suite.cases.size(), suite.timeout_seconds,
                 suite.description.empty() ? "" : "\n" + suite.description);
      for (const SuiteCase& c : suite.cases) {
        if (!selected(c)) continue;
        std::string settings;
        for (const std::string& o : c.overrides)
          settings += o.find(' ') == std::string::npos ? " --set " + o : " --set '" + o + "'";
        fmt::print(out, "{:<48} {}{}\n", c.id, c.scene_file, settings);
      }
    }
    return finish_mpi(0);
  }
  const fs::path dir = request.output_dir.empty() ? fs::path("results") / suite.name : fs::path(request.output_dir);
  const fs::path cases_dir = dir / "cases";
  std::error_code ec;
  fs::create_directories(cases_dir, ec);
  if (ec) {
    if (rank == 0) fmt::print(err, "mpmvv suite: -o {}: cannot create {}: {}\n", dir.string(), cases_dir.string(), ec.message());
    return finish_mpi(2);
  }
  // One suite at a time on a directory: a second would rename the first's
  // partial files and rewrite its manifest. The lock (flock on DIR/.lock,
  // held by rank 0 until it exits, not by the cases it starts) is released by
  // the kernel however the holder ends. A directory that holds another
  // suite's manifest is refused unless asked (--force).
  int refused = 0;
  std::string refusal;
  if (rank == 0) {
    const fs::path lock_file = dir / ".lock";
    const int fd = ::open(lock_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
      refused = 1;
      refusal = fmt::format("-o {}: cannot open {}: {}", dir.string(), lock_file.string(), std::strerror(errno));
    } else if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      refused = 1;
      refusal = fmt::format("-o {}: another mpmvv suite is running in this directory (it holds {}); wait for it, "
                            "or choose another directory",
                            dir.string(), lock_file.string());
    }  // else the descriptor stays open, and the lock held, until this process exits
    const fs::path manifest = dir / "manifest.json";
    if (!refused && fs::exists(manifest) && !request.force) {
      const std::string other = member<std::string>(read_json(manifest), "suite", suite.name);
      if (other != suite.name) {
        refused = 1;
        refusal = fmt::format("-o {}: the directory holds the results of suite '{}' (its manifest.json); choose "
                              "another directory, or --force to run '{}' there and replace that manifest",
                              dir.string(), other, suite.name);
      }
    }
  }
#ifdef MPMVV_HAVE_MPI
  if (under_mpi) MPI_Bcast(&refused, 1, MPI_INT, 0, MPI_COMM_WORLD);
#endif
  if (refused) {
    if (rank == 0) fmt::print(err, "mpmvv suite: {}\n", refusal);
    return finish_mpi(2);
  }
  if (rank == 0) fs::copy_file(suite.file, dir / "suite.toml", fs::copy_options::overwrite_existing, ec);

  const std::size_t n = suite.cases.size();
  std::vector<CaseState> state(n);
  auto results_of = [&](std::size_t i) { return cases_dir / (suite.cases[i].id + ".h5"); };
  auto relative_results = [&](std::size_t i) { return "cases/" + suite.cases[i].id + ".h5"; };
  auto record = [&](std::size_t i) {
    write_atomically(cases_dir / (suite.cases[i].id + ".json"),
                     json_text(case_json(suite.cases[i], state[i], relative_results(i))) + "\n");
  };
  auto write_manifest = [&]() {
    Json cases = Json::array();
    for (std::size_t i = 0; i < n; ++i) {
      Json object = read_json(cases_dir / (suite.cases[i].id + ".json"));
      if (!object.is_object()) object = case_json(suite.cases[i], CaseState{}, relative_results(i));
      cases.push_back(std::move(object));
    }
    const std::time_t now = std::time(nullptr);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    const Json head = {{"suite", suite.name},
                       {"suite_file", suite.file},
                       {"description", suite.description},
                       {"written", stamp},
                       {"expectations", suite.expectations}};
    // Each value written by nlohmann, a case a line, so that a manifest of
    // hundreds of cases reads (and greps) case by case.
    std::string text = "{";
    for (const auto& [key, value] : head.items()) text += json_text(key) + ": " + json_text(value) + ", ";
    text += "\"cases\": [";
    for (std::size_t i = 0; i < cases.size(); ++i) text += (i ? ",\n  " : "\n  ") + json_text(cases[i]);
    write_atomically(dir / "manifest.json", text + "\n]}\n");
  };

  // A write of the suite's own files that fails (a full disk) stops the
  // suite as an interrupt does: what is finished stays, and the last
  // manifest written stays whole.
  std::string write_failure;
  auto guarded = [&](auto&& write) {
    if (!write_failure.empty()) return;
    try {
      write();
    } catch (const std::exception& e) {
      write_failure = e.what();
    }
  };
  auto stopping = [&] { return interrupted || !write_failure.empty(); };

  // This rank's share, and what an earlier run already finished.
  std::vector<std::size_t> queue;
  std::size_t resumed = 0, unselected = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i % std::size_t(ranks) != std::size_t(rank)) continue;
    if (const auto done = finished_state(results_of(i), suite.cases[i])) {
      state[i] = *done;
      state[i].detail = (state[i].detail.empty() ? "" : state[i].detail + "; ") + "kept from an earlier run";
      guarded([&] { record(i); });
      ++resumed;
    } else if (selected(suite.cases[i])) {
      queue.push_back(i);
    } else {
      ++unselected;
    }
  }

  const int cores = std::max(1u, std::thread::hardware_concurrency());
  const int jobs = std::max(1, request.jobs);
  const int threads = request.threads > 0 ? request.threads : std::max(1, cores / (jobs * ranks));
  const bool passive = jobs * ranks > 1 || request.threads > 0;  // threads set: others share the cores
  const std::string exe = self_executable();
  const bool tty = isatty(fileno(stderr));
  const std::string prefix = ranks > 1 ? fmt::format("[rank {}] ", rank) : "";
  if (!request.quiet)
    fmt::print(err, "{}mpmvv suite {}: {} cases ({} here, {} kept from an earlier run{}), {} at once, {} threads each{} -> {}\n",
               prefix, suite.file, n, queue.size() + resumed + unselected, resumed,
               unselected ? fmt::format(", {} left pending by --only", unselected) : std::string(), jobs, threads,
               suite.checkpoint_seconds > 0.0
                   ? fmt::format(", each saving its state every {} (a rerun goes on from it)",
                                 duration(suite.checkpoint_seconds))
                   : std::string(),
               dir.string());

  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  std::vector<Running> running;
  std::size_t next = 0, finished = 0;
  double finished_wall = 0.0;
  const auto suite_start = std::chrono::steady_clock::now();
  auto last_progress = suite_start - std::chrono::seconds(60);
  std::size_t last_finished = 0;
  // A terminal line rewritten twice a second; in a log a line when a case
  // ends (printed where it is reaped) or once a minute.
  auto progress = [&](bool force) {
    if (request.quiet) return;
    const auto now = std::chrono::steady_clock::now();
    if (!force && now - last_progress < std::chrono::milliseconds(tty ? 500 : 60000) &&
        (tty || finished == last_finished))
      return;
    last_progress = now;
    last_finished = finished;
    std::size_t completed = 0, failed = 0, broken = 0;
    for (std::size_t i : queue) {
      if (state[i].status == "completed") ++completed;
      else if (state[i].status == "failed" || state[i].status == "lost") ++failed;
      else if (state[i].status != "pending" && state[i].status != "running") ++broken;
    }
    const std::size_t remaining = queue.size() - finished;
    const double eta = finished ? finished_wall / double(finished) * double(remaining) / double(jobs) : NAN;
    const int width = 24;
    const int filled = queue.empty() ? width : int(width * finished / queue.size());
    const std::string bar = std::string(std::size_t(filled), '#') + std::string(std::size_t(width - filled), '.');
    const std::string line = fmt::format("{}[{}] {}/{} cases: {} completed, {} failed or lost, {} crashed/timeout/error, {} running, ETA {}",
                                         prefix, bar, finished, queue.size(), completed, failed, broken, running.size(),
                                         duration(eta));
    if (tty) fmt::print(err, "\r{:<110}", line);
    else fmt::print(err, "{}\n", line);
    err.flush();
  };

  while ((next < queue.size() || !running.empty()) && !stopping()) {
    while (next < queue.size() && int(running.size()) < jobs && !stopping()) {
      const std::size_t i = queue[next++];
      fs::remove(results_of(i), ec);
      try {
        running.push_back({i, spawn_case(exe, suite.cases[i], results_of(i), cases_dir / (suite.cases[i].id + ".log"),
                                         threads, passive, suite.checkpoint_seconds),
                           std::chrono::steady_clock::now()});
        state[i].status = "running";
      } catch (const std::exception& e) {
        state[i] = {"error", -1, 0.0, e.what()};
        guarded([&] { record(i); });
        ++finished;
      }
    }
    // Reap whatever ended; kill what overran its time.
    for (auto it = running.begin(); it != running.end();) {
      int status = 0;
      const pid_t r = waitpid(it->pid, &status, WNOHANG);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - it->start).count();
      if (r == 0) {
        if (wall > suite.timeout_seconds && !it->timed_out) {
          kill(-it->pid, SIGKILL);
          it->timed_out = true;
        }
        ++it;
        continue;
      }
      const std::size_t i = it->index;
      CaseState& s = state[i];
      s.wall = wall;
      if (it->timed_out) {
        s.status = "timeout";
        s.detail = fmt::format("killed after {:.0f} s", suite.timeout_seconds);
      } else if (WIFSIGNALED(status)) {
        s.status = "crashed";
        s.detail = fmt::format("signal {} ({})", WTERMSIG(status), strsignal(WTERMSIG(status)));
      } else {
        s.exit_code = WEXITSTATUS(status);
        if (s.exit_code == 0 || s.exit_code == 1) {
          const auto done = finished_state(results_of(i), suite.cases[i]);
          if (done) {
            s = *done;
            s.wall = wall;
          } else {
            s.status = "error";
            s.detail = "the run ended without a usable results file (none, one without /errors, or one made with another MPMVV_FAULT)";
          }
        } else {
          s.status = "error";
          s.detail = last_line(cases_dir / (suite.cases[i].id + ".log"));
        }
      }
      fs::remove(results_of(i).string() + ".partial", ec);
      guarded([&] { record(i); });
      ++finished;
      finished_wall += wall;
      if (!tty && !request.quiet)
        fmt::print(err, "{}case {}: {} ({:.3g} s){}\n", prefix, suite.cases[i].id, s.status, wall,
                   s.detail.empty() ? "" : ", " + s.detail);
      if (ranks == 1) guarded(write_manifest);
      it = running.erase(it);
    }
    progress(false);
    if (!running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }

  if (stopping()) {
    for (const Running& r : running) kill(-r.pid, SIGTERM);
    for (const Running& r : running) waitpid(r.pid, nullptr, 0);
    for (const Running& r : running) fs::remove(results_of(r.index).string() + ".partial", ec);
    if (ranks == 1) guarded(write_manifest);
    if (tty && !request.quiet) fmt::print(err, "\n");
    if (!write_failure.empty()) {
      fmt::print(err, "{}mpmvv suite: {}; the suite stopped: {} {} finished, their results and the last manifest "
                 "written are kept; make room and rerun the same command to resume\n",
                 prefix, write_failure, finished, finished == 1 ? "case" : "cases");
      return finish_mpi(1);
    }
    fmt::print(err, "{}mpmvv suite: interrupted; {} cases finished; rerun the same command to resume\n", prefix, finished);
    return finish_mpi(130);
  }
  progress(true);
  if (tty && !request.quiet) fmt::print(err, "\n");

#ifdef MPMVV_HAVE_MPI
  if (under_mpi) MPI_Barrier(MPI_COMM_WORLD);
#endif
  int status = 0;
  if (rank == 0) {
    guarded(write_manifest);
    // Every case's state, from the status files all ranks wrote.
    std::string table = fmt::format("suite {} ({} cases) -> {}\n{:<48} {:<10} {:>9}  {}\n", suite.name, n, dir.string(),
                                    "case", "status", "wall [s]", "detail");
    std::map<std::string, int> counts;
    for (std::size_t i = 0; i < n; ++i) {
      const fs::path status_file = cases_dir / (suite.cases[i].id + ".json");
      const Json json = read_json(status_file);
      const std::string case_status = member<std::string>(json, "status", "pending");
      const double wall = member<double>(json, "wall_time_s", 0.0);
      const std::string detail = member<std::string>(json, "detail", "");
      ++counts[case_status];
      const std::string error = fs::exists(results_of(i)) ? headline_error(results_of(i)) : "";
      table += fmt::format("{:<48} {:<10} {:>9.3g}  {}\n", suite.cases[i].id, case_status, wall,
                           detail.empty() ? error : detail + (error.empty() ? "" : "; " + error));
      // A case --only left out may stay pending.
      if (case_status != "completed" && case_status != "failed" && case_status != "lost" &&
          !(case_status == "pending" && !selected(suite.cases[i])))
        status = 1;
    }
    std::string totals;
    for (const auto& [k, v] : counts) totals += fmt::format("{}{} {}", totals.empty() ? "" : ", ", v, k);
    table += fmt::format("{} in {}\n", totals,
                         duration(std::chrono::duration<double>(std::chrono::steady_clock::now() - suite_start).count()));
    guarded([&] { write_atomically(dir / "summary.txt", table); });
    fmt::print(out, "{}", table);
    if (!write_failure.empty()) {
      fmt::print(err, "mpmvv suite: {}; every case finished, and the results written are kept; make room and rerun "
                 "the same command to write the manifest and summary\n", write_failure);
      status = 1;
    }
  }
  return finish_mpi(status);
}

}  // namespace mpmvv::app
