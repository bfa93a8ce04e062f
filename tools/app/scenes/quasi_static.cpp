#include "quasi_static.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

std::vector<KeySpec> static_scene_keys(std::vector<KeySpec> k, const std::vector<KeySpec>& own,
                                       const std::vector<KeySpec>& material) {
  const double inf = std::numeric_limits<double>::infinity();
  k.insert(k.end(), own.begin(), own.end());
  const std::vector<KeySpec> load = {
      {"solver", KeyKind::text, std::string("explicit"),
       "explicit: the load ramped in time, grid damping settles the body (dynamic relaxation); implicit: "
       "quasi-static load steps, each solved for equilibrium by KINSOL's Newton-Krylov method",
       -inf, inf, false, false, {"explicit", "implicit"}},
      {"load_steps", KeyKind::integer, std::int64_t(4),
       "implicit: equal steps over the ramp (then steps of that length at full load to the end time)", 1, 100000},
      {"newton_tolerance", KeyKind::real, 1e-8,
       "implicit: a load step's Newton iteration stops at max |R| / (2 mu h) below this (R the nodal force "
       "residual: about the displacement error over h); the results' settling_displacement says how far from "
       "equilibrium that leaves the end",
       0.0, 1e-2, true},
      {"ramp_periods", KeyKind::real, 4.0,
       "the load rises over this many periods of the body's lowest mode, (1 - cos(pi t / T)) / 2, then holds", 0.0,
       inf, true},
      {"damping_ratio", KeyKind::real, 1.0,
       "grid damping (eq. 1.65, zeta = ratio x 2 omega_1; 1 damps the lowest mode critically, 0: none)", 0.0, 100.0},
  };
  k.insert(k.end(), load.begin(), load.end());
  return scene_keys(std::move(k), {}, material);
}

void add_bar_probes(SceneSetup& s, double L, double half, int points) {
  ProbeLine line{"line_axis", ProbeQuantity::displacement_x, "reference_x", {}, {}, std::nullopt};
  line.reference = points_on_segment(Vec2(0.0, 0.5 * half), Vec2(L, 0.5 * half), points);
  for (const Vec2& X : line.reference) line.parameter.push_back(X.x());
  s.lines.push_back(std::move(line));
  s.points.push_back({"point_top_middle", ProbeQuantity::displacement_y, Vec2(0.5 * L, half)});
}

QuasiStatic quasi_static_from(const Config& c, double omega, double shear_modulus, SceneSetup& s) {
  const double period = 2.0 * std::numbers::pi / omega;
  const double ramp_time = c.real("ramp_periods") * period;
  if (c.real("end_time") < 1.5 * ramp_time)
    c.reject("end_time", fmt::format("leaves no time to settle: the ramp lasts {:.6g} s ({} periods of {:.6g} s); "
                                     "use at least {:.6g} s",
                                     ramp_time, c.real("ramp_periods"), period, 1.5 * ramp_time));
  const QuasiStatic qs{ramp_time, c.real("damping_ratio") * 2.0 * omega};
  s.smooth_until = qs.ramp_time;
  s.settling = SettlingBody{omega, shear_modulus, qs.damping};
  return qs;
}

namespace {

int node_index(double offset, double h, const char* what) {
  const double index = offset / h;
  if (std::abs(index - std::round(index)) > 1e-9)
    throw std::logic_error(fmt::format("the {} at {} is not a node line (h = {})", what, offset, h));
  return int(std::lround(index));
}

}  // namespace

std::vector<std::size_t> node_column(const GridGeometry& grid, double x) {
  const int i = node_index(x - grid.origin.x(), grid.h, "column");
  std::vector<std::size_t> nodes;
  for (int j = 0; j < grid.nodes_y(); ++j) nodes.push_back(std::size_t(grid.node(i, j)));
  return nodes;
}

std::vector<std::size_t> node_row(const GridGeometry& grid, double y) {
  const int j = node_index(y - grid.origin.y(), grid.h, "row");
  std::vector<std::size_t> nodes;
  for (int i = 0; i < grid.nodes_x(); ++i) nodes.push_back(std::size_t(grid.node(i, j)));
  return nodes;
}

RegionMeans region_means(const Particles& P, const std::function<bool(const Vec2&)>& in_region) {
  RegionMeans m;
  double weight = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (!in_region(P.reference_position[p])) continue;
    const double w = P.reference_volume[p];
    m.deformation_gradient += w * P.deformation_gradient[p];
    m.stress += w * P.stress[p];
    weight += w;
    ++m.particles;
  }
  if (weight > 0.0) {
    m.deformation_gradient /= weight;
    m.stress /= weight;
  }
  return m;
}

Lame small_strain_lame(const MaterialModel& m) {
  const SmallStrainModuli s = std::visit([](const auto& x) { return x.small_strain_moduli(); }, m);
  return {s.lambda, s.mu};
}

void check_small_displacement(const Config& c, const std::string& key, double length, const char* length_name) {
  const double d = c.real(key);
  if (d == 0.0) c.reject(key, "must not be zero");
  if (std::abs(d) > 0.01 * length)
    c.reject(key, fmt::format("must stay within 1 % of the {} ({} m): the exact solution is small-strain", length_name,
                              0.01 * length));
}

double relative_error(double measured, double exact) {
  return exact != 0.0 ? std::abs(measured / exact - 1.0) : std::abs(measured);
}

}  // namespace mpmvv::app
