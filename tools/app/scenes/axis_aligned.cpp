// The axis-aligned MMS (PROBLEMS.md section 3) on the unit square, or in 1D on
// a strip in uniaxial strain, with roller walls on the body's boundary (the
// motion is tangential there). Probes: the mid-lines read the displacement
// along them; a point at (L/4, L/4) its history.
#include <cmath>

#include <fmt/format.h>

#include "mms/axis_aligned.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

namespace {

constexpr const char* kClosedForm = "mms/axis_aligned.hpp";

std::vector<KeySpec> keys() {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<KeySpec> k = solver_keys(32, 0.02, {0.005, 0.01, 0.015, 0.02});
  const std::vector<KeySpec> own = {
      force_quadrature_key(),
      body_force_key(kClosedForm),
      {"variant", KeyKind::text, std::string("2d"),
       "2d: the unit square; 1d: u = A sin(2 pi X / L) cos(c pi t / L) on a strip in uniaxial strain", -inf, inf,
       false, false, {"2d", "1d"}},
      {"amplitude", KeyKind::real, 0.05, "A [m]", 0.0, inf, true},
      {"length", KeyKind::real, 1.0, "L, the side of the square or the length of the strip [m]", 0.0, inf, true},
      {"probe_points", KeyKind::integer, std::int64_t(51), "material points on each probe line", 2, 100000},
  };
  // mu = 3846.15 Pa and K = 8333.33 Pa (lambda = K - 2 mu / 3), rho_0 = 1: E = 1e4 Pa, c = 100 m/s.
  return scene_keys(std::move(k), own, material_keys("neo-hookean", 5769.23, 3846.15, 1.0));
}

// Young's modulus of the chosen material at small strain.
double youngs_modulus(const MaterialModel& m) {
  if (const auto* mr = std::get_if<MooneyRivlin>(&m)) {
    const double G = mr->shear_modulus(), K = mr->bulk_modulus;
    return 9.0 * K * G / (3.0 * K + G);
  }
  const double lambda = std::visit([](const auto& x) {
    if constexpr (requires { x.lambda; }) return x.lambda;
    else return 0.0;
  }, m);
  const double mu = std::visit([](const auto& x) {
    if constexpr (requires { x.mu; }) return x.mu;
    else return 0.0;
  }, m);
  return mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
}

SceneSetup setup(const Config& c) {
  SceneSetup s;
  s.material = material_from(c);
  s.geometry = Geometry::plane_strain;
  const double L = c.real("length");
  const bool one_d = c.text("variant") == "1d";
  const double E = youngs_modulus(s.material);
  if (!(E > 0.0)) c.reject("lambda", "the material's Young's modulus must be positive");
  mms::AxisAlignedMotion motion{c.real("amplitude"), std::sqrt(E / c.real("density")), L, one_d};
  if (!(motion.amplitude < 0.25 * L))
    c.reject("amplitude", fmt::format("must stay below L / 4 = {} so that the square keeps its shape", 0.25 * L));
  s.solution = mms::make_solution(motion, s.material, c.real("density"), s.geometry);
  if (const NeoHookean* solid = closed_form_force(c, s.material, kClosedForm))
    s.fast_body_force = std::make_shared<mms::AxisAlignedClosedFormField>(motion, *solid, c.real("density"));

  const int cells = int(c.integer("cells"));
  // The strip is two cells high, walls above and below. The body's extent is
  // L (not a sum of cells, which rounds) so that probes on its sides belong to it.
  s.grid = GridGeometry::walled(Vec2::Zero(), L / cells, cells, one_d ? 2 : cells);
  const double height = one_d ? 2.0 * L / cells : L;
  s.body_is_rectangle(Vec2::Zero(), Vec2(L, height));

  const int n = int(c.integer("probe_points"));
  const double middle_y = 0.5 * height;
  ProbeLine along_x{"line_y_mid", ProbeQuantity::displacement_x, "reference_x", {}, {}, std::nullopt};
  along_x.reference = points_on_segment(Vec2(0.0, middle_y), Vec2(L, middle_y), n);
  for (const Vec2& X : along_x.reference) along_x.parameter.push_back(X.x());
  s.lines.push_back(std::move(along_x));
  if (!one_d) {
    ProbeLine along_y{"line_x_mid", ProbeQuantity::displacement_y, "reference_y", {}, {}, std::nullopt};
    along_y.reference = points_on_segment(Vec2(0.5 * L, 0.0), Vec2(0.5 * L, L), n);
    for (const Vec2& X : along_y.reference) along_y.parameter.push_back(X.y());
    s.lines.push_back(std::move(along_y));
  }
  s.points.push_back({"point_quarter", ProbeQuantity::displacement_x, Vec2(0.25 * L, one_d ? middle_y : 0.25 * L)});
  return s;
}

}  // namespace

SceneType axis_aligned_scene() {
  return {"axis-aligned", "axis-aligned small-deformation MMS on the unit square or a 1D strip (PROBLEMS.md section 3)",
          keys, setup};
}

}  // namespace mpmvv::app
