#include "particle_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <string_view>

#include <fmt/format.h>

#include "number_spacing.hpp"
#include "solver/io/hdf5.hpp"
#include "vtk_file.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

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

// Every optional field NaN until given (OutputState).
void start_state(OutputState& s, std::size_t n) {
  s.P.resize(n);
  std::fill(s.P.velocity.begin(), s.P.velocity.end(), Vec2::Constant(nan));
  std::fill(s.P.stress.begin(), s.P.stress.end(), Mat2::Constant(nan));
  std::fill(s.P.deformation_gradient.begin(), s.P.deformation_gradient.end(), Mat2::Constant(nan));
  std::fill(s.P.volume.begin(), s.P.volume.end(), nan);
  std::fill(s.P.mass.begin(), s.P.mass.end(), nan);
}

// J from the volumes when no J was given.
void finish_state(OutputState& s, const std::string& where) {
  const Particles& P = s.P;
  for (std::size_t p = 0; p < P.size(); ++p)
    if (!(P.reference_volume[p] > 0.0))
      throw ParticleOutputError(fmt::format("{}: reference_volume of particle {} is {}, not positive", where, p,
                                            P.reference_volume[p]));
  if (s.fields.J || !s.fields.volume) return;
  s.J.resize(P.size());
  for (std::size_t p = 0; p < P.size(); ++p) s.J[p] = P.volume[p] / P.reference_volume[p];
  s.fields.J = true;
}

// The requested time k, or the program's own when close to it: within a
// hundredth of the gap to the requested time before (a code that steps with
// a fixed dt lands near, not on, an output time).
double checked_time(double own, const std::vector<double>& requested, std::size_t k, const std::string& where) {
  const double gap = k > 0 ? requested[k] - requested[k - 1] : requested[k];
  if (!(std::abs(own - requested[k]) <= 0.01 * gap))
    throw ParticleOutputError(fmt::format("{}: time {} is not the requested output time {} (at most {:.3g} s off: a "
                                          "hundredth of the gap to the output before)",
                                          where, own, requested[k], 0.01 * gap));
  return own;
}

// One output's arrays as mpmvv names them (reference_position, position,
// reference_volume, velocity, stress, deformation_gradient, J, volume, mass),
// whatever the file's format: `get` gives an array as rows of `width` values
// (a tensor's four in-plane entries row-major) or none when the file does not
// hold it; `spelled` says how the file spells it, for messages.
struct ArraySource {
  struct Rows {
    std::vector<double> values;
    std::size_t rows = 0;
    double spacing = kDoubleSpacing;  // of the numbers as the file stores them
    bool text = false;                // counted from text's digits (number_spacing.hpp)
  };
  std::function<std::optional<Rows>(const std::string& name, std::size_t width)> get;
  std::function<std::string(const std::string& name)> spelled;
};

