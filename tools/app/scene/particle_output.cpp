#include "particle_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "solver/io/hdf5.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

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

}  // namespace

ParticleOutput::ParticleOutput(std::string path, std::string format, std::vector<double> requested)
    : path_(std::move(path)), format_(std::move(format)), requested_(std::move(requested)) {}

std::optional<OutputState> ParticleOutput::read(std::size_t k, std::size_t tracers) const {
  return format_ == "csv" ? read_csv(k, tracers) : read_hdf5(k, tracers);
}

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
  for (const char* required : {"reference_position", "position", "reference_volume"})
    if (!g.has(required)) throw ParticleOutputError(fmt::format("{}: no dataset '{}' (it is required)", where, required));
  OutputState s;
  std::vector<hsize_t> dims;
  const std::vector<double> X = g.read_doubles("reference_position", &dims);
  if (dims.size() != 2 || dims[1] != 2)
    throw ParticleOutputError(fmt::format("{}/reference_position: must be N x 2", where));
  const std::size_t n = dims[0];
  start_state(s, n);
  // A dataset of n rows of `width` values (N x 2 x 2 counts as N x 4).
  auto rows = [&](const char* dataset, std::size_t width) {
    std::vector<hsize_t> d;
    std::vector<double> v = g.read_doubles(dataset, &d);
    if (d.empty() || d[0] != n || v.size() != n * width)
      throw ParticleOutputError(fmt::format("{}/{}: must have {} rows of {} values ({} particles in "
                                            "reference_position)", where, dataset, n, width, n));
    return v;
  };
  const std::vector<double> x = rows("position", 2), V0 = rows("reference_volume", 1);
  for (std::size_t p = 0; p < n; ++p) {
    s.P.reference_position[p] = Vec2(X[2 * p], X[2 * p + 1]);
    s.P.position[p] = Vec2(x[2 * p], x[2 * p + 1]);
    s.P.reference_volume[p] = V0[p];
  }
  auto vectors = [&](const char* dataset, std::vector<Vec2>& into, bool& given) {
    if (!g.has(dataset)) return;
    const std::vector<double> v = rows(dataset, 2);
    for (std::size_t p = 0; p < n; ++p) into[p] = Vec2(v[2 * p], v[2 * p + 1]);
    given = true;
  };
  auto tensors = [&](const char* dataset, std::vector<Mat2>& into, bool& given) {
    if (!g.has(dataset)) return;
    const std::vector<double> v = rows(dataset, 4);
    for (std::size_t p = 0; p < n; ++p) into[p] << v[4 * p], v[4 * p + 1], v[4 * p + 2], v[4 * p + 3];
    given = true;
  };
  auto scalars = [&](const char* dataset, std::vector<double>& into, bool& given) {
    if (!g.has(dataset)) return;
    into = rows(dataset, 1);
    given = true;
  };
  vectors("velocity", s.P.velocity, s.fields.velocity);
  tensors("stress", s.P.stress, s.fields.stress);
  tensors("deformation_gradient", s.P.deformation_gradient, s.fields.deformation_gradient);
  scalars("volume", s.P.volume, s.fields.volume);
  scalars("mass", s.P.mass, s.fields.mass);
  scalars("J", s.J, s.fields.J);
  if (g.has("tracer_position")) {
    std::vector<hsize_t> d;
    const std::vector<double> t = g.read_doubles("tracer_position", &d);
    if (d.size() != 2 || d[0] != tracers || d[1] != 2)
      throw ParticleOutputError(fmt::format("{}/tracer_position: must be {} x 2 (the input file's tracers)", where, tracers));
    for (std::size_t i = 0; i < tracers; ++i) s.tracers.emplace_back(t[2 * i], t[2 * i + 1]);
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
  std::optional<double> time;
  const std::vector<double>* find(const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? nullptr : &columns[std::size_t(it - names.begin())];
  }
};

std::string trimmed(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

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
  for (const char* required : {"X", "Y", "x", "y", "V0"})
    if (!t.find(required))
      throw ParticleOutputError(fmt::format("{}: no column '{}' (X, Y, x, y and V0 are required)", path, required));
  OutputState s;
  const std::size_t n = t.find("X")->size();
  start_state(s, n);
  const auto& X = *t.find("X");
  const auto& Y = *t.find("Y");
  const auto& x = *t.find("x");
  const auto& y = *t.find("y");
  const auto& V0 = *t.find("V0");
  for (std::size_t p = 0; p < n; ++p) {
    s.P.reference_position[p] = Vec2(X[p], Y[p]);
    s.P.position[p] = Vec2(x[p], y[p]);
    s.P.reference_volume[p] = V0[p];
  }
  // A group of columns given whole or not at all.
  auto group = [&](std::initializer_list<const char*> names, bool& given) -> std::vector<const std::vector<double>*> {
    std::vector<const std::vector<double>*> columns;
    for (const char* c : names) columns.push_back(t.find(c));
    const auto present = std::count_if(columns.begin(), columns.end(), [](auto* c) { return c != nullptr; });
    if (present == 0) return {};
    if (present != std::ptrdiff_t(columns.size())) {
      std::string all;
      for (const char* c : names) all += (all.empty() ? "" : ", ") + std::string(c);
      throw ParticleOutputError(fmt::format("{}: the columns {} go together: give all or none", path, all));
    }
    given = true;
    return columns;
  };
  if (auto v = group({"vx", "vy"}, s.fields.velocity); !v.empty())
    for (std::size_t p = 0; p < n; ++p) s.P.velocity[p] = Vec2((*v[0])[p], (*v[1])[p]);
  if (auto v = group({"sxx", "syy", "sxy"}, s.fields.stress); !v.empty())
    for (std::size_t p = 0; p < n; ++p) s.P.stress[p] << (*v[0])[p], (*v[2])[p], (*v[2])[p], (*v[1])[p];
  if (auto v = group({"F11", "F12", "F21", "F22"}, s.fields.deformation_gradient); !v.empty())
    for (std::size_t p = 0; p < n; ++p) s.P.deformation_gradient[p] << (*v[0])[p], (*v[1])[p], (*v[2])[p], (*v[3])[p];
  if (auto v = group({"V"}, s.fields.volume); !v.empty()) s.P.volume = *v[0];
  if (auto v = group({"m"}, s.fields.mass); !v.empty()) s.P.mass = *v[0];
  if (auto v = group({"J"}, s.fields.J); !v.empty()) s.J = *v[0];
  const std::string tracer_path = (fs::path(path_) / fmt::format("tracers_{}.csv", k)).string();
  if (fs::exists(tracer_path)) {
    const CsvTable r = read_csv_table(tracer_path);
    const auto* tx = r.find("x");
    const auto* ty = r.find("y");
    if (!tx || !ty) throw ParticleOutputError(fmt::format("{}: needs the columns x and y", tracer_path));
    if (tx->size() != tracers)
      throw ParticleOutputError(fmt::format("{}: {} rows, the input file lists {} tracers", tracer_path, tx->size(), tracers));
    for (std::size_t i = 0; i < tracers; ++i) s.tracers.emplace_back((*tx)[i], (*ty)[i]);
    s.fields.tracers = true;
  }
  s.time = t.time ? checked_time(*t.time, requested_, k, path) : requested_[k];
  finish_state(s, path);
  return s;
}

}  // namespace mpmvv::app
