#include "particle_output.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "number_spacing.hpp"
#include "output_arrays.hpp"
#include "solver/io/hdf5.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;

namespace {

// Each array of the layout by mpmvv's name, in the layout's order, with its
// CSV columns (the stress's three give its four entries), given whole or not
// at all.
const std::vector<std::pair<std::string, std::vector<const char*>>> kArrays = {
    {"reference_position", {"X", "Y"}}, {"position", {"x", "y"}}, {"reference_volume", {"V0"}},
    {"velocity", {"vx", "vy"}}, {"stress", {"sxx", "sxy", "sxy", "syy"}},
    {"deformation_gradient", {"F11", "F12", "F21", "F22"}}, {"volume", {"V"}}, {"mass", {"m"}}, {"J", {"J"}}};

const std::vector<const char*>& csv_columns(const std::string& array) {
  const auto it = std::find_if(kArrays.begin(), kArrays.end(), [&](const auto& a) { return a.first == array; });
  if (it == kArrays.end()) throw std::logic_error("no array " + array + " in the layout");
  return it->second;
}

std::string trimmed(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// The items each format's files hold under mpmvv's names (external-format.md):
// the arrays (and the tracers) of HDF5, the point arrays of VTK, whose
// positions are its points and carry no name, the columns of CSV.
const std::vector<std::string>& own_names(const std::string& format) {
  static const std::map<std::string, std::vector<std::string>> names = [] {
    std::map<std::string, std::vector<std::string>> by_format;
    for (const auto& [array, columns] : kArrays) {
      by_format["hdf5"].push_back(array);
      if (array != "position") by_format["vtk"].push_back(array);
      std::vector<std::string>& csv = by_format["csv"];
      for (const char* c : columns)
        if (std::find(csv.begin(), csv.end(), c) == csv.end()) csv.push_back(c);
    }
    by_format["hdf5"].push_back("tracer_position");
    return by_format;
  }();
  return names.at(format);
}

}  // namespace

OutputNames parse_output_names(const std::string& text, const std::string& format) {
  OutputNames names;
  const std::vector<std::string>& own = own_names(format);
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string pair = trimmed(text.substr(start, comma - start));
    start = comma + 1;
    if (pair.empty()) continue;
    const std::size_t eq = pair.find('=');
    if (eq == std::string::npos)
      throw std::invalid_argument(fmt::format("'{}' is no NAME=FILE_NAME pair (e.g. reference_volume=vol0)", pair));
    const std::string name = trimmed(pair.substr(0, eq)), file = trimmed(pair.substr(eq + 1));
    if (std::find(own.begin(), own.end(), name) == own.end()) {
      std::string list;
      for (const std::string& n : own) list += (list.empty() ? "" : ", ") + n;
      throw std::invalid_argument(fmt::format("'{}' is not an item of the {} layout, whose names are {}{}", name, format,
                                              list, format == "vtk" ? " (the positions are the points)" : ""));
    }
    if (file.empty()) throw std::invalid_argument(fmt::format("'{}' is given no file name", name));
    if (names.count(name)) throw std::invalid_argument(fmt::format("'{}' is named twice", name));
    for (const auto& [other, given] : names)
      if (given == file) throw std::invalid_argument(fmt::format("'{}' is the file's name of both {} and {}", file, other, name));
    names[name] = file;
  }
  // An item left under its own name keeps that name in the file.
  for (const auto& [name, file] : names)
    if (file != name && std::find(own.begin(), own.end(), file) != own.end() && !names.count(file))
      throw std::invalid_argument(fmt::format("'{}' is the file's name of both {} and {} (which keeps its own name)",
                                              file, name, file));
  return names;
}

StressOrder parse_stress_order(const std::string& text) {
  static const std::map<std::string, std::size_t> component = {{"xx", 0}, {"yy", 1}, {"zz", 2}, {"xy", 3}, {"yx", 3},
                                                               {"yz", 4}, {"zy", 4}, {"xz", 5}, {"zx", 5}};
  static const char* const names[6] = {"xx", "yy", "zz", "xy", "yz", "xz"};
  constexpr std::size_t unset = 6;
  StressOrder order;
  order.fill(unset);
  std::size_t place = 0, start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    std::string name = trimmed(text.substr(start, comma - start));
    start = comma + 1;
    for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
    const auto it = component.find(name);
    if (it == component.end())
      throw std::invalid_argument(fmt::format("'{}' (place {}) is not a stress component: the six are xx, yy, zz, xy, "
                                              "yz, xz (yx, zy, zx for the last three), separated by commas",
                                              name, place + 1));
    if (order[it->second] != unset)
      throw std::invalid_argument(fmt::format("{} is given twice (places {} and {})", names[it->second],
                                              order[it->second] + 1, place + 1));
    if (place == 6) throw std::invalid_argument("more than six components");
    order[it->second] = place++;
  }
  for (std::size_t i = 0; i < 6; ++i)
    if (order[i] == unset) throw std::invalid_argument(fmt::format("{} is missing: each of the six is given once", names[i]));
  return order;
}

