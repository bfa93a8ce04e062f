// Hertz contact of a rigid sphere on an elastic plate in r-z (PROBLEMS.md
// section 4; K. L. Johnson, Contact Mechanics, section 3.4): the plate and the
// ramped, damped press of hertz_cylinder.cpp turned about the axis x = r = 0,
// the indenter a sphere of radius R. Compared with Hertz at the load the run
// measures, P = 2 pi times the sum of the node rings' vertical contact forces
// (per radian): a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2),
// p(r) = p0 sqrt(1 - r^2 / a^2), and the stresses on the axis
// (analytic/hertz.hpp). The contact radius is read from the moments of the
// ring forces, a^2 = (5/2) int r^2 p r dr / int p r dr, exact for that
// profile (hertz_contact.cpp). A finite plate departs from the half-space by
// terms in (a / D)^2 in a and p0; the approach, fixed by the half-space in
// Hertz theory (delta = a^2 / R), depends on the whole plate's compliance and
// is not compared.
#include <cmath>

#include "analytic/hertz.hpp"
#include "tools/app/scene/setup.hpp"
#include "tools/app/scenes/hertz_contact.hpp"

namespace mpmvv::app {

namespace {

std::vector<KeySpec> keys() { return hertz_keys("sphere"); }

SceneSetup setup(const Config& c) {
  SceneSetup s;
  HertzContact contact = hertz_plate(c, s, Geometry::axisymmetric, "sphere");
  const double R = contact.radius, E_star = contact.contact_modulus, nu = contact.poisson_ratio;
  contact.theory = [R, E_star, nu](double load) {
    const analytic::HertzSphere hertz{load, R, E_star};
    return HertzAtLoad{hertz.contact_radius(), hertz.peak_pressure(), [hertz](double r) { return hertz.pressure(r); },
                       [hertz, nu](double z) { return hertz.axis_sigma_r(z, nu); },
                       [hertz](double z) { return hertz.axis_sigma_z(z); }};
  };
  // Hertz's largest shear on the axis and its depth at this Poisson ratio,
  // over z in [0, 2a] in steps of a / 10^4 (a = 1, p0 = 1 by scaling).
  const analytic::HertzSphere unit{4.0 / 3.0, 1.0, 1.0};  // a = 1
  for (int k = 0; k <= 20000; ++k) {
    const double z = 1e-4 * k;
    const double shear = 0.5 * (unit.axis_sigma_r(z, nu) - unit.axis_sigma_z(z)) / unit.peak_pressure();
    if (shear > contact.largest_shear) {
      contact.largest_shear = shear;
      contact.largest_shear_depth = z;
    }
  }
  add_hertz_readings(s, contact);
  return s;
}

}  // namespace

SceneType hertz_sphere_scene() {
  return {"hertz-sphere",
          "rigid sphere pressed into a steel plate, r-z: contact radius and pressure against Hertz (PROBLEMS.md "
          "section 4)",
          keys, setup};
}

}  // namespace mpmvv::app
