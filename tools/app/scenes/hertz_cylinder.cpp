// Hertz contact of a rigid cylinder on an elastic plate in plane strain
// (PROBLEMS.md section 4; K. L. Johnson, Contact Mechanics; the setup of
// 004_5b499dc27e377c32.txt section 4.3: a rigid disk of radius 2 m pressed
// into a steel plate, E = 207 GPa, nu = 0.3, bottom fixed). No forcing. The
// disk is a rigid master moved down by the approach along the ramp of
// analytic/quasi_static.hpp, in frictionless contact with the plate through
// the grid (solver/contact.hpp); damping settles the plate. The scene holds
// the half x >= 0 (the wall x = 0 is the plane of symmetry); the plate
// [0, W] x [-D, 0] is clamped at its bottom and free at its far side.
//
// In plane strain the approach is not fixed by half-space theory, so the
// comparison is at the load the run measures, P = 2 sum of the vertical contact
// force: a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a), E* = E / (1 - nu^2)
// (analytic/hertz.hpp). The half-width is read from the moments of the node
// columns' contact forces, a^2 = 4 int x^2 p / int p (exact for
// p0 sqrt(1 - x^2 / a^2)), the pressure per cell and the peak from the cells
// beside the axis (hertz_contact.cpp). A finite
// plate departs from the half-space by terms in (a / D)^2: the default plate
// is ten half-widths deep, and `plate_depth` takes it deeper.
#include "analytic/hertz.hpp"
#include "tools/app/scene/setup.hpp"
#include "tools/app/scenes/hertz_contact.hpp"

namespace mpmvv::app {

namespace {

std::vector<KeySpec> keys() { return hertz_keys("disk"); }

SceneSetup setup(const Config& c) {
  SceneSetup s;
  HertzContact contact = hertz_plate(c, s, Geometry::plane_strain, "disk");
  contact.largest_shear = 0.300;
  contact.largest_shear_depth = 0.786;
  contact.theory = [R = contact.radius, E_star = contact.contact_modulus](double load) {
    const analytic::HertzCylinder hertz{load, R, E_star};
    return HertzAtLoad{hertz.half_width(), hertz.peak_pressure(), [hertz](double x) { return hertz.pressure(x); },
                       [hertz](double z) { return hertz.axis_sigma_x(z); },
                       [hertz](double z) { return hertz.axis_sigma_z(z); }};
  };
  add_hertz_readings(s, contact);
  return s;
}

}  // namespace

SceneType hertz_cylinder_scene() {
  return {"hertz-cylinder",
          "rigid cylinder pressed into a steel plate, plane strain: contact half-width and pressure against Hertz "
          "(PROBLEMS.md section 4)",
          keys, setup};
}

}  // namespace mpmvv::app
