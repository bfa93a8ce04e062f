// A manufactured solution the user writes in the scene file: the displacement
// u(X, Y, t) as two formulas (mms/expression.hpp) with named parameters, on
// the rectangle [0, W] x [0, H], in any of the materials; its body force and
// exact fields are derived by automatic differentiation (mms/manufactured.hpp)
// and `mpmvv mms check user-motion` checks them by finite differences. The
// default is the axis-aligned problem (PROBLEMS.md section 3) written as
// formulas: the same solution as the scene axis-aligned, for comparison.
//
// In r-z (geometry = "rz") the same on the rectangle [R_0, R_0 + W] x [0, H]
// of (R, Z), the formulas u_r, u_z of R, Z, t, the hoop stretch r / R; with
// R_0 = 0 its left side is the axis, where the motion must keep u_r = 0.
//
// The rectangle's sides are roller walls (boundary = "walls": the grid's
// walls lie on them, and the motion must keep u . n = 0 and carry no shear
// traction there), free (boundary = "free": the motion's traction P N must
// vanish there) or loaded (boundary = "traction": they carry the motion's
// nominal traction P N, applied by the solver on the sides of the boundary
// particles' domains, solver/traction.hpp; any motion, plane strain). The
// scene checks the motion against walls and free sides before anything
// runs, at 21 points of each side and 8 times up to end_time, and refuses
// one that breaks them: that motion needs boundary = "traction".
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "mms/expression_motion.hpp"
#include "tools/app/scene/exact_traction.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

