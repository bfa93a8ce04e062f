#include "output_arrays.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>
#include <limits>
#include <utility>

#include <fmt/format.h>

namespace mpmvv::app {

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

}  // namespace

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

double checked_time(double own, const std::vector<double>& requested, std::size_t k, const std::string& where) {
  const double gap = k > 0 ? requested[k] - requested[k - 1] : requested[k];
  if (!(std::abs(own - requested[k]) <= 0.01 * gap))
    throw ParticleOutputError(fmt::format("{}: time {} is not the requested output time {} (at most {:.3g} s off: a "
                                          "hundredth of the gap to the output before)",
                                          where, own, requested[k], 0.01 * gap));
  return own;
}

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
  if (n == 0) throw ParticleOutputError(fmt::format("{}: no particles ({} has no rows)", where,
                                                    source.spelled("reference_position")));
  // The reference positions are the program's input as it took it, not its
  // result: one that is not a number is malformed output, not a lost run.
  for (std::size_t i = 0; i < X.size(); ++i)
    if (!std::isfinite(X[i]))
      throw ParticleOutputError(fmt::format("{}: {} of particle {} is {}, not a number", where,
                                            source.spelled("reference_position"), i / 2, X[i]));
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

bool output_file_written(const std::string& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) return false;
  if (error) throw ParticleOutputError(fmt::format("{}: cannot be read ({})", path, error.message()));
  if (!std::filesystem::is_regular_file(status))
    throw ParticleOutputError(fmt::format("{}: not a regular file (a FIFO, device or folder is no output)", path));
  return true;
}

}  // namespace mpmvv::app
