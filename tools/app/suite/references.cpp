#include "references.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "toml_values.hpp"

namespace mpmvv::app::suite_file {

namespace {

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

}  // namespace

void check_references(const toml::table& top, const std::string& path, const std::map<std::string, Study>& suite_studies,
                      const Suite& suite) {
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
      if (!suite_studies.count(s)) throw ConfigError(fmt::format("{}: [[reference]]: no study named '{}'", where_in(path, *study), s));

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
          const std::vector<KeySpec>& specs = suite_studies.at(s).keys;
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

}  // namespace mpmvv::app::suite_file
