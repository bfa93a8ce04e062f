#include "tools/app/scenes/hertz_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "analytic/hertz.hpp"
#include "analytic/quasi_static.hpp"
#include "tools/app/scenes/quasi_static.hpp"

namespace mpmvv::app {

namespace {

// The vertical contact force of each node column x_i >= 0 (positive pressing
// into the plate; in r-z each node ring's, per radian), the pressure it gives
// and what Hertz theory says at the load it sums to. Nodal contact forces
// alternate from column to column (the checkerboard of a node-wise
// constraint); the pressure is read per cell: each column's force is shared
// between its two half-cells in proportion to their areas (in plane strain
// halves; in r-z the ring areas, (x_i -+ h/4) h / 2 per radian), the axis
// column's all to the first cell, and a cell's force over its area (h; in r-z
// its ring area x_mid h). This removes the alternation and, for a smooth
// profile, changes the pressure by O(h^2):
//   plane strain: p(h/2) = (F_0 + F_1 / 2) / h,  p((i + 1/2) h) = (F_i + F_{i+1}) / (2 h).
// The peak on the axis comes from two cells near it, with p even in x: in
// plane strain the two beside it, p0 = (9 p(h/2) - p(3h/2)) / 8; in r-z the
// next two, p0 = (25 p(3h/2) - 9 p(5h/2)) / 16, because the first cell's
// force is mostly its outer node's (the axis node's ring area is a third of
// the share it takes of node 1's), so the alternation does not cancel there:
// on the sphere at 50 and 100 cells the first cell read 13 % and 10 % above
// Hertz while the next eight were within 1-4 % and 0.7-2.5 %. The half-width from the moments of the
// column forces: a^2 = 4 sum F x^2 / sum F in plane strain and 5/2 of the
// ratio in r-z (both exact for p0 sqrt(1 - x^2 / a^2)). The amplitude of
// p0 sqrt(1 - x^2 / a^2) fitted by least squares to the cells within a is
// reported beside it (`peak_pressure_fit`).
struct ContactReading {
  std::vector<double> x, pressure, exact_pressure;  // at cell midpoints
  double load = 0.0;            // P: both halves per unit length, or in r-z the whole circle's [N]
  double half_width = 0.0;      // from the moments
  double extent = 0.0;          // the farthest column that carries force
  double peak_pressure = 0.0;   // on the axis, from the two cells beside it
  double fitted_peak = 0.0;     // the fitted amplitude
  HertzAtLoad hertz;
};

ContactReading read_contact(const GridGeometry& grid, const ContactForces& contact, const HertzContact& c) {
  const bool rz = c.geometry == Geometry::axisymmetric;
  ContactReading r;
  const int nx = grid.nodes_x(), ny = grid.nodes_y();
  const int axis = grid.ghost_layers;  // the wall x = 0
  std::vector<double> column;
  double half_load = 0.0, second_moment = 0.0;
  for (int i = axis; i < nx; ++i) {
    double force = 0.0;
    if (!contact.node_force.empty())
      for (int j = 0; j < ny; ++j) force -= contact.node_force[std::size_t(grid.node(i, j))].y();
    const double x = grid.node_position(i, 0).x();
    column.push_back(force);
    half_load += force;
    second_moment += force * x * x;
    if (force > 0.0) r.extent = x;
  }
  const double h = grid.h;
  // The share of column i's force that falls in the cell on its right (left: 1 - it).
  auto right_share = [&](std::size_t i) { return i == 0 ? 1.0 : rz ? 0.5 + 0.125 / double(i) : 0.5; };
  for (std::size_t i = 0; i + 1 < column.size(); ++i) {
    const double middle = (double(i) + 0.5) * h;
    const double force = right_share(i) * column[i] + (1.0 - right_share(i + 1)) * column[i + 1];
    r.x.push_back(middle);
    r.pressure.push_back(force / (rz ? middle * h : h));
  }
  r.load = rz ? 2.0 * std::numbers::pi * half_load : 2.0 * half_load;
  const double moment_factor = rz ? 2.5 : 4.0;
  r.half_width = half_load > 0.0 ? std::sqrt(moment_factor * second_moment / half_load) : 0.0;
  if (rz)  // from the second and third cells, at 3h/2 and 5h/2 (why: above)
    r.peak_pressure = r.pressure.size() > 2 ? (25.0 * r.pressure[1] - 9.0 * r.pressure[2]) / 16.0 : 0.0;
  else
    r.peak_pressure = r.pressure.size() > 1 ? (9.0 * r.pressure[0] - r.pressure[1]) / 8.0 : 0.0;
  double pw = 0.0, ww = 0.0;
  for (std::size_t i = 0; i < r.x.size() && r.x[i] < r.half_width; ++i) {
    const double w = std::sqrt(1.0 - r.x[i] * r.x[i] / (r.half_width * r.half_width));
    pw += r.pressure[i] * w;
    ww += w * w;
  }
  r.fitted_peak = ww > 0.0 ? pw / ww : 0.0;
  r.hertz = c.theory(std::max(r.load, 0.0));
  for (double x : r.x) r.exact_pressure.push_back(r.load > 0.0 ? r.hertz.pressure(x) : 0.0);
  return r;
}

// The stresses below the contact's centre: the particles of the column next
// to the axis (reference x within a spacing of it), by depth z below the
// surface, against Hertz's sigma_z and sigma_x (in r-z sigma_r) at the
// measured load; the largest shear (sigma_x - sigma_z) / 2 and its depth.
// Errors: mean |sigma - sigma_Hertz| over 0 < z < 3a, relative to p0.
struct AxisReading {
  std::vector<double> depth, sigma_x, sigma_z, exact_x, exact_z;
  double error_x = 0.0, error_z = 0.0, largest_shear = 0.0, shear_depth = 0.0;
};

AxisReading read_axis(const Particles& P, double spacing, const HertzAtLoad& hertz) {
  AxisReading r;
  std::vector<std::size_t> column;
  for (std::size_t p = 0; p < P.size(); ++p)
    if (P.reference_position[p].x() < spacing) column.push_back(p);
  std::sort(column.begin(), column.end(),
            [&](std::size_t a, std::size_t b) { return P.position[a].y() > P.position[b].y(); });
  const double a = hertz.half_width, p0 = hertz.peak_pressure;
  int counted = 0;
  for (std::size_t p : column) {
    const double z = -P.position[p].y();
    r.depth.push_back(z);
    r.sigma_x.push_back(P.stress[p](0, 0));
    r.sigma_z.push_back(P.stress[p](1, 1));
    r.exact_x.push_back(hertz.axis_sigma_x(std::max(z, 0.0)));
    r.exact_z.push_back(hertz.axis_sigma_z(std::max(z, 0.0)));
    const double shear = 0.5 * (P.stress[p](0, 0) - P.stress[p](1, 1));
    if (shear > r.largest_shear) {
      r.largest_shear = shear;
      r.shear_depth = z;
    }
    if (z > 0.0 && z < 3.0 * a) {
      r.error_x += std::abs(r.sigma_x.back() - r.exact_x.back());
      r.error_z += std::abs(r.sigma_z.back() - r.exact_z.back());
      ++counted;
    }
  }
  if (counted > 0 && p0 > 0.0) {
    r.error_x /= counted * p0;
    r.error_z /= counted * p0;
  }
  return r;
}

// The pressure profiles at the output times and the load-approach history,
// gathered during the run and written with the results.
struct HertzRecord {
  std::vector<double> x;
  std::vector<double> time;
  std::vector<std::vector<double>> pressure, exact_pressure;
  std::vector<double> peak_pressure_exact, half_width_exact;  // Hertz's p0 and a at each output's load (0 without)
  AxisReading axis;  // at the last output
};

}  // namespace

std::vector<KeySpec> hertz_keys(const char* indenter) {
  const double inf = std::numeric_limits<double>::infinity();
  // The plate's lowest mode (shear through its depth, clamped below) has a
  // period of 4 D / c_s = 2.5e-4 s; four periods of ramp, four to settle.
  std::vector<KeySpec> k = solver_keys(50, 2e-3, {2e-3});
  for (KeySpec& spec : k)
    if (spec.name == "cells") spec.help = "cells across the plate's depth";
  const std::vector<KeySpec> own = {
      {"radius", KeyKind::real, 2.0,
       fmt::format("R, the rigid {}'s radius [m]{}", indenter, std::string(indenter) == "disk" ? " (the seed's 2 m)" : ""),
       0.0, inf, true},
      {"approach", KeyKind::real, 2e-4, fmt::format("delta, how far the {} moves into the plate [m]", indenter), 0.0,
       inf, true},
      {"plate_depth", KeyKind::real, 0.2, "D, the plate's depth below its surface [m]", 0.0, inf, true},
      {"plate_width", KeyKind::real, 0.2, "W, the plate's half-width beside the axis [m]", 0.0, inf, true},
  };
  return static_scene_keys(std::move(k), own,
                           material_keys("linear-elastic", 1.194230769e11, 7.96153846e10, 7850.0));
}

HertzContact hertz_plate(const Config& c, SceneSetup& s, Geometry geometry, const char* indenter) {
  s.material = material_from(c);
  if (!std::holds_alternative<LinearElastic>(s.material))
    c.reject("material", "Hertz theory is small-strain linear elasticity: use linear-elastic");
  s.geometry = geometry;
  s.force_free = true;
  s.exact_motion = false;
  const double R = c.real("radius"), delta = c.real("approach");
  const double D = c.real("plate_depth"), W = c.real("plate_width");
  if (delta > 0.05 * D)
    c.reject("approach", fmt::format("must stay below 5 % of the plate's depth ({} m): Hertz theory is "
                                     "small-strain",
                                     0.05 * D));
  const Lame lame = small_strain_lame(s.material);
  const double E_star = analytic::contact_modulus_rigid(lame.youngs_modulus(), lame.poisson_ratio());
  const double density = c.real("density");
  const double omega = 0.5 * std::numbers::pi * std::sqrt(lame.mu / density) / D;
  const QuasiStatic qs = quasi_static_from(c, omega, lame.mu, s);
  // The plate starts at rest; the exact state is not a motion of the plate.
  s.solution = mms::make_solution(analytic::RampedHomogeneousMotion{Mat2::Zero(), qs.ramp_time, D}, s.material,
                                  density, s.geometry);

  const int cells = int(c.integer("cells"));
  const double h = D / cells;
  s.grid = GridGeometry::walled(Vec2(0.0, -D), h, int(std::ceil(W / h - 1e-9)) + 3, cells + 4);
  s.body_is_rectangle(Vec2(0.0, -D), Vec2(W, 0.0));
  s.loading = fmt::format("rigid {} R = {} m moved {} m into the plate, frictionless contact; bottom clamped; "
                          "grid damping",
                          indenter, R, delta);
  const double ramp_time = qs.ramp_time, damping = qs.damping;
  s.stages = [=](const Particles&, const GridGeometry& grid) {
    SceneStages stages;
    stages.constraints.push_back({node_row(grid, -D), 0, [](double) { return 0.0; }});
    RigidBody disk;
    disk.kind = RigidBody::Kind::disk;
    disk.point = Vec2(0.0, R);
    disk.radius = R;
    disk.displacement = [delta, ramp_time](double t) { return Vec2(0.0, -delta * analytic::ramp(t, ramp_time)); };
    stages.contact = disk;
    stages.damping = damping;
    return stages;
  };

  return {s.geometry, R, delta, ramp_time, D, h / double(c.integer("particles_per_direction")), E_star,
          lame.poisson_ratio()};
}

void add_hertz_readings(SceneSetup& s, const HertzContact& c) {
  auto record = std::make_shared<HertzRecord>();
  s.extra_error_names = {"error_half_width", "error_peak_pressure", "error_pressure_profile", "error_axis_sigma_x",
                         "error_axis_sigma_z"};
  s.extra_errors = [=](double t, const RunRecord& run) {
    const ContactReading r = read_contact(run.stepper.model().grid, run.stepper.contact_forces(), c);
    record->x = r.x;
    record->time.push_back(t);
    record->pressure.push_back(r.pressure);
    record->exact_pressure.push_back(r.exact_pressure);
    record->peak_pressure_exact.push_back(r.load > 0.0 ? r.hertz.peak_pressure : 0.0);
    record->half_width_exact.push_back(r.load > 0.0 ? r.hertz.half_width : 0.0);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (!(r.load > 0.0)) return std::vector<double>{nan, nan, nan, nan, nan};
    record->axis = read_axis(run.stepper.model().particles, c.spacing, r.hertz);
    // Mean |p - p_Hertz| over the columns within 1.5 a, relative to p0.
    double profile = 0.0;
    int columns = 0;
    for (std::size_t i = 0; i < r.x.size() && r.x[i] <= 1.5 * r.hertz.half_width; ++i, ++columns)
      profile += std::abs(r.pressure[i] - r.exact_pressure[i]);
    return std::vector<double>{relative_error(r.half_width, r.hertz.half_width),
                               relative_error(r.peak_pressure, r.hertz.peak_pressure),
                               profile / std::max(columns, 1) / r.hertz.peak_pressure, record->axis.error_x,
                               record->axis.error_z};
  };
  s.measure = [=](const RunRecord& run) -> Measurements {
    const ContactReading r = read_contact(run.stepper.model().grid, run.stepper.contact_forces(), c);
    const AxisReading axis = read_axis(run.stepper.model().particles, c.spacing, r.hertz);
    const double a = r.hertz.half_width, p0 = r.hertz.peak_pressure;
    return {{"load", r.load},
            {"approach", c.approach},
            {"half_width", r.half_width},
            {"half_width_exact", r.hertz.half_width},
            {"half_width_error", relative_error(r.half_width, r.hertz.half_width)},
            {"contact_extent", r.extent},
            {"peak_pressure", r.peak_pressure},
            {"peak_pressure_exact", r.hertz.peak_pressure},
            {"peak_pressure_error", relative_error(r.peak_pressure, r.hertz.peak_pressure)},
            {"peak_pressure_fit", r.fitted_peak},
            {"peak_pressure_fit_error", relative_error(r.fitted_peak, r.hertz.peak_pressure)},
            {"largest_shear_over_p0", axis.largest_shear / p0},
            {"largest_shear_over_p0_exact", c.largest_shear},
            {"largest_shear_depth_over_a", axis.shear_depth / a},
            {"largest_shear_depth_over_a_exact", c.largest_shear_depth},
            {"half_width_over_h", r.half_width / run.stepper.model().grid.h},
            {"half_width_over_depth", r.half_width / c.plate_depth}};
  };
  const bool rz = c.geometry == Geometry::axisymmetric;
  s.write_extra = [record, rz](h5::Group& probes) {
    h5::Group g = probes.create_group("contact_pressure");
    g.set_attribute("description",
                    rz ? "pressure of the contact on the plate at each output time, at cell midpoints x (the radius "
                         "r): the vertical contact force of each node ring shared between its two half-cells by "
                         "their areas, a cell's over its ring area, and Hertz's p0 sqrt(1 - r^2 / a^2) at the load "
                         "it sums to [Pa]; that p0 [Pa] and the contact radius a [m] at each output time "
                         "(exact_peak_pressure, exact_half_width; 0 where no load)"
                       : "pressure of the contact on the plate at each output time, at cell midpoints x: half the "
                         "vertical contact force of each bounding node column over the cell's width, and Hertz's "
                         "p0 sqrt(1 - x^2 / a^2) at the load it sums to [Pa]; that p0 [Pa] and a [m] at each output "
                         "time (exact_peak_pressure, exact_half_width; 0 where no load)");
    const std::size_t n = record->x.size(), T = record->time.size();
    std::vector<double> p, e;
    for (std::size_t k = 0; k < T; ++k) {
      p.insert(p.end(), record->pressure[k].begin(), record->pressure[k].end());
      e.insert(e.end(), record->exact_pressure[k].begin(), record->exact_pressure[k].end());
    }
    g.write("x", record->x, {n});
    g.write("time", record->time, {T});
    g.write("pressure", p, {T, n});
    g.write("exact_pressure", e, {T, n});
    g.write("exact_peak_pressure", record->peak_pressure_exact, {T});
    g.write("exact_half_width", record->half_width_exact, {T});
    h5::Group axis = probes.create_group("axis_stress");
    axis.set_attribute("description",
                       rz ? "stresses of the particles next to the axis at the last output time, by depth z below "
                            "the surface (sigma_x the radial stress sigma_r), and Hertz's sigma_r, sigma_z on the "
                            "axis at the measured load [Pa]"
                          : "stresses of the particles next to the axis at the last output time, by depth z below the "
                            "surface, and Hertz's sigma_x, sigma_z on the axis at the measured load [Pa]");
    const AxisReading& r = record->axis;
    const std::size_t m = r.depth.size();
    axis.write("depth", r.depth, {m});
    axis.write("sigma_x", r.sigma_x, {m});
    axis.write("sigma_z", r.sigma_z, {m});
    axis.write("exact_sigma_x", r.exact_x, {m});
    axis.write("exact_sigma_z", r.exact_z, {m});
  };
  s.history_names = {"approach", "load"};
  s.history = [=](double t, const Stepper& stepper) {
    const ContactReading r = read_contact(stepper.model().grid, stepper.contact_forces(), c);
    return std::vector<double>{c.approach * analytic::ramp(t, c.ramp_time), r.load};
  };
}

}  // namespace mpmvv::app