ParticleOutput::ParticleOutput(std::string path, std::string format, std::vector<double> requested, OutputNames names,
                               StressOrder stress_order)
    : path_(std::move(path)),
      format_(std::move(format)),
      requested_(std::move(requested)),
      names_(std::move(names)),
      stress_order_(stress_order) {}

std::string ParticleOutput::named(const std::string& own) const {
  const auto it = names_.find(own);
  return it == names_.end() ? own : it->second;
}

std::optional<OutputState> ParticleOutput::read(std::size_t k, std::size_t tracers) const {
  if (format_ == "csv") return read_csv(k, tracers);
  if (format_ == "vtk") return read_vtk(k, tracers);
  return read_hdf5(k, tracers);
}

namespace {

// The spacing of a dataset's `values` as HDF5 stores them (number_spacing.hpp).
double stored_spacing(const h5::Group& g, const std::string& dataset, const std::vector<double>& values) {
  const h5::Group::StoredNumber stored = g.stored_number(dataset);
  return binary_spacing(stored.floating, stored.bytes, values);
}

}  // namespace

std::optional<OutputState> ParticleOutput::read_hdf5(std::size_t k, std::size_t tracers) const {
  if (!output_file_written(path_)) return std::nullopt;
  const h5::File file = h5::File::open_read(path_);
  const h5::Group root = file.root();
  if (!root.has("snapshots")) return std::nullopt;
  const h5::Group all = root.open_group("snapshots");
  const std::string name = std::to_string(k);
  if (!all.has(name)) return std::nullopt;
  const h5::Group g = all.open_group(name);
  const std::string where = fmt::format("{}:/snapshots/{}", path_, name);
  // A dataset of N rows (N x 2 x 2 counts as N x 4).
  ArraySource source;
  source.get = [&](const std::string& item, std::size_t) -> std::optional<ArraySource::Rows> {
    const std::string& dataset = named(item);
    if (!g.has(dataset)) return std::nullopt;
    std::vector<hsize_t> d;
    ArraySource::Rows a;
    a.values = g.read_doubles(dataset, &d);
    a.rows = d.empty() ? 0 : d[0];
    a.spacing = stored_spacing(g, dataset, a.values);
    return a;
  };
  source.spelled = [&](const std::string& item) { return fmt::format("dataset '{}'", named(item)); };
  OutputState s;
  fill_state(s, source, where);
  if (const std::string& tracer = named("tracer_position"); g.has(tracer)) {
    std::vector<hsize_t> d;
    const std::vector<double> t = g.read_doubles(tracer, &d);
    if (d.size() != 2 || d[0] != tracers || d[1] != 2)
      throw ParticleOutputError(fmt::format("{}/{}: must be {} x 2 (the input file's tracers)", where, tracer, tracers));
    for (std::size_t i = 0; i < tracers; ++i) s.tracers.emplace_back(t[2 * i], t[2 * i + 1]);
    s.output_spacing = std::max(s.output_spacing, stored_spacing(g, tracer, t));
    s.fields.tracers = true;
  }
  s.time = g.has_attribute("time") ? checked_time(g.attribute_double("time"), requested_, k, where) : requested_[k];
  finish_state(s, where);
  return s;
}

namespace {

// A CSV file: a header naming the columns, then rows of numbers; lines that
// start with '#' are comments, and "# time = T" gives the program's time.
struct CsvTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  std::vector<int> digits;  // the most significant digits of any number in each column
  std::optional<double> time;
  const std::vector<double>* find(const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? nullptr : &columns[std::size_t(it - names.begin())];
  }
  double spacing(const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? kDoubleSpacing : digits_spacing(digits[std::size_t(it - names.begin())]);
  }
};

