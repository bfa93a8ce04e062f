#include "setup.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace mpmvv::app {

const char* to_string(ProbeQuantity q) {
  switch (q) {
    case ProbeQuantity::angular_displacement: return "angular_displacement";
    case ProbeQuantity::radial_displacement: return "radial_displacement";
    case ProbeQuantity::displacement_x: return "displacement_x";
    case ProbeQuantity::displacement_y: return "displacement_y";
  }
  return "?";
}

KeySpec seeding_key() {
  const double inf = std::numeric_limits<double>::infinity();
#ifdef MPMVV_HAVE_CGAL
  const std::vector<std::string> choices = {"exact", "centre"};
  const std::string fallback = "exact";
#else
  const std::vector<std::string> choices = {"centre"};
  const std::string fallback = "centre";
#endif
  return {"seeding", KeyKind::text, fallback,
          "exact: particles in cells the boundary cuts get the exact clipped volume and centroid (CGAL), so the body's "
          "volume is exact; centre: a particle wherever its sub-cell centre lies in the body (a staircase boundary)",
          -inf, inf, false, false, choices};
}

KeySpec force_quadrature_key() {
  const double inf = std::numeric_limits<double>::infinity();
  return {"body_force_quadrature", KeyKind::text, std::string("centroid"),
          "centroid: each particle takes the body force at its reference centroid; domain: the mean over its "
          "reference domain by 2 x 2 Gauss points (mms/force_field.hpp), which removes the centroid rule's error of "
          "order (h / particles_per_direction)^2 where the force is large against the motion it makes (a stiff "
          "solid moved slowly)",
          -inf, inf, false, false, {"centroid", "domain"}};
}

KeySpec body_force_key(const std::string& closed_form) {
  const double inf = std::numeric_limits<double>::infinity();
  return {"body_force", KeyKind::text, std::string("closed-form"),
          "closed-form: " + closed_form + " (neo-hookean only; equal to the derived force to round-off); derived: "
          "automatic differentiation of the motion and material",
          -inf, inf, false, false, {"closed-form", "derived"}};
}

const NeoHookean* closed_form_force(const Config& c, const MaterialModel& material, const std::string& closed_form) {
  if (c.text("body_force") != "closed-form") return nullptr;
  const NeoHookean* solid = std::get_if<NeoHookean>(&material);
  if (!solid)
    c.reject("body_force", fmt::format("the closed form ({}) holds for the neo-Hookean solid only; material = \"{}\" "
                                       "(from {}) needs body_force = \"derived\"",
                                       closed_form, c.text("material"), c.origin("material").source));
  return solid;
}

std::vector<KeySpec> scene_keys(std::vector<KeySpec> k, const std::vector<KeySpec>& own,
                                  const std::vector<KeySpec>& material) {
  k.insert(k.end(), own.begin(), own.end());
  k.push_back(seeding_key());
  k.insert(k.end(), material.begin(), material.end());
  return k;
}

std::vector<KeySpec> material_keys(const std::string& default_material, double lambda, double mu, double density) {
  const double inf = std::numeric_limits<double>::infinity();
  return {
      {"material", KeyKind::text, default_material,
       "neo-hookean (eq. 2.2), mooney-rivlin (eq. 2.18 with K ln J) or linear-elastic (small strain)", -inf, inf,
       false, false, {"neo-hookean", "mooney-rivlin", "linear-elastic"}},
      {"lambda", KeyKind::real, lambda, "first Lame constant, neo-hookean and linear-elastic [Pa]"},
      {"mu", KeyKind::real, mu, "shear modulus, neo-hookean and linear-elastic [Pa]", 0.0, inf, true},
      {"c1", KeyKind::real, 0.5 * mu, "C1 of mooney-rivlin [Pa] (shear modulus 2 (C1 + C2))"},
      {"c2", KeyKind::real, 0.0, "C2 of mooney-rivlin [Pa]"},
      {"bulk_modulus", KeyKind::real, lambda + 2.0 / 3.0 * mu, "K of mooney-rivlin [Pa]", 0.0, inf, true},
      {"density", KeyKind::real, density, "reference density rho_0 [kg/m^3]", 0.0, inf, true},
  };
}

MaterialModel material_from(const Config& c) {
  const std::string& m = c.text("material");
  if (m == "mooney-rivlin") {
    if (!(c.real("c1") + c.real("c2") > 0.0))
      c.reject("c1", fmt::format("c1 + c2 must be positive (a positive shear modulus); c2 = {} from {}",
                                 c.real("c2"), c.origin("c2").source));
    return MooneyRivlin{c.real("c1"), c.real("c2"), c.real("bulk_modulus")};
  }
  if (!(c.real("lambda") > -2.0 / 3.0 * c.real("mu")))
    c.reject("lambda", fmt::format("must exceed -2 mu / 3 = {:.6g} (a positive bulk modulus; mu from {})",
                                   -2.0 / 3.0 * c.real("mu"), c.origin("mu").source));
  if (m == "linear-elastic") return LinearElastic{c.real("lambda"), c.real("mu")};
  return NeoHookean{c.real("lambda"), c.real("mu")};
}

void require_two_cells_clearance(const Config& config, const std::string& what, double reach, double domain,
                                 int cells) {
  const double h = domain / cells;
  if (reach + 2.0 * h <= 0.5 * domain) return;
  // reach + 2 domain / n <= domain / 2, so n >= 2 domain / (domain / 2 - reach).
  const bool fits = 0.5 * domain > reach;
  const int fewest = fits ? int(std::ceil(2.0 * domain / (0.5 * domain - reach))) : 0;
  const std::string need = fmt::format("{} needs two cells of clearance inside the {} m domain, and cells = {} makes "
                                       "h = {:.4g} m", what, domain, cells, h);
  const std::string wider = fmt::format("a domain over {:.4g} m", 2.0 * (reach + 2.0 * h));
  // The key the user changed is the one to blame: the domain when it alone was set.
  const bool domain_set = config.origin("domain").source != "default" && config.origin("cells").source == "default";
  if (!fits || domain_set)
    config.reject("domain", fmt::format("{}: use {}{}", need, wider,
                                        fits ? fmt::format(", or cells >= {}", fewest) : std::string()));
  config.reject("cells", fmt::format("{}: use cells >= {}, or {}", need, fewest, wider));
}

std::vector<Vec2> points_on_segment(const Vec2& a, const Vec2& b, int count) {
  std::vector<Vec2> out;
  for (int i = 0; i < count; ++i) out.push_back(a + (b - a) * (double(i) / double(count - 1)));
  return out;
}

void SceneSetup::body_is_rectangle(const Vec2& lower, const Vec2& upper) {
  contains = [lower, upper](const Vec2& X) {
    return X.x() >= lower.x() && X.x() <= upper.x() && X.y() >= lower.y() && X.y() <= upper.y();
  };
#ifdef MPMVV_HAVE_CGAL
  body = Body::rectangle(lower, upper);
#endif
}

void SceneSetup::body_is_annulus(double inner_radius, double outer_radius) {
  contains = [inner_radius, outer_radius](const Vec2& X) {
    const double R = X.norm();
    return R >= inner_radius && R <= outer_radius;
  };
#ifdef MPMVV_HAVE_CGAL
  body = Body::annulus(Vec2::Zero(), inner_radius, outer_radius);
#endif
}

}  // namespace mpmvv::app
