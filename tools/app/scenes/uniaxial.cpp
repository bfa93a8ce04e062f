// The uniaxial bar in tension and in compression (PROBLEMS.md section 5; the
// seed's steel bar, 004_5b499dc27e377c32.txt section 4.1: E = 207 GPa,
// nu = 0.3, 5 x 11 particles of 23.4 mm^3 (side d = 2.86 mm), pulled or pushed
// 0.8566 um along its axis). No forcing. Plane strain: the exact static state
// is homogeneous with
//   eps_xx = delta / L,   sigma_xx = E' eps_xx,   E' = E / (1 - nu^2),
//   eps_yy = -nu' eps_xx, nu' = nu / (1 - nu)
// (analytic/uniaxial.hpp). The bar [0, L] x [0, H/2] is the upper half of the
// bar: the wall y = 0 is its plane of symmetry, the wall x = 0 a frictionless
// support, and the grid column x = L a frictionless grip moved by delta along
// the ramp of analytic/quasi_static.hpp; the top is free. Damping settles it.
// Read in the middle half of the bar: the mean strains and stress of its
// particles, and the grip's reaction over the end's current height.
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "analytic/quasi_static.hpp"
#include "analytic/uniaxial.hpp"
#include "tools/app/scene/setup.hpp"
#include "tools/app/scenes/quasi_static.hpp"