namespace {

std::vector<KeySpec> keys() {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<KeySpec> k = solver_keys(32, 0.02, {0.005, 0.01, 0.015, 0.02});
  const std::vector<KeySpec> own = {
      force_quadrature_key(),
      {"displacement_x", KeyKind::text, std::string("A * sin(pi * X / L) * sin(c * pi * t / L)"),
       "u_x(X, Y, t) [m]: a formula of X, Y [m], t [s], pi and the parameters, with + - * / ^ (a constant exponent), "
       "sin cos tan exp log sqrt",
       -inf, inf},
      {"displacement_y", KeyKind::text, std::string("A * sin(pi * Y / L) * sin(pi * (2 / 3 + c * t / L))"),
       "u_y(X, Y, t) [m], as displacement_x", -inf, inf},
      {"parameters", KeyKind::text, std::string("A = 0.05, c = 100, L = 1"),
       "the formulas' named constants, \"name = value, ...\"; a value may be a formula of the names before it", -inf,
       inf},
      {"geometry", KeyKind::text, std::string("plane-strain"),
       "plane-strain: u(X, Y, t) on [0, W] x [0, H]; rz: the solver's axisymmetric mode, u_r and u_z as formulas of "
       "R, Z, t on [inner_radius, inner_radius + W] x [0, H] (the hoop stretch r / R)",
       -inf, inf, false, false, {"plane-strain", "rz"}},
      {"inner_radius", KeyKind::real, 0.0,
       "rz: R_0, the rectangle's inner side [m]; 0: the body reaches the axis, where u_r must vanish", 0.0, inf},
      {"width", KeyKind::real, 1.0, "W, the rectangle's side along X (R in r-z) [m]", 0.0, inf, true},
      {"height", KeyKind::real, 1.0, "H, its side along Y [m]; a whole number of cells of W / cells", 0.0, inf, true},
      {"boundary", KeyKind::text, std::string("walls"),
       "walls: roller walls on the rectangle's sides (u . n = 0 and no shear traction there); free: traction-free "
       "sides (P N = 0), the grid two cells and the motion's reach beyond them; traction: the sides carry the "
       "motion's nominal traction P N, a force on each boundary particle's domain side (solver/traction.hpp; "
       "plane strain; the grid as for free)",
       -inf, inf, false, false, {"walls", "free", "traction"}},
      {"time_scale", KeyKind::real, 0.01,
       "the time over which the motion varies [s] (for the default L / c): the finite-difference check's steps", 0.0,
       inf, true},
      {"probe_points", KeyKind::integer, std::int64_t(51), "material points on each probe line", 2, 100000},
  };
  // The axis-aligned problem's solid: E = 1e4 Pa, rho_0 = 1, c = 100 m/s.
  return scene_keys(std::move(k), own, material_keys("neo-hookean", 5769.23, 3846.15, 1.0));
}

// "name = value, ..." in order; each value a formula of the names before it.
std::map<std::string, double> read_parameters(const Config& c) {
  std::map<std::string, double> parameters;
  std::stringstream list(c.text("parameters"));
  std::string item;
  while (std::getline(list, item, ',')) {
    const std::size_t equals = item.find('=');
    auto trim = [](std::string s) {
      s.erase(0, s.find_first_not_of(" \t"));
      s.erase(s.find_last_not_of(" \t") + 1);
      return s;
    };
    const std::string name = trim(item.substr(0, equals));
    if (equals == std::string::npos || name.empty())
      c.reject("parameters", fmt::format("'{}' is not 'name = value'", trim(item)));
    if (!(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_') ||
        !std::all_of(name.begin(), name.end(), [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; }))
      c.reject("parameters", fmt::format("'{}' is not a name (letters, digits, _)", name));
    if (name == "X" || name == "Y" || name == "R" || name == "Z" || name == "t" || mms::Expression::reserved(name))
      c.reject("parameters", fmt::format("'{}' is a coordinate, time, pi or a function", name));
    if (parameters.count(name)) c.reject("parameters", fmt::format("'{}' is given twice", name));
    try {
      const mms::Expression value(item.substr(equals + 1), {"", "", ""}, parameters);
      parameters[name] = value(0.0, 0.0, 0.0);
    } catch (const mms::ExpressionError& e) {
      c.reject("parameters", fmt::format("the value of '{}': {}", name, e.what()));
    }
    if (!std::isfinite(parameters[name])) c.reject("parameters", fmt::format("'{}' is not a finite number", name));
  }
  return parameters;
}

mms::Expression read_formula(const Config& c, const std::string& key, const std::map<std::string, double>& parameters,
                             bool rz) {
  try {
    return rz ? mms::Expression(c.text(key), {"R", "Z", "t"}, parameters)
              : mms::Expression(c.text(key), {"X", "Y", "t"}, parameters);
  } catch (const mms::ExpressionError& e) {
    c.reject(key, fmt::format("{}{}", e.what(), rz ? " (in r-z the formulas are of R, Z and t)" : ""));
  }
}

// The motion against the rectangle's boundary, at 21 points of each side and 8
// times in (0, end_time]: with walls u . n = 0 and (P N) . s = 0, free P N = 0,
// each to 1e-8 of the largest |u| and |P - P(I)| in the body; on the
// axis (r-z, R_0 = 0) u_r = 0 whatever the boundary; the first point that
// breaks it makes runs refuse the setup. Returns the largest |u| (the motion's
// reach).
double check_boundary(const Config& c, SceneSetup& setup, double R0, double W, double H, bool walls, bool axis,
                      bool loaded) {
  const mms::ExactSolution& solution = *setup.solution;
  struct Sample {
    Vec2 X, normal;
    double t, u_normal, traction;
    bool on_axis;
  };
  std::vector<Sample> samples;
  const double end = c.real("end_time");
  double reach = 0.0, stress = 0.0;
  const Mat2 rest = solution.state(Vec2(R0 + 0.5 * W, 0.5 * H), 0.0).first_piola;
  for (int side = 0; side < 4; ++side)
    for (int k = 0; k <= 20; ++k)
      for (int m = 1; m <= 8; ++m) {
        const double s = k / 20.0;
        Vec2 X = Vec2(R0, 0.0) + (side == 0   ? Vec2(s * W, 0.0)
                                  : side == 1 ? Vec2(W, s * H)
                                  : side == 2 ? Vec2(s * W, H)
                                              : Vec2(0.0, s * H));
        const bool on_axis = axis && X.x() == 0.0;  // the left side and the corners on it
        if (on_axis && side != 3) continue;         // the corners are the left side's ends
        if (on_axis) X.x() = 1e-9 * W;             // the hoop stretch r / R is 0 / 0 on the axis itself
        const Vec2 n = side == 0 ? Vec2(0.0, -1.0) : side == 1 ? Vec2(1.0, 0.0) : side == 2 ? Vec2(0.0, 1.0) : Vec2(-1.0, 0.0);
        const double t = end * m / 8.0;
        const mms::ExactFields f = solution.state(X, t);
        const Vec2 traction = f.first_piola * n;
        const Vec2 tangent(-n.y(), n.x());
        reach = std::max(reach, f.displacement.norm());
        stress = std::max(stress, (f.first_piola - rest).cwiseAbs().maxCoeff());
        samples.push_back({X, n, t, f.displacement.dot(n), walls || on_axis ? traction.dot(tangent) : traction.norm(),
                           on_axis});
      }
  // The scales the boundary's values are judged against: the largest |u| and
  // |P - P(I)| over the body (an 11 x 11 lattice inside it at the same times)
  // as well as its boundary, so that a motion that vanishes on the boundary
  // is not held to its own round-off there.
  double body_reach = reach, body_stress = stress;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j)
      for (int m = 1; m <= 8; ++m) {
        const Vec2 X = Vec2(R0, 0.0) + Vec2(W * (0.05 + 0.09 * i), H * (0.05 + 0.09 * j));
        const mms::ExactFields f = solution.state(X, end * m / 8.0);
        if (!(f.displacement.allFinite() && f.first_piola.allFinite())) continue;  // named below, on the boundary
        body_reach = std::max(body_reach, f.displacement.norm());
        body_stress = std::max(body_stress, (f.first_piola - rest).cwiseAbs().maxCoeff());
      }
  // A motion that moves the axis has a hoop stretch 1 + u_r / R that is no
  // number near it: the axis is checked, and named, first.
  std::stable_partition(samples.begin(), samples.end(), [](const Sample& s) { return s.on_axis; });
  for (const Sample& s : samples) {
    const bool moves_axis = s.on_axis && !(std::abs(s.u_normal) <= 1e-8 * body_reach);
    if (!moves_axis && !(std::isfinite(s.u_normal) && std::isfinite(s.traction)))
      c.reject("displacement_x", fmt::format("the motion is not a number at X = ({:.4g}, {:.4g}), t = {:.4g}", s.X.x(),
                                             s.X.y(), s.t));
    if (setup.run_refused) break;
    if (loaded) continue;  // the sides carry whatever traction the motion has
    if (moves_axis || (walls && std::abs(s.u_normal) > 1e-8 * body_reach))
      setup.run_refused = {"boundary", fmt::format("the motion crosses {}: at X = ({:.4g}, {:.4g}), t = {:.4g} its u . n "
                                       "= {:.3g} m (largest |u| in the body {:.3g} m); {}",
                                       s.on_axis ? "the axis" : "a roller wall", s.X.x(), s.X.y(), s.t, s.u_normal,
                                       body_reach, s.on_axis ? "the axis needs u_r = 0" : "walls need u . n = 0")};
    else if (std::abs(s.traction) > 1e-8 * body_stress && !(s.on_axis && !walls))
      setup.run_refused = {"boundary",
               fmt::format("the motion carries {} at X = ({:.4g}, {:.4g}), t = {:.4g}: {:.3g} Pa (the largest change of P over the "
                           "body and the run {:.3g} Pa); {}: boundary = \"traction\" applies it",
                           walls ? "a shear traction on a roller wall" : "a traction on a free side", s.X.x(), s.X.y(),
                           s.t, s.traction, body_stress,
                           walls ? "walls need (P N) . s = 0" : "free sides need P N = 0")};
  }
  return reach;
}

SceneSetup setup(const Config& c) {
  SceneSetup s;
  s.material = material_from(c);
  const bool rz = c.text("geometry") == "rz";
  s.geometry = rz ? Geometry::axisymmetric : Geometry::plane_strain;
  const double W = c.real("width"), H = c.real("height"), R0 = c.real("inner_radius");
  if (!rz && R0 != 0.0) c.reject("inner_radius", "is the inner side of the r-z rectangle: set geometry = \"rz\"");
  const std::map<std::string, double> parameters = read_parameters(c);
  mms::ExpressionMotion motion{read_formula(c, "displacement_x", parameters, rz),
                               read_formula(c, "displacement_y", parameters, rz), std::max(W, H), c.real("time_scale")};
  s.solution = mms::make_solution(motion, s.material, c.real("density"), s.geometry);
  const bool walls = c.text("boundary") == "walls", loaded = c.text("boundary") == "traction";
  const bool axis = rz && R0 == 0.0;  // the left side is the axis
  if (loaded && rz) c.reject("boundary", "traction is plane strain only (set geometry = \"plane-strain\")");
  const double reach = check_boundary(c, s, R0, W, H, walls, axis, loaded);

  const int cells = int(c.integer("cells"));
  const double h = W / cells;
  const double rows = H / h;
  if (walls && std::abs(rows - std::round(rows)) > 1e-9 * rows)
    c.reject("height", fmt::format("with walls must be a whole number of cells (W / cells = {:.6g} m): it is {:.6g} of them",
                                   h, rows));
  if (walls) {
    s.grid = GridGeometry::walled(Vec2(R0, 0.0), h, cells, int(std::round(rows)));
  } else {
    // Free sides: the grid two cells and the motion's reach beyond them; in r-z
    // not past the axis, which is a wall (the grid's r >= 0).
    const int margin = int(std::ceil(reach / h)) + 2;
    const int left = rz ? std::min(margin, int(std::floor(R0 / h + 1e-9))) : margin;
    s.grid = GridGeometry::walled(Vec2(R0 - left * h, -margin * h), h, cells + left + margin,
                                  int(std::ceil(rows - 1e-9)) + 2 * margin);
  }
  s.body_is_rectangle(Vec2(R0, 0.0), Vec2(R0 + W, H));
  if (loaded) {
    // The lattice's half spacing: the domains of methods without one (linear).
    const Vec2 half = Vec2::Constant(0.5 * h / double(c.integer("particles_per_direction")));
    s.stages = [solution = s.solution, W, H, half](const Particles& P, const GridGeometry&) {
      SceneStages stages;
      stages.traction = exact_rectangle_traction(solution, Vec2::Zero(), Vec2(W, H), P, half);
      return stages;
    };
    s.loading = "the motion's nominal traction P N on the rectangle's sides (boundary = \"traction\")";
  }

  const int n = int(c.integer("probe_points"));
  ProbeLine along_x{"line_y_mid", ProbeQuantity::displacement_x, "reference_x", {}, {}, std::nullopt};
  along_x.reference = points_on_segment(Vec2(R0, 0.5 * H), Vec2(R0 + W, 0.5 * H), n);
  for (const Vec2& X : along_x.reference) along_x.parameter.push_back(X.x());
  s.lines.push_back(std::move(along_x));
  ProbeLine along_y{"line_x_mid", ProbeQuantity::displacement_y, "reference_y", {}, {}, std::nullopt};
  along_y.reference = points_on_segment(Vec2(R0 + 0.5 * W, 0.0), Vec2(R0 + 0.5 * W, H), n);
  for (const Vec2& X : along_y.reference) along_y.parameter.push_back(X.y());
  s.lines.push_back(std::move(along_y));
  s.points.push_back({"point_quarter", ProbeQuantity::displacement_x, Vec2(R0 + 0.25 * W, 0.25 * H)});
  return s;
}

}  // namespace

SceneType user_motion_scene() {
  return {"user-motion",
          "a manufactured solution written in the scene file: u(X, Y, t) as formulas on a rectangle, its force derived",
          keys, setup};
}

}  // namespace mpmvv::app
