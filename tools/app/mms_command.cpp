#include "mms_command.hpp"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <random>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "json.hpp"
#include "scene/setup.hpp"

namespace mpmvv::app {

// The scene's configuration with its defaults and the overrides; throws ConfigError.
const SceneType& scene_named(const std::string& name) {
  const SceneType* p = find_scene_type(name);
  if (!p) {
    std::string names;
    for (const SceneType& q : scene_types()) names += (names.empty() ? "" : ", ") + q.name;
    throw ConfigError(fmt::format("unknown manufactured solution '{}' (known: {})", name, names));
  }
  return *p;
}

SceneSetup setup_for(const SceneType& scene, const std::vector<std::string>& overrides, const std::string& how) {
  Config config(scene.name, scene.keys());
  for (const std::string& o : overrides) config.set_from_text(o, how);
  return scene.setup(config);
}

std::vector<KeySpec> solution_parameters(const SceneType& scene) {
  // The solver's keys (solver_keys: method, resolution, time, health) and
  // the keys of how a run samples and bounds the body belong to runs, not to
  // the solution.
  std::vector<std::string> run_only = {"probe_points", "circle_points", "seeding", "body_force_quadrature", "domain",
                                       "rims"};
  for (const KeySpec& k : solver_keys(1, 1.0, {1.0})) run_only.push_back(k.name);
  std::vector<KeySpec> keys;
  for (const KeySpec& k : scene.keys())
    if (std::find(run_only.begin(), run_only.end(), k.name) == run_only.end()) keys.push_back(k);
  return keys;
}

namespace {

Json json_of(const Vec2& v) { return {v.x(), v.y()}; }
Json json_of(const Mat2& m) { return {{m(0, 0), m(0, 1)}, {m(1, 0), m(1, 1)}}; }

}  // namespace

// The scenes whose exact solution moves under a manufactured body force,
// with their parameters; then, by name, the scenes whose exact solution needs
// none (eval and check take those too; `mpmvv scenes` lists every scene).
std::string mms_list() {
  std::string s, exact_only;
  for (const SceneType& p : scene_types()) {
    if (setup_for(p, {}).force_free) {
      exact_only += (exact_only.empty() ? "" : ", ") + p.name;
      continue;
    }
    s += fmt::format("{}: {}\n", p.name, p.summary);
    for (const KeySpec& k : solution_parameters(p))
      s += fmt::format("  {:<16} default {:<14} {}\n", k.name, format_value(k.default_value), k.help);
  }
  if (!exact_only.empty())
    s += fmt::format("exact solutions without a manufactured force (mms eval and mms check take them too; "
                     "mpmvv scenes lists every scene): {}\n",
                     exact_only);
  return s;
}

int mms_eval(const MmsEvalRequest& r, std::ostream& out, std::ostream& err) {
  SceneSetup setup;
  try {
    const SceneType& scene = scene_named(r.name);
    if (r.at.size() != 2) throw ConfigError("--at takes two coordinates, X,Y (R,Z in r-z)");
    setup = setup_for(scene, r.overrides);
    const Vec2 X(r.at[0], r.at[1]);
    if (!setup.contains(X))
      throw ConfigError(fmt::format("--at {},{}: the point lies outside the body of '{}'", X.x(), X.y(), r.name));
    if (setup.geometry == Geometry::axisymmetric && !(X.x() > 0.0))
      throw ConfigError(fmt::format("--at {},{}: r-z solutions are evaluated off the axis (R > 0)", X.x(), X.y()));
  } catch (const ConfigError& e) {
    fmt::print(err, "mpmvv mms eval: {}\n", e.what());
    return 2;
  }
  const Vec2 X(r.at[0], r.at[1]);
  const mms::ExactFields f = setup.solution->fields(X, r.time);
  const bool rz = setup.geometry == Geometry::axisymmetric;
  const bool finite = f.position.allFinite() && f.velocity.allFinite() && f.acceleration.allFinite() &&
                      f.deformation_gradient.allFinite() && f.cauchy_stress.allFinite() && f.body_force.allFinite();
  if (!finite) {
    fmt::print(err, "mpmvv mms eval: --time {}: the fields of '{}' at X = ({}, {}) are not finite numbers there "
               "(its motion overflows or is not defined at that time)\n", r.time, r.name, X.x(), X.y());
    return 2;
  }
  if (r.json) {
    // Doubles to their shortest exact text; a NaN or an infinity as null.
    const Json j = {{"solution", r.name},
                    {"geometry", to_string(setup.geometry)},
                    {"reference_position", json_of(X)},
                    {"time", r.time},
                    {"position", json_of(f.position)},
                    {"displacement", json_of(f.displacement)},
                    {"velocity", json_of(f.velocity)},
                    {"acceleration", json_of(f.acceleration)},
                    {"F", json_of(f.deformation_gradient)},
                    {"F33", f.hoop_stretch},
                    {"J", f.J},
                    {"cauchy_stress", json_of(f.cauchy_stress)},
                    {"cauchy_stress_33", f.cauchy_stress_33},
                    {"first_piola", json_of(f.first_piola)},
                    {"first_piola_33", f.first_piola_33},
                    {"body_force", json_of(f.body_force)}};
    fmt::print(out, "{}\n", json_text(j));
    return 0;
  }
  const char* third = rz ? "theta" : "zz";
  fmt::print(out, "{} ({}) at X = ({}, {}), t = {}\n", r.name, to_string(setup.geometry), X.x(), X.y(), r.time);
  fmt::print(out, "  position       x     = ({:.10g}, {:.10g})\n", f.position.x(), f.position.y());
  fmt::print(out, "  displacement   u     = ({:.10g}, {:.10g})\n", f.displacement.x(), f.displacement.y());
  fmt::print(out, "  velocity       v     = ({:.10g}, {:.10g})\n", f.velocity.x(), f.velocity.y());
  fmt::print(out, "  acceleration   a     = ({:.10g}, {:.10g})\n", f.acceleration.x(), f.acceleration.y());
  fmt::print(out, "  F              = [[{:.10g}, {:.10g}], [{:.10g}, {:.10g}]], F_{} = {:.10g}, J = {:.10g}\n",
             f.deformation_gradient(0, 0), f.deformation_gradient(0, 1), f.deformation_gradient(1, 0),
             f.deformation_gradient(1, 1), third, f.hoop_stretch, f.J);
  fmt::print(out, "  Cauchy stress  = [[{:.10g}, {:.10g}], [{:.10g}, {:.10g}]], sigma_{} = {:.10g} Pa\n",
             f.cauchy_stress(0, 0), f.cauchy_stress(0, 1), f.cauchy_stress(1, 0), f.cauchy_stress(1, 1), third,
             f.cauchy_stress_33);
  fmt::print(out, "  body force     b     = ({:.10g}, {:.10g}) m/s^2 (per unit mass)\n", f.body_force.x(),
             f.body_force.y());
  return 0;
}

int mms_check(const MmsCheckRequest& r, std::ostream& out, std::ostream& err) {
  SceneSetup setup;
  Config config("", {});
  try {
    const SceneType& scene = scene_named(r.name);
    config = Config(scene.name, scene.keys());
    for (const std::string& o : r.overrides) config.set_from_text(o);
    setup = scene.setup(config);
  } catch (const ConfigError& e) {
    fmt::print(err, "mpmvv mms check: {}\n", e.what());
    return 2;
  }
  // A scene whose exact solution is not a motion of the body (Hertz: the
  // plate's state is compared with theory at the load the run measures) has
  // no balance of momentum to check: say so rather than PASS on zeros.
  if (!setup.exact_motion) {
    fmt::print(out, "{}: its exact solution is not a motion of the body (compared with theory at the load the run "
                    "measures): no residual to check\n", r.name);
    return 0;
  }
  // Random points of the body (rejection sampling in its walled box) and
  // times in [0, end_time], or up to where the motion stops being analytic
  // (less the reach of the differences in time, 3e-3 of its time scale).
  std::mt19937 rng(r.seed);
  const Vec2 lo = setup.grid.wall_lower(), hi = setup.grid.wall_upper();
  const double last_time = std::min(config.real("end_time"), 0.99 * setup.smooth_until);
  std::uniform_real_distribution<double> ux(lo.x(), hi.x()), uy(lo.y(), hi.y()), ut(0.0, last_time);
  // Finite differences reach 2e-3 of the motion's length scale from the point:
  // stay that far inside the body and off the axis.
  std::vector<mms::ResidualCheck> checks, coarse;
  std::vector<Vec2> where;
  std::vector<double> when;
  int attempts = 0;
  while (int(checks.size()) < r.points && attempts < 1000 * r.points) {
    ++attempts;
    const Vec2 X(ux(rng), uy(rng));
    const double margin = 0.01 * setup.grid.h;
    bool inside = setup.contains(X);
    for (const Vec2& d : {Vec2(margin, 0), Vec2(-margin, 0), Vec2(0, margin), Vec2(0, -margin)})
      inside = inside && setup.contains(X + d);
    if (!inside || (setup.geometry == Geometry::axisymmetric && X.x() < 0.02 * hi.x())) continue;
    when.push_back(ut(rng));
    checks.push_back(setup.solution->check(X, when.back()));
    coarse.push_back(setup.solution->check(X, when.back(), 2.0 * mms::kCheckStep));
    where.push_back(X);
  }
  const mms::ResidualVerdict v = mms::judge_residuals(checks, coarse, r.tolerance);
  double worst_local = 0.0;
  for (const mms::ResidualCheck& c : checks)
    if (c.scale > 1e-3 * v.scale) worst_local = std::max(worst_local, c.relative());
  const std::size_t w = v.worst_at;
  fmt::print(out, "{}: residual a - Div P / rho_0 - b at {} random points (finite differences against the derived force)\n",
             r.name, checks.size());
  fmt::print(out, "  relative to the largest |a| + |Div P / rho_0| + |b| = {:.4g}: max {:.3e} (at X = ({:.6g}, {:.6g}), "
             "t = {:.6g}), mean {:.3e}\n", v.scale, v.worst, checks.empty() ? NAN : where[w].x(),
             checks.empty() ? NAN : where[w].y(), checks.empty() ? NAN : when[w], v.mean);
  fmt::print(out, "  the differences' own error (steps {:g} and {:g} of the motion's scales differ by): max {:.3e}\n",
             mms::kCheckStep, 2.0 * mms::kCheckStep, v.difference);
  fmt::print(out, "  pointwise, where the local scale exceeds 1e-3 of it: max {:.3e}\n", worst_local);
  if (r.tolerance > 0.0)
    fmt::print(out, "  {} (tolerance {:.1e}, as given)\n", v.pass ? "PASS" : "FAIL", v.tolerance);
  else
    fmt::print(out, "  {} (tolerance {:.1e}: {:g} times the differences' own error)\n", v.pass ? "PASS" : "FAIL",
               v.tolerance, mms::kCheckMargin);
  return v.pass ? 0 : 1;
}

}  // namespace mpmvv::app
