// What the classical exact-solution scenes share: a load ramped slowly to a
// static state (analytic/quasi_static.hpp), damping for dynamic relaxation,
// the grid nodes of a boundary, and means over the particles of a region
// where the exact state is homogeneous.
#pragma once

#include <functional>
#include <vector>

#include "solver/grid.hpp"
#include "solver/model.hpp"
#include "solver/particles.hpp"
#include "tools/app/config.hpp"

namespace mpmvv::app {

// The keys of a static scene: the solver's, the scene's own, then
// ramp_periods (the load's ramp time in periods of the body's lowest mode),
// damping_ratio (zeta of eq. 1.65 as a fraction of twice that mode's angular
// frequency; 1: the lowest mode critically damped), the seeding and the
// material's.
std::vector<KeySpec> static_scene_keys(std::vector<KeySpec> solver, const std::vector<KeySpec>& own,
                                       const std::vector<KeySpec>& material);

struct QuasiStatic {
  double ramp_time;  // T [s]
  double damping;    // zeta [1/s]
};
struct SceneSetup;
// From the keys and the body's lowest mode's angular frequency; rejects an end
// time that leaves the body no time to settle after the ramp (less than half
// the ramp). Marks the scene's setup as one that settles (its smooth_until,
// the ramp's end, and its settling body, with the small-strain shear modulus).
QuasiStatic quasi_static_from(const Config& c, double lowest_angular_frequency, double shear_modulus,
                              SceneSetup& s);

// Nodes of the grid column through x (or row through y), which must be a node line.
std::vector<std::size_t> node_column(const GridGeometry& grid, double x);
std::vector<std::size_t> node_row(const GridGeometry& grid, double y);

// The bar's probes [0, L] x [0, half]: the line along it at Y = half / 2
// (x-displacement) and the top's middle point (y-displacement).
void add_bar_probes(SceneSetup& s, double L, double half, int points);

// Reference-volume-weighted means over the particles whose reference position
// lies in a region.
struct RegionMeans {
  Mat2 deformation_gradient = Mat2::Zero();
  Mat2 stress = Mat2::Zero();
  std::size_t particles = 0;
};
RegionMeans region_means(const Particles& P, const std::function<bool(const Vec2&)>& in_region);

// The small-strain Lame constants of a material (Mooney-Rivlin: mu = 2 (C1 + C2),
// lambda = K - 2 mu / 3), and the plane-strain bar modulus 4 mu (lambda + mu) / (lambda + 2 mu).
struct Lame {
  double lambda, mu;
  double youngs_modulus() const { return mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu); }
  double poisson_ratio() const { return lambda / (2.0 * (lambda + mu)); }
  double plane_strain_modulus() const { return 4.0 * mu * (lambda + mu) / (lambda + 2.0 * mu); }
};
Lame small_strain_lame(const MaterialModel& m);

// Rejects a prescribed displacement that is zero or beyond 1 % of the length
// it strains (the exact solutions it is compared with are small-strain).
void check_small_displacement(const Config& c, const std::string& key, double length, const char* length_name);

// |measured / exact - 1|, or |measured| when the exact value is zero.
double relative_error(double measured, double exact);

}  // namespace mpmvv::app
