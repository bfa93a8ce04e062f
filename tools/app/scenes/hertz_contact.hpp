// What the Hertz scenes share (hertz_cylinder.cpp in plane strain, a rigid
// cylinder; hertz_sphere.cpp in r-z, a rigid sphere): the contact pressure
// read from the grid's contact forces, the stresses of the particles next to
// the axis, and the errors, measurements, probes and history they give
// against Hertz theory at the load the run measures (analytic/hertz.hpp).
#pragma once

#include <functional>

#include "solver/geometry.hpp"
#include "tools/app/scene/setup.hpp"

namespace mpmvv::app {

// Hertz theory at a load: the contact's half-width (in r-z its radius) a, its
// peak pressure p0, the pressure p(x) and the stresses on the axis at depth z
// below the surface (compression negative; x stands for r in r-z).
struct HertzAtLoad {
  double half_width = 0.0;
  double peak_pressure = 0.0;
  std::function<double(double)> pressure, axis_sigma_x, axis_sigma_z;
};

struct HertzContact {
  Geometry geometry;        // plane strain: P per unit length, both halves; r-z: P over the whole circle [N]
  double radius;            // R, the rigid indenter's [m]
  double approach;          // delta [m]
  double ramp_time;         // [s] (analytic/quasi_static.hpp)
  double plate_depth;       // D [m]
  double spacing;           // the particles' spacing in the reference: the axis column lies within it
  double contact_modulus;   // E* of a rigid indenter on the plate [Pa]
  double poisson_ratio;     // the plate's
  double largest_shear = 0.0;  // Hertz's largest shear on the axis over p0, and its depth over a
  double largest_shear_depth = 0.0;
  std::function<HertzAtLoad(double load)> theory;  // the scene's
};

// The keys of a Hertz scene: the solver's (cells across the plate's depth),
// the indenter's radius ("disk" or "sphere" in its help), the approach, the
// plate's depth and half-width, the static scene's and a steel plate's.
std::vector<KeySpec> hertz_keys(const char* indenter);

// The plate [0, W] x [-D, 0], clamped at its bottom and free at its far side,
// the line x = 0 its plane of symmetry (in r-z the axis), and the rigid
// indenter of radius R centred above x = 0, moved delta into it along the
// ramp of analytic/quasi_static.hpp in frictionless contact through the grid
// (solver/contact.hpp); damping settles the plate. Sets the scene's material,
// geometry, grid, body and stages; the theory is left to the scene.
HertzContact hertz_plate(const Config& c, SceneSetup& s, Geometry geometry, const char* indenter);

// Sets the scene's extra errors, measurements, probes and history from the
// contact forces and the particles at each output time.
void add_hertz_readings(SceneSetup& s, const HertzContact& contact);

}  // namespace mpmvv::app