// The particles of one output from its arrays: the required three, then each
// optional field the file holds (OutputFields), with the rows checked.
void fill_state(OutputState& s, const ArraySource& source, const std::string& where) {
  auto required = [&](const char* name, std::size_t width) {
    auto a = source.get(name, width);
    if (!a)
      throw ParticleOutputError(fmt::format("{}: no {} ({}, {} and {} are required)", where, source.spelled(name),
                                            source.spelled("reference_position"), source.spelled("position"),
                                            source.spelled("reference_volume")));
    return std::move(*a);
  };
  // The coarsest spacing of the arrays the norms difference (positions, F,
  // J, stress, velocity); volumes and masses only weight them.
  double spacing = 0.0;
  auto differenced = [&](ArraySource::Rows a) {
    spacing = std::max(spacing, a.spacing);
    return a;
  };
  ArraySource::Rows reference = required("reference_position", 2);
  ArraySource::Rows current = required("position", 2);
  // Text's digits bound a writer's precision from below only: seeded
  // reference positions on a lattice ("-1.225") need fewer digits than the
  // format gives them. A program writes X as it writes x, so in text the two
  // take the finer of their spacings (the most digits either shows).
  if (reference.text && current.text) reference.spacing = current.spacing = std::min(reference.spacing, current.spacing);
  const std::size_t n = reference.rows;
  auto checked = [&](const char* name, ArraySource::Rows a, std::size_t width) {
    if (a.rows != n || a.values.size() != n * width)
      throw ParticleOutputError(fmt::format("{}: {} must have {} rows of {} values ({} particles in {})", where,
                                            source.spelled(name), n, width, n, source.spelled("reference_position")));
    return std::move(a.values);
  };
  const std::vector<double> X = checked("reference_position", differenced(std::move(reference)), 2);
  const std::vector<double> x = checked("position", differenced(std::move(current)), 2);
  const std::vector<double> V0 = checked("reference_volume", required("reference_volume", 1), 1);
  start_state(s, n);
  for (std::size_t p = 0; p < n; ++p) {
    s.P.reference_position[p] = Vec2(X[2 * p], X[2 * p + 1]);
    s.P.position[p] = Vec2(x[2 * p], x[2 * p + 1]);
    s.P.reference_volume[p] = V0[p];
  }
  auto optional = [&](const char* name, std::size_t width, bool& given, bool weight = false) -> std::vector<double> {
    auto a = source.get(name, width);
    if (!a) return {};
    given = true;
    return checked(name, weight ? std::move(*a) : differenced(std::move(*a)), width);
  };
  if (const auto v = optional("velocity", 2, s.fields.velocity); s.fields.velocity)
    for (std::size_t p = 0; p < n; ++p) s.P.velocity[p] = Vec2(v[2 * p], v[2 * p + 1]);
  if (const auto v = optional("stress", 4, s.fields.stress); s.fields.stress)
    for (std::size_t p = 0; p < n; ++p) s.P.stress[p] << v[4 * p], v[4 * p + 1], v[4 * p + 2], v[4 * p + 3];
  if (const auto v = optional("deformation_gradient", 4, s.fields.deformation_gradient); s.fields.deformation_gradient)
    for (std::size_t p = 0; p < n; ++p)
      s.P.deformation_gradient[p] << v[4 * p], v[4 * p + 1], v[4 * p + 2], v[4 * p + 3];
  if (auto v = optional("volume", 1, s.fields.volume, true); s.fields.volume) s.P.volume = std::move(v);
  if (auto v = optional("mass", 1, s.fields.mass, true); s.fields.mass) s.P.mass = std::move(v);
  if (auto v = optional("J", 1, s.fields.J); s.fields.J) s.J = std::move(v);
  s.output_spacing = spacing;
}

void check_tracers(std::size_t given, std::size_t tracers, const std::string& where) {
  if (given != tracers)
    throw ParticleOutputError(fmt::format("{}: {} tracers, the input file lists {}", where, given, tracers));
}

}  // namespace

namespace {

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
  return names;
}

