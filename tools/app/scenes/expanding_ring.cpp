// The expanding ring (PROBLEMS.md section 2a) in plane strain on a square
// domain with roller walls. Probes: the lines Theta = 0, +45, -45 degrees and
// the point (r_b, 0) read the radial displacement; the circle r_b gives the
// angular spectrum of the error (the motion is axisymmetric).
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "mms/expanding_ring.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

namespace {

constexpr const char* kClosedForm = "mms/expanding_ring.hpp";

using std::numbers::pi;

std::vector<KeySpec> keys() {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<KeySpec> k = solver_keys(64, 0.02, {0.005, 0.01, 0.015, 0.02});
  const std::vector<KeySpec> own = {
      force_quadrature_key(),
      body_force_key(kClosedForm),
      {"amplitude", KeyKind::real, 0.1, "A of u = A sin(C pi t / (2 r_b)) (c1 + c2 R + c3 R^2) X", 0.0, 1.0, true},
      {"inner_radius", KeyKind::real, 0.4, "r_i [m]", 0.0, inf, true},
      {"outer_radius", KeyKind::real, 0.6, "r_o [m]", 0.0, inf, true},
      {"domain", KeyKind::real, 2.0, "width of the square domain centred on the ring [m]", 0.0, inf, true},
      {"probe_points", KeyKind::integer, std::int64_t(51), "material points on each probe line", 2, 100000},
      {"circle_points", KeyKind::integer, std::int64_t(128),
       "material points on the circle R = r_b for the angular spectrum", 8, 65536},
      {"profile", KeyKind::text, std::string("uintah"),
       "uintah: c1 + c2 R + c3 R^2 (rims free of traction, not of hoop stress); bubble: 16 ((R - r_i)(r_o - "
       "R))^2 / (r_o - r_i)^4 (rims free of all stress: the control case)",
       -inf, inf, false, false, {"uintah", "bubble"}},
  };
  // E = 1e7 Pa, nu = 0: lambda = 0, mu = E / 2; rho_0 = 1000.
  return scene_keys(std::move(k), own, material_keys("neo-hookean", 0.0, 5e6, 1000.0));
}

SceneSetup setup(const Config& c) {
  SceneSetup s;
  s.material = material_from(c);
  s.geometry = Geometry::plane_strain;
  const double ri = c.real("inner_radius"), ro = c.real("outer_radius");
  if (!(ro > ri))
    c.reject("outer_radius", fmt::format("must exceed inner_radius = {} (from {})", ri, c.origin("inner_radius").source));
  if (!(ro < 3.0 * ri))
    c.reject("outer_radius", fmt::format("the motion's c1, c2, c3 need r_o < 3 r_i = {}", 3.0 * ri));
  // C = sqrt(E / rho_0) with E from the small-strain moduli.
  const double E = std::visit(
      [](const auto& m) {
        if constexpr (requires { m.lambda; }) return m.mu * (3.0 * m.lambda + 2.0 * m.mu) / (m.lambda + m.mu);
        else return 9.0 * m.bulk_modulus * m.shear_modulus() / (3.0 * m.bulk_modulus + m.shear_modulus());
      },
      s.material);
  const mms::ExpandingRingMotion motion{ri, ro, c.real("amplitude"), std::sqrt(E / c.real("density")),
                                       c.text("profile") == "bubble"};
  s.solution = mms::make_solution(motion, s.material, c.real("density"), s.geometry);
  if (const NeoHookean* solid = closed_form_force(c, s.material, kClosedForm))
    s.fast_body_force = std::make_shared<mms::ExpandingRingClosedFormField>(motion, *solid, c.real("density"));

  const double domain = c.real("domain");
  const int cells = int(c.integer("cells"));
  s.grid = GridGeometry::walled(Vec2(-0.5 * domain, -0.5 * domain), domain / cells, cells, cells);
  // The largest radius the ring reaches, |1 + A f(R)| R over the ring.
  double reach = 0.0;
  for (int i = 0; i <= 100; ++i) {
    const double R = ri + (ro - ri) * i / 100.0;
    reach = std::max(reach, R * (1.0 + motion.amplitude * std::abs(motion.profile(R))));
  }
  require_two_cells_clearance(c, fmt::format("the ring, reaching r = {:.4g} m,", reach), reach, domain, cells);
  if (ro - ri < s.grid.h)
    c.reject("cells", fmt::format("the ring is {} m wide but a cell is {:.4g} m: use more cells", ro - ri, s.grid.h));
  s.body_is_annulus(ri, ro);
  const int n = int(c.integer("probe_points"));
  const double angles[3] = {0.0, pi / 4.0, -pi / 4.0};
  const char* names[3] = {"theta0", "theta_plus45", "theta_minus45"};
  for (int k = 0; k < 3; ++k) {
    const Vec2 direction(std::cos(angles[k]), std::sin(angles[k]));
    ProbeLine line{names[k], ProbeQuantity::radial_displacement, "reference_radius", {}, {}, angles[k]};
    line.reference = points_on_segment(ri * direction, ro * direction, n);
    for (const Vec2& X : line.reference) line.parameter.push_back(X.norm());
    s.lines.push_back(std::move(line));
  }
  s.points.push_back({"point_rb", ProbeQuantity::radial_displacement, Vec2(motion.mean_radius(), 0.0)});
  s.circle = ProbeCircle{ProbeQuantity::radial_displacement, motion.mean_radius(), int(c.integer("circle_points"))};
  return s;
}

}  // namespace

SceneType expanding_ring_scene() {
  return {"expanding-ring", "expanding ring in plane strain, radial motion (PROBLEMS.md section 2a)", keys, setup};
}

}  // namespace mpmvv::app
