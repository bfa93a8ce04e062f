// Simple shear of a steel block (PROBLEMS.md section 5; the seed's test,
// 004_5b499dc27e377c32.txt section 4.2: E = 207 GPa, nu = 0.3, sheared
// 18.3429 um over a height of 9.3619 cm, gamma = 1.9593e-4, exact
// tau = G gamma = 15.5992 MPa, G = E / (2 (1 + nu))). No forcing. The bottom
// y = 0 is clamped (the wall's roller plus a prescribed u_x = 0), the grid row
// y = H moves by the shear displacement along the ramp of
// analytic/quasi_static.hpp (u_y = 0), and damping settles the block. Its ends
// are free, where the state is not simple shear; the block is width_ratio
// times as wide as high (8; the seed's 11 x 3 particles give 3.7) so that its
// middle, read for the comparison, is in simple shear to far below 1e-3
// (end effects decay like exp(-pi x / H)).
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "analytic/quasi_static.hpp"
#include "analytic/uniaxial.hpp"
#include "tools/app/scene/setup.hpp"
#include "tools/app/scenes/quasi_static.hpp"

namespace mpmvv::app {

namespace {

std::vector<KeySpec> keys() {
  const double inf = std::numeric_limits<double>::infinity();
  // The block's lowest thickness-shear mode (clamped, then held at the top) has
  // a period of 2 H / c_s = 5.9e-5 s, c_s = sqrt(G / rho); four periods of
  // ramp, four to settle.
  std::vector<KeySpec> k = solver_keys(8, 5e-4, {5e-4});
  for (KeySpec& spec : k)
    if (spec.name == "cells") spec.help = "cells across the block's height";
  const std::vector<KeySpec> own = {
      {"height", KeyKind::real, 9.3619e-2, "H, the block's height [m] (the seed's 9.3619 cm)", 0.0, inf, true},
      {"width_ratio", KeyKind::real, 8.0, "the block's width over its height; its middle H is read", 3.0, 100.0},
      {"displacement", KeyKind::real, 18.3429e-6, "the top's displacement along x [m] (the seed's 18.3429 um)"},
      {"probe_points", KeyKind::integer, std::int64_t(21), "material points on the probe line", 2, 100000},
  };
  return static_scene_keys(std::move(k), own, material_keys("linear-elastic", 1.194230769e11, 7.96153846e10, 7850.0));
}

SceneSetup setup(const Config& c) {
  SceneSetup s;
  s.material = material_from(c);
  if (!std::holds_alternative<LinearElastic>(s.material))
    c.reject("material", "the shear scene compares with small-strain theory: use linear-elastic");
  s.geometry = Geometry::plane_strain;
  s.force_free = true;
  const double H = c.real("height"), W = c.real("width_ratio") * H, shift = c.real("displacement");
  check_small_displacement(c, "displacement", H, "height");
  const Lame lame = small_strain_lame(s.material);
  const analytic::SmallStrainBar solid{lame.youngs_modulus(), lame.poisson_ratio()};
  const double density = c.real("density");
  const double gamma = shift / H, tau = solid.shear_stress(gamma);
  const double omega = std::numbers::pi * std::sqrt(lame.mu / density) / H;
  const QuasiStatic qs = quasi_static_from(c, omega, lame.mu, s);

  Mat2 D = Mat2::Zero();
  D(0, 1) = gamma;
  s.solution = mms::make_solution(analytic::RampedHomogeneousMotion{D, qs.ramp_time, H}, s.material, density,
                                  s.geometry);

  const int cells = int(c.integer("cells"));
  const double h = H / cells;
  const int across = int(std::ceil(W / h - 1e-9));
  s.grid = GridGeometry::walled(Vec2(-3.0 * h, 0.0), h, across + 6, cells + 3);
  s.body_is_rectangle(Vec2::Zero(), Vec2(W, H));
  s.loading = fmt::format("bottom clamped, top moved by {} m along x (prescribed node motion), grid damping", shift);
  const double ramp_time = qs.ramp_time, damping = qs.damping;
  s.stages = [H, shift, ramp_time, damping](const Particles&, const GridGeometry& grid) {
    SceneStages stages;
    const auto still = [](double) { return 0.0; };
    stages.constraints.push_back({node_row(grid, 0.0), 0, still});
    // The top plate is rigid: its row and the one above move together.
    std::vector<std::size_t> top = node_row(grid, H), above = node_row(grid, H + grid.h);
    top.insert(top.end(), above.begin(), above.end());
    stages.constraints.push_back(
        {top, 0, [shift, ramp_time](double t) { return shift * analytic::ramp(t, ramp_time); }});
    stages.constraints.push_back({top, 1, still});
    stages.damping = damping;
    return stages;
  };

  ProbeLine line{"line_middle", ProbeQuantity::displacement_x, "reference_y", {}, {}, std::nullopt};
  line.reference = points_on_segment(Vec2(0.5 * W, 0.0), Vec2(0.5 * W, H), int(c.integer("probe_points")));
  for (const Vec2& X : line.reference) line.parameter.push_back(X.y());
  s.lines.push_back(std::move(line));
  s.points.push_back({"point_middle", ProbeQuantity::displacement_x, Vec2(0.5 * W, 0.5 * H)});

  auto middle = [W, H](const Vec2& X) { return std::abs(X.x() - 0.5 * W) <= 0.5 * H; };
  s.extra_error_names = {"error_shear_strain", "error_shear_stress", "error_normal_stress"};
  s.extra_errors = [=](double t, const RunRecord& record) {
    const Stepper& stepper = record.stepper;
    const double r = analytic::ramp(t, ramp_time);
    const RegionMeans m = region_means(stepper.model().particles, middle);
    const double normal = std::max(std::abs(m.stress(0, 0)), std::abs(m.stress(1, 1)));
    return std::vector<double>{relative_error(m.deformation_gradient(0, 1), r * gamma),
                               relative_error(m.stress(0, 1), r * tau), normal / tau};
  };
  s.measure = [=](const RunRecord& record) -> Measurements {
    const Particles& P = record.stepper.model().particles;
    const RegionMeans m = region_means(P, middle);
    double largest = 0.0;
    for (std::size_t p = 0; p < P.size(); ++p)
      if (middle(P.reference_position[p])) largest = std::max(largest, std::abs(P.stress[p](0, 1)));
    return {{"shear_strain", m.deformation_gradient(0, 1)},
            {"shear_strain_exact", gamma},
            {"shear_stress", m.stress(0, 1)},
            {"shear_stress_exact", tau},
            {"shear_stress_error", relative_error(m.stress(0, 1), tau)},
            {"largest_shear_stress_middle", largest},
            {"largest_shear_stress_error", relative_error(largest, tau)},
            {"top_reaction_stress", record.stepper.constraint_reactions().at(1) / W},
            {"middle_particles", double(m.particles)}};
  };
  return s;
}

}  // namespace

SceneType shear_scene() {
  return {"shear", "simple shear of a steel block, gamma = 1.96e-4, against tau = G gamma (PROBLEMS.md section 5)",
          keys, setup};
}

}  // namespace mpmvv::app
