#include "study.hpp"

#include <algorithm>
#include <map>
#include <filesystem>
#include <regex>

#include <fmt/format.h>

#include "toml_values.hpp"

namespace mpmvv::app::suite_file {

namespace fs = std::filesystem;

std::pair<std::string, Study> expand_study(const toml::node& node, const std::string& path,
                                           const std::map<std::string, Study>& studies, Suite& suite) {
  const fs::path base = fs::path(path).parent_path();
  static const std::regex name_pattern("[A-Za-z0-9_-]+");
  const toml::table& study = *node.as_table();
  const std::string here = where_in(path, node);
  expect_only(study, {"name", "scene", "set", "sweep", "zip", "override", "ci"}, path, "[[study]]");
  const toml::node* name_node = study.get("name");
  if (!name_node || !name_node->is_string())
    throw ConfigError(fmt::format("{}: [[study]] needs a name (a string)", here));
  const std::string name = name_node->as_string()->get();
  if (!std::regex_match(name, name_pattern))
    throw ConfigError(fmt::format("{}: study name '{}' may hold only letters, digits, '-' and '_'", where_in(path, *name_node), name));
  if (studies.count(name)) throw ConfigError(fmt::format("{}: a second study named '{}'", where_in(path, *name_node), name));
  const toml::node* scene_node = study.get("scene");
  if (!scene_node || !scene_node->is_string())
    throw ConfigError(fmt::format("{}: study '{}' needs a scene (a scene file, relative to the suite)", here, name));
  const std::string scene_file = (base / scene_node->as_string()->get()).lexically_normal().string();
  std::error_code missing;
  if (!fs::exists(scene_file, missing) && !missing)  // (a loop or a FIFO: load_scene_file names it)
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

  std::vector<Setting> fixed;
  if (const toml::node* s = study.get("set")) fixed = settings_of(table_at(*s, path, "set"), path, specs, scene_config.scene(), "set");
  std::vector<Axis> sweep, zip;
  if (const toml::node* s = study.get("sweep")) sweep = axes_of(table_at(*s, path, "sweep"), path, specs, scene_config.scene(), "sweep");
  if (const toml::node* s = study.get("zip")) zip = axes_of(table_at(*s, path, "zip"), path, specs, scene_config.scene(), "zip");
  // The study's ci tier (suites/README.md): its `ci` table's keys take the
  // place of the study's own; a study without one is not in that tier.
  const toml::node* ci_node = study.get("ci");
  if (ci_node) {
    const toml::table& ci = table_at(*ci_node, path, "ci");
    expect_only(ci, {"set", "sweep", "zip"}, path, "a study's ci table");
    if (suite.tier == kCiTier) {
      std::vector<Setting> ci_set;
      std::vector<Axis> ci_sweep;
      if (const toml::node* s = ci.get("set")) ci_set = settings_of(table_at(*s, path, "ci set"), path, specs, scene_config.scene(), "ci set");
      if (const toml::node* s = ci.get("sweep")) ci_sweep = axes_of(table_at(*s, path, "ci sweep"), path, specs, scene_config.scene(), "ci sweep");
      if (const toml::node* s = ci.get("zip")) zip = axes_of(table_at(*s, path, "ci zip"), path, specs, scene_config.scene(), "ci zip");
      const auto replaced = [&](const std::string& key) {
        return std::any_of(ci_set.begin(), ci_set.end(), [&](const Setting& s) { return s.key == key; }) ||
               std::any_of(ci_sweep.begin(), ci_sweep.end(), [&](const Axis& a) { return a.key == key; });
      };
      // A key moved between set and sweep leaves where it was; a swept key
      // swept again keeps its place in the id.
      fixed.erase(std::remove_if(fixed.begin(), fixed.end(), [&](const Setting& s) { return replaced(s.key); }), fixed.end());
      sweep.erase(std::remove_if(sweep.begin(), sweep.end(),
                                 [&](const Axis& a) {
                                   return std::any_of(ci_set.begin(), ci_set.end(), [&](const Setting& s) { return s.key == a.key; });
                                 }),
                  sweep.end());
      for (Axis& c : ci_sweep) {
        const auto at = std::find_if(sweep.begin(), sweep.end(), [&](const Axis& a) { return a.key == c.key; });
        if (at == sweep.end()) continue;
        *at = c;
        c.key.clear();
      }
      ci_sweep.erase(std::remove_if(ci_sweep.begin(), ci_sweep.end(), [](const Axis& a) { return a.key.empty(); }),
                     ci_sweep.end());
      fixed.insert(fixed.end(), ci_set.begin(), ci_set.end());
      sweep.insert(sweep.end(), ci_sweep.begin(), ci_sweep.end());
    }
  }
  if (suite.tier == kCiTier && !ci_node) return {name, Study{specs, nullptr, false}};
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
      // A where of text for a number (cells = "24") would match no case and
      // be called a typo of the value.
      for (const Setting& w : ov.where)
        if (const bool text = std::holds_alternative<std::string>(w.value);
            text != std::holds_alternative<std::string>(scene_config.value(w.key)))
          throw ConfigError(fmt::format("{}: [[study.override]] where {} = {}: '{}' takes {}", where_in(path, item),
                                        w.key, text ? "\"" + std::get<std::string>(w.value) + "\"" : as_setting(w.value),
                                        w.key, text ? "a number" : "text"));
      overrides.push_back(std::move(ov));
    }
  }

  // A bound on the cases, before any is built: a sweep of hundreds of
  // thousands of cases is a mistake, and listing it alone would take minutes.
  double count = double(zip_length);
  for (const Axis& a : sweep) count *= double(a.values.size());
  if (double(suite.cases.size()) + count > double(kMaxCases))
    throw ConfigError(fmt::format("{}: study '{}' makes {:.0f} cases ({} before it), more than the {} a suite may "
                                  "hold: split the sweep into suites",
                                  here, name, count, suite.cases.size(), kMaxCases));

  // The product of the sweep lists, times the zipped tuples.
  std::vector<int> override_matches(overrides.size(), 0);
  std::unique_ptr<SceneCase> first;
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
      // Two overrides that set one key of a case to two values leave the
      // reader to guess which holds (the last would).
      std::map<std::string, std::pair<std::size_t, Value>> set_by;
      for (std::size_t k = 0; k < overrides.size(); ++k) {
        const Override& ov = overrides[k];
        const bool match = std::all_of(ov.where.begin(), ov.where.end(),
                                       [&](const Setting& w) { return same_value(config.value(w.key), w.value); });
        if (!match) continue;
        ++override_matches[k];
        for (const Setting& s : ov.set) {
          if (const auto it = set_by.find(s.key); it != set_by.end() && !same_value(it->second.second, s.value))
            throw ConfigError(fmt::format("{}: study '{}': [[study.override]] {} and {} both set '{}' on case '{}' ({} "
                                          "and {}): make their where tables exclusive",
                                          here, name, it->second.first + 1, k + 1, s.key, c.id,
                                          as_setting(it->second.second), as_setting(s.value)));
          set_by[s.key] = {k, s.value};
          apply(s.key, s.value, s.origin);
        }
      }
      // The scene's own rules between keys, before anything runs.
      std::unique_ptr<SceneCase> built = find_scene_type(config.scene())->build(config);
      c.error_columns = built->possible_error_columns();
      if (!first) first = std::move(built);
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
  // An override that matches no case is a typo, not a no-op: in the full
  // tier, where every level runs (a ci tier may leave its levels out).
  if (suite.tier == kFullTier)
    for (std::size_t k = 0; k < overrides.size(); ++k)
      if (override_matches[k] == 0) {
        std::vector<std::string> keys;
        std::vector<Value> values;
        for (const Setting& w : overrides[k].where) keys.push_back(w.key), values.push_back(w.value);
        throw ConfigError(fmt::format("{}: study '{}': [[study.override]] {} where {} matches none of its cases",
                                      here, name, k + 1, row_text(keys, values)));
      }
  return {name, Study{specs, std::move(first), true}};
}

}  // namespace mpmvv::app::suite_file
