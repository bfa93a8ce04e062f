// A neo-Hookean bar stretched or compressed by half its length under a dead
// load (PROBLEMS.md section 5, finite strain). No forcing. Plane strain,
// F = diag(l1, l2, 1): the lateral stretch l2 solves sigma_yy(l1, l2) = 0
// (000_1dbcb8acb6dddab9.txt eq. 2.2; a scalar root by KINSOL,
// analytic/uniaxial.hpp), and the end carries the nominal traction
// P = sigma_xx l2 per unit reference height. The bar [0, L] x [0, H/2] is the
// upper half (symmetry plane y = 0) on a frictionless support x = 0. In
// tension the end particles carry P, ramped (analytic/quasi_static.hpp); in
// compression a dead load on a free end folds the loaded column of particles,
// so a rigid platen (a half-plane in frictionless contact, solver/contact.hpp)
// pushes the end to l1 L instead, and its force is the load. Damping settles it.
// The static state is homogeneous: read in the middle half of the bar, the
// mean stretches and stress of its particles against (l1, l2, sigma_xx). The
// exact motion X + r(t) (F - I) X is exact at rest and from the end of the
// ramp on; in between the load, not the stretch, follows the ramp, so errors
// mean something at the end.
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
  // The ring's material: c = sqrt(E' / rho) = 1.05 m/s, the lowest mode of
  // the bar on its support has a period of 4 L / c = 3.8 s; four periods of
  // ramp, four to settle.
  std::vector<KeySpec> k = solver_keys(32, 32.0, {32.0});
  for (KeySpec& spec : k)
    if (spec.name == "cells") spec.help = "cells along the bar's length";
  const std::vector<KeySpec> own = {
      {"stretch", KeyKind::real, 1.5, "l1, the axial stretch of the static state (1.5: 50 % tension; 0.5: 50 % "
                                      "compression)",
       0.2, 3.0},
      {"length", KeyKind::real, 1.0, "L, the bar's length [m]", 0.0, inf, true},
      {"height", KeyKind::real, 0.25, "H, the bar's full height [m]; the scene holds its upper half", 0.0, inf, true},
      {"probe_points", KeyKind::integer, std::int64_t(21), "material points on the probe line", 2, 100000},
  };
  return static_scene_keys(std::move(k), own, material_keys("neo-hookean", 577.0, 385.0, 1000.0));
}