CsvTable read_csv_table(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw ParticleOutputError(fmt::format("{}: cannot be read", path));
  CsvTable t;
  std::size_t number = 0;
  for (std::string line; std::getline(f, line);) {
    ++number;
    // A UTF-8 byte order mark before the header, as spreadsheet programs write.
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    const std::string text = trimmed(line);
    if (text.empty()) continue;
    if (text[0] == '#') {
      const std::string body = trimmed(text.substr(1));
      if (body.rfind("time", 0) == 0 && body.find('=') != std::string::npos) {
        const std::string value = trimmed(body.substr(body.find('=') + 1));
        char* end = nullptr;
        const double v = std::strtod(value.c_str(), &end);
        if (end == value.c_str() || *end != '\0')
          throw ParticleOutputError(fmt::format("{}:{}: '{}' is not a time", path, number, value));
        t.time = v;
      }
      continue;
    }
    std::vector<std::string> cells;
    std::stringstream ss(text);
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(trimmed(cell));
    if (t.names.empty()) {
      for (std::size_t a = 0; a < cells.size(); ++a)
        for (std::size_t b = 0; b < a; ++b)
          if (cells[a] == cells[b])
            throw ParticleOutputError(fmt::format("{}:{}: the header names column '{}' twice (columns {} and {})",
                                                  path, number, cells[a], b + 1, a + 1));
      t.names = cells;
      t.columns.assign(cells.size(), {});
      t.digits.assign(cells.size(), 0);
      continue;
    }
    if (cells.size() != t.names.size())
      throw ParticleOutputError(fmt::format("{}:{}: {} values, the header names {} columns", path, number, cells.size(),
                                            t.names.size()));
    for (std::size_t c = 0; c < cells.size(); ++c) {
      char* end = nullptr;
      const double v = std::strtod(cells[c].c_str(), &end);
      if (cells[c].empty() || *end != '\0')
        throw ParticleOutputError(fmt::format("{}:{}: column '{}': '{}' is not a number", path, number, t.names[c],
                                              cells[c]));
      t.columns[c].push_back(v);
      t.digits[c] = std::max(t.digits[c], significant_digits(cells[c]));
    }
  }
  if (t.names.empty()) throw ParticleOutputError(fmt::format("{}: no header line", path));
  return t;
}

}  // namespace

std::optional<OutputState> ParticleOutput::read_csv(std::size_t k, std::size_t tracers) const {
  const std::string path = (fs::path(path_) / fmt::format("particles_{}.csv", k)).string();
  if (!output_file_written(path)) return std::nullopt;
  const CsvTable t = read_csv_table(path);
  auto names = [&](const std::string& array) {
    std::vector<std::string> unique;
    for (const char* c : csv_columns(array))
      if (std::find(unique.begin(), unique.end(), named(c)) == unique.end()) unique.push_back(named(c));
    return unique;
  };
  ArraySource source;
  source.spelled = [&](const std::string& array) {
    const std::vector<std::string> n = names(array);
    std::string all;
    for (const std::string& c : n) all += (all.empty() ? "" : ", ") + c;
    return n.size() == 1 ? fmt::format("column '{}'", all) : fmt::format("columns {}", all);
  };
  source.get = [&](const std::string& array, std::size_t width) -> std::optional<ArraySource::Rows> {
    std::vector<const std::vector<double>*> given;
    for (const char* c : csv_columns(array)) given.push_back(t.find(named(c)));
    const auto present = std::count_if(given.begin(), given.end(), [](auto* c) { return c != nullptr; });
    if (present == 0) return std::nullopt;
    if (present != std::ptrdiff_t(given.size()))
      throw ParticleOutputError(fmt::format("{}: the {} go together: give all or none", path, source.spelled(array)));
    ArraySource::Rows a;
    a.rows = given[0]->size();
    a.values.resize(a.rows * width);
    a.spacing = 0.0;
    a.text = true;
    for (const char* c : csv_columns(array)) a.spacing = std::max(a.spacing, t.spacing(named(c)));
    for (std::size_t p = 0; p < a.rows; ++p)
      for (std::size_t c = 0; c < width; ++c) a.values[p * width + c] = (*given[c])[p];
    return a;
  };
  OutputState s;
  fill_state(s, source, path);
  const std::string tracer_path = (fs::path(path_) / fmt::format("tracers_{}.csv", k)).string();
  if (output_file_written(tracer_path)) {
    const CsvTable r = read_csv_table(tracer_path);
    const auto* tx = r.find("x");
    const auto* ty = r.find("y");
    if (!tx || !ty) throw ParticleOutputError(fmt::format("{}: needs the columns x and y", tracer_path));
    check_tracers(tx->size(), tracers, tracer_path);
    for (std::size_t i = 0; i < tracers; ++i) s.tracers.emplace_back((*tx)[i], (*ty)[i]);
    s.output_spacing = std::max({s.output_spacing, r.spacing("x"), r.spacing("y")});
    s.fields.tracers = true;
  }
  s.time = t.time ? checked_time(*t.time, requested_, k, path) : requested_[k];
  finish_state(s, path);
  return s;
}

}  // namespace mpmvv::app
