// The VTK reader of an external program's particles (particle_output.hpp):
// a folder of particles_<k>.vtu, .vtp or .vtk files, the plane read from VTK's
// three components where the third vanish.
#include "particle_output.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string_view>

#include <fmt/format.h>

#include "output_arrays.hpp"
#include "vtk_file.hpp"

namespace mpmvv::app {

namespace fs = std::filesystem;

namespace {

// The one file of output k in a folder of VTK files, whichever of .vtu, .vtp
// and .vtk it is; none when there is none, refused when there are two.
std::optional<std::string> vtk_file_of(const std::string& folder, const std::string& stem) {
  std::optional<std::string> found;
  for (const char* ext : {".vtu", ".vtp", ".vtk"}) {
    const std::string path = (fs::path(folder) / (stem + ext)).string();
    if (!output_file_written(path)) continue;
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

void check_plane(const VtkPoints& v, const std::string& path, const std::function<std::string(const char*)>& named,
                 const StressOrder& o) {
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
    check("stress", *S, {o[0], o[1], o[2], o[3]}, {{o[4], 0.0, "sigma_yz"}, {o[5], 0.0, "sigma_xz"}}, nullptr);
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
  // z and a tensor's third row and column are dropped; a symmetric stress of
  // 6 is in VTK's order xx, yy, zz, xy, yz, xz unless external_stress_order
  // says otherwise.
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
      const StressOrder& o = stress_order_;
      pick = {o[0], o[3], o[3], o[1]};
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
  check_plane(v, *path, [&](const char* array) { return named(array); }, stress_order_);
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