SceneSetup setup(const Config& c) {
  SceneSetup s;
  s.material = material_from(c);
  const auto* neo = std::get_if<NeoHookean>(&s.material);
  if (!neo) c.reject("material", "the finite-strain bar's exact solution is for the neo-hookean material");
  s.geometry = Geometry::plane_strain;
  s.force_free = true;
  const double L = c.real("length"), half = 0.5 * c.real("height"), l1 = c.real("stretch");
  if (std::abs(l1 - 1.0) < 1e-6) c.reject("stretch", "must differ from 1");
  const analytic::NeoHookeanBar::State exact = analytic::NeoHookeanBar{neo->lambda, neo->mu}.plane_strain(l1);
  const double l2 = exact.lateral_stretch, sigma = exact.axial_stress;
  const double nominal = sigma * l2;  // force per unit reference height
  const Lame lame = small_strain_lame(s.material);
  const double density = c.real("density");
  // Lowest mode, support to free end: omega = pi c / (2 L).
  const double omega = 0.5 * std::numbers::pi * std::sqrt(lame.plane_strain_modulus() / density) / L;
  const QuasiStatic qs = quasi_static_from(c, omega, lame.mu, s);

  Mat2 D = Mat2::Zero();
  D(0, 0) = l1 - 1.0;
  D(1, 1) = l2 - 1.0;
  s.solution = mms::make_solution(analytic::RampedHomogeneousMotion{D, qs.ramp_time, L}, s.material, density,
                                  s.geometry);

  const int cells = int(c.integer("cells"));
  const double h = L / cells;
  const int ppd = int(c.integer("particles_per_direction"));
  const double spacing = h / ppd;
  s.grid = GridGeometry::walled(Vec2::Zero(), h, int(std::ceil(std::max(1.0, l1) * cells)) + 4,
                                int(std::ceil(std::max(1.0, l2) * half / h)) + 4);
  s.body_is_rectangle(Vec2::Zero(), Vec2(L, half));
  const bool platen = l1 < 1.0;
  s.loading = platen ? fmt::format("rigid platen moved from x = L to {} L, frictionless contact, grid damping", l1)
                     : fmt::format("dead load {:.9g} N/m per unit reference height on the end x = L, grid damping",
                                   nominal);
  const double ramp_time = qs.ramp_time, damping = qs.damping;
  s.stages = [=](const Particles& P, const GridGeometry&) {
    if (platen) {
      SceneStages stages;
      RigidBody plate;
      plate.kind = RigidBody::Kind::half_plane;
      plate.point = Vec2(L, 0.0);
      plate.outward = Vec2(-1.0, 0.0);
      plate.displacement = [=](double t) { return Vec2((l1 - 1.0) * L * analytic::ramp(t, ramp_time), 0.0); };
      stages.contact = plate;
      stages.damping = damping;
      return stages;
    }
    // The last sub-column of particles carries the end: each its share of
    // the height, its reference area over the sub-cell width.
    std::vector<std::size_t> loaded;
    std::vector<double> face;
    for (std::size_t p = 0; p < P.size(); ++p)
      if (P.reference_position[p].x() > L - spacing) {
        loaded.push_back(p);
        face.push_back(P.reference_volume[p] / spacing);
      }
    SceneStages stages;
    stages.body_force = std::make_shared<SurfaceTraction>(
        std::move(loaded), std::move(face), Vec2(1.0, 0.0),
        [nominal, ramp_time](double t) { return nominal * analytic::ramp(t, ramp_time); });
    stages.damping = damping;
    return stages;
  };

  add_bar_probes(s, L, half, int(c.integer("probe_points")));

  auto middle = [L](const Vec2& X) { return X.x() >= 0.25 * L && X.x() <= 0.75 * L; };
  s.extra_error_names = {"error_axial_stretch", "error_lateral_stretch", "error_axial_stress"};
  s.extra_errors = [=](double, const RunRecord& record) {
    const Stepper& stepper = record.stepper;
    const RegionMeans m = region_means(stepper.model().particles, middle);
    return std::vector<double>{relative_error(m.deformation_gradient(0, 0) - 1.0, l1 - 1.0),
                               relative_error(m.deformation_gradient(1, 1) - 1.0, l2 - 1.0),
                               relative_error(m.stress(0, 0), sigma)};
  };
  s.measure = [=](const RunRecord& record) -> Measurements {
    const RegionMeans m = region_means(record.stepper.model().particles, middle);
    return {{"axial_stretch", m.deformation_gradient(0, 0)},
            {"axial_stretch_exact", l1},
            {"lateral_stretch", m.deformation_gradient(1, 1)},
            {"lateral_stretch_exact", l2},
            {"lateral_strain_error", relative_error(m.deformation_gradient(1, 1) - 1.0, l2 - 1.0)},
            {"axial_stress", m.stress(0, 0)},
            {"axial_stress_exact", sigma},
            {"axial_stress_error", relative_error(m.stress(0, 0), sigma)},
            {"nominal_traction", nominal},
            {"platen_nominal_traction", platen ? record.stepper.contact_forces().total.x() / half : 0.0},
            {"root_iterations", double(exact.iterations)},
            {"middle_particles", double(m.particles)}};
  };
  return s;
}

}  // namespace

SceneType neo_hookean_bar_scene() {
  return {"neo-hookean-bar",
          "neo-Hookean bar under a dead load to a stretch of 1.5 (or 0.5), plane strain, against the exact "
          "homogeneous state (PROBLEMS.md section 5)",
          keys, setup};
}

}  // namespace mpmvv::app
