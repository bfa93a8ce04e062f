// What a scene hands the solver: the grid, the particles it seeded, the
// material, the options of the method, and the optional stages it needs.
#pragma once

#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "faults.hpp"
#include "geometry.hpp"
#include "grid.hpp"
#include "material/mooney_rivlin.hpp"
#include "material/linear_elastic.hpp"
#include "material/neo_hookean.hpp"
#include "particles.hpp"
#include "stages.hpp"

namespace mpmvv {

enum class Method { linear, gimp, cpdi, cpdi_exact, bspline, bspline_cubic };
enum class Scheme { usl, usf, musl };
// What each particle's J is after a deformation update: its own det F, its
// cell's mean (average_cell_dilatation, eqs. 1.82-1.84), or the mean its
// nodes hold (smooth_node_dilatation); stages.hpp.
enum class Dilatation { particle, cell_averaged, node_smoothed };
// Where the grid is: fixed in space, the particles moving through it
// (updated), or the body's reference configuration, each particle weighed at
// its reference position for the whole run (total; shape/total_lagrangian.hpp).
enum class Formulation { updated, total };
// How particle velocities come back from the grid (stages.hpp: grid_to_particles).
// flip: each particle keeps its velocity and adds the grid's acceleration
// (eq. 1.76); what the grid cannot represent stays on the particles for the
// whole run. apic: each particle takes the grid's velocity and its gradient
// C_p and maps back the affine field v_p + C_p (x - x_p) (affine
// particle-in-cell): affine motion is carried without loss, the rest is damped
// at every step.
enum class VelocityTransfer { flip, apic };

// CPDI's particle domains: the parallelograms F_p diag(l_p) of eq. 1.97, or
// quadrilaterals whose corners move with the grid (domain_corners.hpp).
enum class CpdiDomain { convected, corners };

const char* to_string(Method m);
const char* to_string(Scheme s);

using MaterialModel = std::variant<NeoHookean, MooneyRivlin, LinearElastic>;
double p_wave_modulus(const MaterialModel& m);

struct SolverOptions {
  Method method = Method::cpdi;
  Scheme scheme = Scheme::usl;
  Geometry geometry = Geometry::plane_strain;
  // A deliberate fault, for showing that a verification gate catches one
  // (faults.hpp; MPMVV_FAULT). None in every real run.
  SolverFault fault = SolverFault::none;
  Dilatation dilatation = Dilatation::particle;
  Formulation formulation = Formulation::updated;
  VelocityTransfer velocity_transfer = VelocityTransfer::flip;
  // CPDI only: a domain longer than this many cells along one of its vectors
  // is split in two along it after a step (split.hpp); 0: never.
  double split_domains_beyond = 0.0;
  // CPDI only: a domain whose sides meet at less than this angle [degrees]
  // is turned after a step, keeping its centroid, area and second moment of
  // area, until they meet at this angle (domain_angle.hpp); 0: never.
  double min_domain_angle = 0.0;
  // CPDI only, updated formulation: the domains' description (CpdiDomain).
  CpdiDomain cpdi_domain = CpdiDomain::convected;
  // Artificial bulk viscosity (002_c3305cb8b1bc1490.txt eqs. 1.66-1.67,
  // add_bulk_viscosity in stages.hpp): the linear and quadratic coefficients
  // C0 and C1; both 0: none.
  double bulk_viscosity_linear = 0.0;
  double bulk_viscosity_quadratic = 0.0;
};

// A body force supplied by the scene, per unit mass. One call fills the whole
// array: the dispatch is per stage, not per particle.
class BodyForce {
 public:
  virtual ~BodyForce() = default;
  // Called with the particles the run will step before the first evaluate,
  // and again whenever the set changes (split.hpp appends halves): a force may
  // keep per-particle factors that hold while the set does.
  virtual void prepare(const Particles&) {}
  // After a split (split.hpp): the particles listed in `changed` were altered
  // in place and those from `previous_count` on are new. A force that keeps
  // per-particle factors may renew only theirs; by default all are prepared.
  virtual void update(const Particles& particles, std::size_t /*previous_count*/,
                      const std::vector<std::size_t>& /*changed*/) {
    prepare(particles);
  }
  virtual void evaluate(double t, const Particles& particles, std::vector<Vec2>& body_force) const = 0;
  // The bytes it keeps per particle set (Stepper::bytes_per_particle counts them).
  virtual std::size_t bytes() const { return 0; }
};

struct Model {
  GridGeometry grid;
  Particles particles;
  std::vector<Vec2> tracers;  // massless probe points; empty when the scene has none
};

}  // namespace mpmvv