ParticleOutput::ParticleOutput(std::string path, std::string format, std::vector<double> requested, OutputNames names)
    : path_(std::move(path)), format_(std::move(format)), requested_(std::move(requested)), names_(std::move(names)) {}

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
  if (!fs::exists(path_)) return std::nullopt;
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
  if (!fs::exists(path)) return std::nullopt;
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
  if (fs::exists(tracer_path)) {
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

namespace {

// The one file of output k in a folder of VTK files, whichever of .vtu, .vtp
// and .vtk it is; none when there is none, refused when there are two.
std::optional<std::string> vtk_file_of(const std::string& folder, const std::string& stem) {
  std::optional<std::string> found;
  for (const char* ext : {".vtu", ".vtp", ".vtk"}) {
    const std::string path = (fs::path(folder) / (stem + ext)).string();
    if (!fs::exists(path)) continue;
    if (found) throw ParticleOutputError(fmt::format("{} and {}: one file per output time, not two", *found, path));
    found = path;
  }
  return found;
}

VtkPoints vtk_points(const std::string& path) {
  try {
    return read_vtk_points(path);
  } catch (const VtkFileError& e) {
    throw ParticleOutputError(e.what());
  }
}

// The program's time from the file's field data: ParaView's TimeValue, or time.
std::optional<double> vtk_time(const VtkPoints& v, const std::string& path) {
  for (const char* name : {"TimeValue", "time", "TIME"}) {
    const auto it = v.field_data.find(name);
    if (it == v.field_data.end()) continue;
    if (it->second.values.size() != 1)
      throw ParticleOutputError(fmt::format("{}: field data '{}' must be one value (the time)", path, name));
    return it->second.values[0];
  }
  return std::nullopt;
}

// The components a plane-strain reading drops must vanish, or a 3-D code's
// motion out of the plane would be measured as if it were plane strain: z -
// Z of the points, a velocity's z, F's out-of-plane shears (and F_33 - 1), a
// stress's out-of-plane shears, each against the largest magnitude of the
// numbers it is a difference of (the in-plane components; |Z| for z - Z; 1 at
// least for F), to 1e-9 of it or to 8 spacings of the numbers as written
// (number_spacing.hpp) where those are coarser: a float code's round-off.
constexpr double kPlaneTolerance = 1e-9;
constexpr double kPlaneSpacings = 8.0;

void check_plane(const VtkPoints& v, const std::string& path,
                 const std::function<std::string(const char*)>& named) {
  struct Component {
    std::size_t index;
    double target;  // its plane-strain value
    const char* name;
  };
  // `a`'s components `off` against their targets (or, with `base`, against
  // base's same component), scaled by the largest of its components `in`.
  auto check = [&](const char* what, const VtkArray& a, std::vector<std::size_t> in, std::vector<Component> off,
                   const VtkArray* base) {
    const std::size_t c = a.components, n = a.tuples();
    double scale = 0.0, worst = 0.0;
    std::size_t at = 0;
    const Component* which = &off[0];
    for (std::size_t p = 0; p < n; ++p) {
      for (std::size_t i : in) {
        scale = std::max(scale, std::abs(a.values[p * c + i]));
        if (base) scale = std::max(scale, std::abs(base->values[p * c + i]));
      }
      for (const Component& k : off) {
        if (base) scale = std::max(scale, std::abs(base->values[p * c + k.index]));  // a slab's |Z|
        const double d = std::abs(a.values[p * c + k.index] - (base ? base->values[p * c + k.index] : k.target));
        if (d > worst || std::isnan(d)) {
          worst = d;
          at = p;
          which = &k;
        }
        if (std::isnan(d)) break;
      }
    }
    if (std::string_view(what) == "deformation_gradient") scale = std::max(scale, 1.0);
    const double tolerance =
        std::max(kPlaneTolerance, kPlaneSpacings * std::max(a.spacing, base ? base->spacing : 0.0));
    if (!(worst <= tolerance * scale))
      throw ParticleOutputError(fmt::format(
          "{}: {} is not plane strain: {} is {:.6g} at particle {} ({:.3g} of the largest in-plane magnitude, {:.6g}); "
          "mpmvv reads the plane and drops the third components only where they vanish (to {:.3g} of it)",
          path, what, which->name, worst, at, scale > 0.0 ? worst / scale : worst, scale, tolerance));
  };
  const auto array = [&](const char* name, std::size_t components) -> const VtkArray* {
    const auto it = v.point_data.find(named(name));
    return it != v.point_data.end() && it->second.components == components ? &it->second : nullptr;
  };
  if (const VtkArray* X = array("reference_position", 3); X && X->tuples() == v.points.tuples())
    check("the points", v.points, {0, 1}, {{2, 0.0, "z - Z"}}, X);
  if (const VtkArray* u = array("velocity", 3)) check("velocity", *u, {0, 1}, {{2, 0.0, "v_z"}}, nullptr);
  if (const VtkArray* F = array("deformation_gradient", 9))
    check("deformation_gradient", *F, {0, 1, 3, 4},
          {{2, 0.0, "F_13"}, {5, 0.0, "F_23"}, {6, 0.0, "F_31"}, {7, 0.0, "F_32"}, {8, 1.0, "F_33 - 1"}}, nullptr);
  if (const VtkArray* S = array("stress", 9))
    check("stress", *S, {0, 1, 3, 4, 8}, {{2, 0.0, "sigma_xz"}, {5, 0.0, "sigma_yz"}, {6, 0.0, "sigma_zx"}, {7, 0.0, "sigma_zy"}},
          nullptr);
  if (const VtkArray* S = array("stress", 6))
    check("stress", *S, {0, 1, 2, 3}, {{4, 0.0, "sigma_yz"}, {5, 0.0, "sigma_xz"}}, nullptr);
}

}  // namespace

std::optional<OutputState> ParticleOutput::read_vtk(std::size_t k, std::size_t tracers) const {
  const std::optional<std::string> path = vtk_file_of(path_, fmt::format("particles_{}", k));
  if (!path) return std::nullopt;
  const VtkPoints v = vtk_points(*path);
  ArraySource source;
  source.spelled = [&](const std::string& array) {
    return array == "position" ? std::string("points") : fmt::format("point array '{}'", named(array));
  };
  // VTK's tuples hold 3 components where mpmvv's plane holds 2: a vector's
  // z and a tensor's third row and column are dropped; a symmetric tensor of
  // 6 is VTK's order xx, yy, zz, xy, yz, xz.
  source.get = [&](const std::string& array, std::size_t width) -> std::optional<ArraySource::Rows> {
    const VtkArray* a = &v.points;
    if (array != "position") {
      const auto it = v.point_data.find(named(array));
      if (it == v.point_data.end()) return std::nullopt;
      a = &it->second;
    }
    const std::size_t c = a->components, n = a->tuples();
    std::vector<std::size_t> pick;
    if (width == c) {
      for (std::size_t i = 0; i < c; ++i) pick.push_back(i);
    } else if (width == 2 && c == 3) {
      pick = {0, 1};
    } else if (width == 4 && c == 9) {
      pick = {0, 1, 3, 4};
    } else if (width == 4 && c == 6 && array == "stress") {
      pick = {0, 3, 3, 1};
    } else {
      throw ParticleOutputError(fmt::format("{}: {} has {} components; mpmvv reads {}", *path, source.spelled(array), c,
                                            width == 1 ? "1" : width == 2 ? "2 or 3" : array == "stress" ? "4, 6 or 9" : "4 or 9"));
    }
    ArraySource::Rows r;
    r.rows = n;
    r.spacing = a->spacing;
    r.text = a->text;
    r.values.resize(n * width);
    for (std::size_t p = 0; p < n; ++p)
      for (std::size_t i = 0; i < width; ++i) r.values[p * width + i] = a->values[p * c + pick[i]];
    return r;
  };
  OutputState s;
  fill_state(s, source, *path);
  check_plane(v, *path, [&](const char* array) { return named(array); });
  if (const auto tracer_path = vtk_file_of(path_, fmt::format("tracers_{}", k))) {
    const VtkPoints t = vtk_points(*tracer_path);
    check_tracers(t.points.tuples(), tracers, *tracer_path);
    for (std::size_t i = 0; i < tracers; ++i) s.tracers.emplace_back(t.points.values[3 * i], t.points.values[3 * i + 1]);
    s.output_spacing = std::max(s.output_spacing, t.points.spacing);
    s.fields.tracers = true;
  }
  const std::optional<double> own = vtk_time(v, *path);
  s.time = own ? checked_time(*own, requested_, k, *path) : requested_[k];
  finish_state(s, *path);
  return s;
}

}  // namespace mpmvv::app
