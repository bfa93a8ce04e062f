// The pulsating cylinder in r-z (PROBLEMS.md section 2b): the solver's
// axisymmetric mode on the body R_i <= R <= R_o, 0 <= Z <= H, with roller
// walls on the axis and at Z = 0 and Z = H. Probes: a radial line at Z = H/4
// and an axial line at R = (R_i + R_o)/2 read the radial displacement; a point
// on their crossing its history.
#include <cmath>

#include <fmt/format.h>

#include "mms/rz_cylinder.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

namespace {

constexpr const char* kClosedForm = "mms/rz_cylinder.hpp";

std::vector<KeySpec> keys() {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<KeySpec> k = solver_keys(32, 1.0, {0.25, 0.5, 0.75, 1.0});
  const std::vector<KeySpec> own = {
      force_quadrature_key(),
      body_force_key(kClosedForm),
      {"amplitude", KeyKind::real, 0.2, "A: the largest of g(t) = (A/2)(1 - cos 2 pi t / T)", 0.0, 1.0, true},
      {"inner_radius", KeyKind::real, 0.25, "R_i [m]; 0 for a solid cylinder with particles up to the axis", 0.0, inf},
      {"outer_radius", KeyKind::real, 1.0, "R_o [m]", 0.0, inf, true},
      {"height", KeyKind::real, 1.0, "H [m]", 0.0, inf, true},
      {"period", KeyKind::real, 1.0, "T, the period of g [s]", 0.0, inf, true},
      {"probe_points", KeyKind::integer, std::int64_t(51), "material points on each probe line", 2, 100000},
  };
  return scene_keys(std::move(k), own, material_keys("neo-hookean", 577.0, 385.0, 1000.0));
}

SceneSetup setup(const Config& c) {
  SceneSetup s;
  s.material = material_from(c);
  s.geometry = Geometry::axisymmetric;
  const mms::RzCylinderMotion motion{c.real("inner_radius"), c.real("outer_radius"), c.real("height"),
                                     c.real("amplitude"), c.real("period")};
  const double ri = motion.inner_radius, ro = motion.outer_radius, H = motion.height;
  if (!(ro > ri))
    c.reject("outer_radius", fmt::format("must exceed inner_radius = {} (from {})", ri, c.origin("inner_radius").source));
  s.solution = mms::make_solution(motion, s.material, c.real("density"), s.geometry);
  if (const NeoHookean* solid = closed_form_force(c, s.material, kClosedForm))
    s.fast_body_force = std::make_shared<mms::RzCylinderClosedFormField>(motion, *solid, c.real("density"));

  const int cells = int(c.integer("cells"));
  const double h = H / cells;  // cells along the height
  // The largest radius the body reaches, R (1 + A q(R)), plus two cells.
  double reach = 0.0;
  for (int i = 0; i <= 200; ++i) {
    const double R = ri + (ro - ri) * i / 200.0;
    reach = std::max(reach, R * (1.0 + motion.amplitude * motion.q(R)));
  }
  // Walls on the axis, at Z = 0 and H, and two cells past the reach.
  s.grid = GridGeometry::walled(Vec2::Zero(), h, int(std::ceil((reach + 2.0 * h) / h)), cells);
  if (ro - ri < h)
    c.reject("cells", fmt::format("the wall is {} m thick but a cell is {:.4g} m: use more cells", ro - ri, h));
  s.body_is_rectangle(Vec2(ri, 0.0), Vec2(ro, H));

  const int n = int(c.integer("probe_points"));
  const double middle = 0.5 * (ri + ro);
  ProbeLine radial{"line_z_quarter", ProbeQuantity::displacement_x, "reference_r", {}, {}, std::nullopt};
  radial.reference = points_on_segment(Vec2(ri, 0.25 * H), Vec2(ro, 0.25 * H), n);
  for (const Vec2& X : radial.reference) radial.parameter.push_back(X.x());
  s.lines.push_back(std::move(radial));
  ProbeLine axial{"line_r_mid", ProbeQuantity::displacement_x, "reference_z", {}, {}, std::nullopt};
  axial.reference = points_on_segment(Vec2(middle, 0.0), Vec2(middle, H), n);
  for (const Vec2& X : axial.reference) axial.parameter.push_back(X.y());
  s.lines.push_back(std::move(axial));
  s.points.push_back({"point_mid", ProbeQuantity::displacement_x, Vec2(middle, 0.25 * H)});
  return s;
}

}  // namespace

SceneType rz_cylinder_scene() {
  return {"rz-cylinder", "pulsating cylinder in r-z, hoop terms (PROBLEMS.md section 2b)", keys, setup};
}

}  // namespace mpmvv::app