namespace mpmvv::app {

namespace {

// The seed's particle side d = (23.4 mm^3)^(1/3).
const double kSeedParticle = std::cbrt(23.4e-9);

std::vector<KeySpec> keys_with(double displacement) {
  const double inf = std::numeric_limits<double>::infinity();
  // Steel, L = 11 d: the lowest mode (fixed-fixed along the axis) has a period
  // of 2 L / c = 1.17e-5 s with c = sqrt(E' / rho); four periods of ramp,
  // about four to settle.
  std::vector<KeySpec> k = solver_keys(22, 1e-4, {1e-4});
  const std::vector<KeySpec> own = {
      {"length", KeyKind::real, 11.0 * kSeedParticle, "L, the bar's length along x [m] (the seed: 11 particles)", 0.0,
       inf, true},
      {"height", KeyKind::real, 5.0 * kSeedParticle,
       "H, the bar's full height [m] (the seed: 5 particles); the scene holds its upper half", 0.0, inf, true},
      {"displacement", KeyKind::real, displacement,
       "delta, the grip's displacement along the axis [m] (positive: tension)"},
      {"probe_points", KeyKind::integer, std::int64_t(21), "material points on the probe line", 2, 100000},
  };
  return static_scene_keys(std::move(k), own, material_keys("linear-elastic", 1.194230769e11, 7.96153846e10, 7850.0));
}

std::vector<KeySpec> tension_keys() { return keys_with(0.8566e-6); }
std::vector<KeySpec> compression_keys() { return keys_with(-0.8566e-6); }

SceneSetup setup(const Config& c) {
  SceneSetup s;
  s.material = material_from(c);
  if (!std::holds_alternative<LinearElastic>(s.material))
    c.reject("material", "the uniaxial scenes compare with small-strain theory: use linear-elastic (the "
                         "neo-hookean-bar scene is the finite-strain bar)");
  s.geometry = Geometry::plane_strain;
  s.force_free = true;
  const double L = c.real("length"), half = 0.5 * c.real("height"), delta = c.real("displacement");
  check_small_displacement(c, "displacement", L, "length");
  const Lame lame = small_strain_lame(s.material);
  const analytic::SmallStrainBar bar{lame.youngs_modulus(), lame.poisson_ratio()};
  const double density = c.real("density");
  const double eps = delta / L;
  const double eps_lateral = bar.lateral_strain_plane_strain(eps);
  const double sigma = bar.stress_plane_strain(eps);
  // Lowest axial mode between support and grip: omega = pi c / L.
  const double omega = std::numbers::pi * std::sqrt(lame.plane_strain_modulus() / density) / L;
  const QuasiStatic qs = quasi_static_from(c, omega, lame.mu, s);

  Mat2 D = Mat2::Zero();
  D(0, 0) = eps;
  D(1, 1) = eps_lateral;
  const analytic::RampedHomogeneousMotion motion{D, qs.ramp_time, L};
  s.solution = mms::make_solution(motion, s.material, density, s.geometry);

  const int cells = int(c.integer("cells"));
  const double h = L / cells;
  const int rows = int(std::ceil(half / h - 1e-9)) + 3;
  s.grid = GridGeometry::walled(Vec2::Zero(), h, cells + 3, rows);
  s.body_is_rectangle(Vec2::Zero(), Vec2(L, half));
  s.loading = fmt::format("grip at x = L moved by {} m (prescribed node motion), grid damping", delta);
  const double ramp_time = qs.ramp_time, damping = qs.damping;
  s.stages = [L, delta, ramp_time, damping](const Particles&, const GridGeometry& grid) {
    SceneStages stages;
    // The grip is rigid: the column x = L and the columns beyond it, which the
    // end particles' domains reach as the bar stretches, move with it.
    std::vector<std::size_t> nodes;
    for (int k = 0; k < 3; ++k) {
      const std::vector<std::size_t> column = node_column(grid, L + k * grid.h);
      nodes.insert(nodes.end(), column.begin(), column.end());
    }
    stages.constraints.push_back(
        {nodes, 0, [delta, ramp_time](double t) { return delta * analytic::ramp(t, ramp_time); }});
    stages.damping = damping;
    return stages;
  };

  add_bar_probes(s, L, half, int(c.integer("probe_points")));

  // The middle half of the bar, away from support and grip.
  auto middle = [L](const Vec2& X) { return X.x() >= 0.25 * L && X.x() <= 0.75 * L; };
  s.extra_error_names = {"error_axial_strain", "error_lateral_strain", "error_axial_stress", "error_grip_stress"};
  s.extra_errors = [=](double t, const RunRecord& record) {
    const Stepper& stepper = record.stepper;
    const double r = analytic::ramp(t, ramp_time);
    const RegionMeans m = region_means(stepper.model().particles, middle);
    const double eps_yy = m.deformation_gradient(1, 1) - 1.0;
    const double grip = stepper.constraint_reactions().at(0) / (half * (1.0 + eps_yy));
    return std::vector<double>{relative_error(m.deformation_gradient(0, 0) - 1.0, r * eps),
                               relative_error(eps_yy, r * eps_lateral), relative_error(m.stress(0, 0), r * sigma),
                               relative_error(grip, r * sigma)};
  };
  const double nu = bar.poisson_ratio;
  s.measure = [=](const RunRecord& record) -> Measurements {
    const RegionMeans m = region_means(record.stepper.model().particles, middle);
    const double exx = m.deformation_gradient(0, 0) - 1.0, eyy = m.deformation_gradient(1, 1) - 1.0;
    const double grip = record.stepper.constraint_reactions().at(0) / (half * (1.0 + eyy));
    const double nu_plane = -eyy / exx, nu_implied = nu_plane / (1.0 + nu_plane);
    return {{"axial_strain", exx},
            {"axial_strain_exact", eps},
            {"lateral_strain", eyy},
            {"lateral_strain_exact", eps_lateral},
            {"lateral_strain_error", relative_error(eyy, eps_lateral)},
            {"axial_stress", m.stress(0, 0)},
            {"axial_stress_exact", sigma},
            {"axial_stress_error", relative_error(m.stress(0, 0), sigma)},
            {"grip_stress", grip},
            {"grip_stress_error", relative_error(grip, sigma)},
            {"poisson_ratio_plane_strain", nu_plane},
            {"poisson_ratio_plane_strain_exact", nu / (1.0 - nu)},
            {"poisson_ratio", nu_implied},
            {"poisson_ratio_exact", nu},
            {"poisson_ratio_error", relative_error(nu_implied, nu)},
            {"middle_particles", double(m.particles)}};
  };
  return s;
}

}  // namespace

SceneType uniaxial_tension_scene() {
  return {"uniaxial-tension",
          "steel bar pulled 0.8566 um, plane strain, against sigma = E' eps and eps_yy = -nu' eps (PROBLEMS.md "
          "section 5)",
          tension_keys, setup};
}

SceneType uniaxial_compression_scene() {
  return {"uniaxial-compression",
          "steel bar pushed 0.8566 um, plane strain, against sigma = E' eps and eps_yy = -nu' eps (PROBLEMS.md "
          "section 5)",
          compression_keys, setup};
}

}  // namespace mpmvv::app
