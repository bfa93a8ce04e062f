// The ring MMS (PROBLEMS.md section 1; 000_1dbcb8acb6dddab9.txt chapters 2-3)
// on the Sandia study's square domain with roller walls. Probes: the lines
// Theta = 0, +45, -45 degrees and the point (R_m, 0) read the angular
// displacement; the circle R_m gives the angular spectrum of the error.
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "mms/ring.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

namespace {

using std::numbers::pi;

constexpr const char* kClosedForm = "eqs. 2.14-2.15";

std::vector<KeySpec> keys() {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<KeySpec> k = solver_keys(64, 1.0, {0.1, 0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.7, 0.75, 0.8, 0.9, 1.0});
  const std::vector<KeySpec> ring = {
      {"amplitude", KeyKind::real, 0.5, "A, the largest angular displacement [rad]", 0.0, 4.0, true},
      {"time_function", KeyKind::text, std::string("cosine"),
       "g(t): cosine = (A/2)(1 - cos 2 pi t) (Sandia report), sine = A sin(pi t) (MMS paper)", -inf, inf, false,
       false, {"cosine", "sine"}},
      {"inner_radius", KeyKind::real, 0.75, "inner radius R_i of the ring [m]", 0.0, inf, true},
      {"outer_radius", KeyKind::real, 1.25, "outer radius R_o of the ring [m]", 0.0, inf, true},
      {"domain", KeyKind::real, 3.0, "width of the square domain centred on the ring [m]", 0.0, inf, true},
      {"probe_points", KeyKind::integer, std::int64_t(51), "material points on each probe line", 2, 100000},
      {"circle_points", KeyKind::integer, std::int64_t(128),
       "material points on the circle R = (R_i + R_o)/2 for the angular spectrum", 8, 65536},
      {"rims", KeyKind::text, std::string("free"),
       "free: traction-free rims, as the exact solution's are; held: every grid node outside the ring held at rest "
       "(the exact motion is rest there: h = h' = 0 at the rims), the boundary of the vortex problem of the total "
       "Lagrangian MPM literature, which takes away the free ring's rigid spin and breathing; rest: the rims "
       "themselves held at rest, at points a cell apart where the grid basis is read, and the nodes beyond a cell "
       "outside the ring (for B-splines, whose node values are not the field's values)",
       -inf, inf, false, false, {"free", "held", "rest"}},
      force_quadrature_key(),
      body_force_key(kClosedForm),
  };
  return scene_keys(std::move(k), ring, material_keys("neo-hookean", 577.0, 385.0, 1000.0));
}

SceneSetup setup(const Config& c) {
  mms::RingParameters p;
  p.inner_radius = c.real("inner_radius");
  p.outer_radius = c.real("outer_radius");
  p.amplitude = c.real("amplitude");
  p.time_function = c.text("time_function") == "sine" ? mms::RingTimeFunction::sine : mms::RingTimeFunction::cosine;
  p.lambda = c.real("lambda");
  p.mu = c.real("mu");
  p.density = c.real("density");

  SceneSetup s;
  s.material = material_from(c);
  s.geometry = Geometry::plane_strain;
  const double domain = c.real("domain");
  const int cells = int(c.integer("cells"));
  s.grid = GridGeometry::walled(Vec2(-0.5 * domain, -0.5 * domain), domain / cells, cells, cells);
  if (!(p.outer_radius > p.inner_radius))
    c.reject("outer_radius", fmt::format("must exceed inner_radius = {} (from {})", p.inner_radius,
                                         c.origin("inner_radius").source));
  // The motion keeps every radius, so the ring never comes nearer the walls.
  require_two_cells_clearance(c, fmt::format("the ring (outer radius {} m)", p.outer_radius), p.outer_radius, domain,
                              cells);
  // h = domain / cells: blame the one the user set (cells when both or neither).
  if (p.outer_radius - p.inner_radius < s.grid.h) {
    const bool domain_set = c.origin("domain").source != "default" && c.origin("cells").source == "default";
    c.reject(domain_set ? "domain" : "cells",
             fmt::format("the ring is {} m wide but a cell ({} m over {} cells) is {:.4g} m: {}",
                         p.outer_radius - p.inner_radius, domain, cells, s.grid.h,
                         domain_set ? "use a smaller domain" : "use more cells"));
  }

  s.solution = mms::make_solution(mms::RingMotion{p}, s.material, p.density, s.geometry);
  s.body_is_annulus(p.inner_radius, p.outer_radius);
  const int n = int(c.integer("probe_points"));
  const double angles[3] = {0.0, pi / 4.0, -pi / 4.0};
  const char* names[3] = {"theta0", "theta_plus45", "theta_minus45"};
  for (int k = 0; k < 3; ++k) {
    const Vec2 direction(std::cos(angles[k]), std::sin(angles[k]));
    ProbeLine line{names[k], ProbeQuantity::angular_displacement, "reference_radius", {}, {}, angles[k]};
    line.reference = points_on_segment(p.inner_radius * direction, p.outer_radius * direction, n);
    for (const Vec2& X : line.reference) line.parameter.push_back(X.norm());
    s.lines.push_back(std::move(line));
  }
  const double middle = 0.5 * (p.inner_radius + p.outer_radius);
  s.points.push_back({"point_R1", ProbeQuantity::angular_displacement, Vec2(middle, 0.0)});
  s.circle = ProbeCircle{ProbeQuantity::angular_displacement, middle, int(c.integer("circle_points"))};
  // Held rims: the exact motion extended beyond the ring is rest, with its
  // first derivative continuous (h = h' = 0 at both rims), so prescribing it
  // at the grid nodes outside the ring is a boundary condition the exact
  // solution meets. A stiff ring needs it to converge from coarse meshes: with
  // free rims its manufactured force, a dead load thousands of times its
  // inertia, is balanced against the normal stresses of the shear (b_r grows
  // with mu (h' g)^2, eq. 2.14), and an error in the shear swells the whole
  // ring (suites/stiff-vortex.toml).
  //
  // Rest rims: the rims themselves held at rest, the grid field read with the
  // method's basis at points about a cell apart along each (rest_points.hpp),
  // and the nodes beyond a cell outside the ring held as above. For a basis
  // that does not interpolate (B-splines) holding the nodes just outside is
  // not holding the rim: the field is held a fraction of a cell inside the
  // ring, by a staircase that changes from mesh to mesh. The nodes farther
  // out reach the ring only through a sliver (at most half a cell for
  // quadratic splines, a cell for cubic ones), where the exact motion is of
  // second order in the distance to the rim. One point per cell along a rim
  // matches the one layer of nodes it replaces: two per cell over-constrain
  // the field (measured, cubic splines on 30 cells: 0.094 against 0.048).
  const std::string rims = c.text("rims");
  if (rims != "free") {
    const bool rest = rims == "rest";
    s.stages = [p, rest](const Particles&, const GridGeometry& grid) {
      SceneStages st;
      const double beyond = rest ? grid.h : 0.0;
      std::vector<std::size_t> nodes;
      for (int j = 0; j < grid.nodes_y(); ++j)
        for (int i = 0; i < grid.nodes_x(); ++i) {
          const double R = grid.node_position(i, j).norm();
          if (R < p.inner_radius - beyond || R > p.outer_radius + beyond) nodes.push_back(std::size_t(grid.node(i, j)));
        }
      for (int axis : {0, 1}) st.constraints.push_back({nodes, axis, [](double) { return 0.0; }});
      if (rest)
        for (double R : {p.inner_radius, p.outer_radius}) {
          const int k = std::max(8, int(std::ceil(2.0 * pi * R / grid.h)));
          for (int i = 0; i < k; ++i) {
            const double angle = 2.0 * pi * i / k;
            st.rest_points.push_back(R * Vec2(std::cos(angle), std::sin(angle)));
          }
        }
      return st;
    };
    s.loading = rest ? "the rims held at rest at points a cell apart, grid nodes beyond a cell outside the ring at rest"
                     : "grid nodes outside the ring held at rest";
  }
  // Eqs. 2.14-2.15 belong to the neo-Hookean solid; other materials use the derived force.
  if (closed_form_force(c, s.material, kClosedForm))
    s.fast_body_force = std::make_shared<mms::RingClosedFormField>(mms::RingMms(p));
  return s;
}

}  // namespace

SceneType ring_scene() {
  return {"ring", "ring MMS: circles of a ring turned by alpha = g(t) h(R) (PROBLEMS.md section 1)", keys, setup};
}

}  // namespace mpmvv::app
