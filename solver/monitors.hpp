// What a run's health is read from, at every output time: energies, the range
// of J, how fast particles move against the waves, how distorted the CPDI
// domains are, how many particles sit at the grid's edge, and what lifts the
// wave speeds that set the step. One pass over
// the particles; a stepper calls it with its own shape and material.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "grid.hpp"
#include "particles.hpp"
#include "shape/stencil.hpp"
#include "stages.hpp"

namespace mpmvv {

// Work done on the particles since t = 0 by what the scene adds [J per unit
// depth; per radian in r-z]: body forces and tractions (sum m b.v dt), node
// constraints (reaction times prescribed increment), contact (sum f.v dt at
// the nodes in contact), and grid damping and bulk viscosity (negative: what
// they dissipate).
struct EnergyLedger {
  double body = 0.0, constraints = 0.0, contact = 0.0, damping = 0.0;
  double total() const { return body + constraints + contact + damping; }
};

// The body force's power over the particles, sum m b . v, with v the velocity
// they carry over the step (the ledger's body work grows by it times dt).
inline double body_force_power(const Particles& P) {
  const std::size_t n = P.size();
  ThreadOrderedSums<1> work;
#pragma omp parallel
  {
    double own = 0.0;
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) own += P.mass[p] * P.body_force[p].dot(P.velocity[p]);
    work.keep({own});
  }
  return work.total()[0];
}

struct Monitors {
  double kinetic = 0.0;        // sum m |v|^2 / 2
  // sum m (x - o) x v about the origin o of coordinates [kg m^2/s per unit
  // depth]; NaN in r-z. The internal forces exert no net torque on the grid
  // (eq. 1.70 with a linearly complete basis and a symmetric stress), so it
  // changes with the torque of what the scene applies (and what the
  // transfers lose).
  double angular_momentum = std::numeric_limits<double>::quiet_NaN();
  double strain = 0.0;         // sum V0 psi(F)
  double min_J = std::numeric_limits<double>::infinity();
  double max_J = 0.0;
  double max_mach = 0.0;       // max |v_p| / c_p, c_p the material's wave speed at the particle's state
  // max over particles of (|r1|^2 + |r2|^2) / (2 |r1 x r2|) for the domain
  // half-vectors: 1 for a square, growing as a domain shears or stretches
  // (NaN without domains: linear MPM).
  double max_distortion = std::numeric_limits<double>::quiet_NaN();
  std::size_t near_edge = 0;   // particles whose domain reaches past the middle of the grid's outermost cell layer
  // Corner domains (domain_corners.hpp) turned over, 4 det [a_1 a_2] <= 0: the
  // exact CPDI integrates such a particle over its own parallelogram F_p A_p,
  // the corner interpolation over the turned quadrilateral as it stands
  // (cpdi_exact.hpp, cpdi.hpp: folded). 0 for every other domain.
  std::size_t folded_domains = 0;
  // What lifts the CFL step's signal speed above the body's small-strain wave
  // speed c0 = sqrt(p_wave_modulus / rho_0) (stages.hpp: scan_particles, whose
  // step is cfl h / max_p (max(c_p, k_p c0_p) + |v_p|), c0_p at the current
  // density rho_0 / J_p; the total formulation's c_p / min(1, stretch) in
  // place of c_p): the particle's state, max c_p / c0 (a stretched
  // neo-Hookean solid carries its waves faster along the stretch, and a
  // particle whose J has grown is lighter for the same stiffness), and the
  // basis, max k_p (CPDI's corner interpolation, stages.hpp: stiffening; for
  // the total formulation the reference cell compressed to F_p h,
  // 1 / min(1, stretch)). Both are 1 for an unstrained body on the grid's own
  // basis, so a step that falls while both stay near 1 falls for a cause
  // these do not name.
  double max_wave_speed_ratio = 0.0;
  double max_basis_stiffening = 0.0;
};

// Over particles [begin, end) of one material (by default all).
template <class Shape, class Material>
Monitors monitor_particles(const Shape& shape, const Material& material, const Particles& P,
                           const GridGeometry& grid, std::size_t begin = 0, std::size_t end = kAllParticles) {
  Monitors m;
  const std::size_t n = std::min(end, P.size());
  double min_J = m.min_J, max_J = 0.0, mach = 0.0;
  double distortion = 0.0, wave_ratio = 0.0, basis_stiffening = 0.0;
  std::size_t near = 0, folded = 0;
  constexpr bool has_domain = Shape::has_domain;
  ThreadOrderedSums<3> sums;  // kinetic, strain, spin
#pragma omp parallel
  {
    double kinetic = 0.0, strain = 0.0, spin = 0.0;
#pragma omp for schedule(static) reduction(+ : near, folded) reduction(min : min_J) \
      reduction(max : max_J, mach, distortion, wave_ratio, basis_stiffening)
    for (std::size_t p = begin; p < n; ++p) {
      const double F33 = out_of_plane_stretch<Shape::geometry>(P, p);
      const double J = determinant(P.deformation_gradient[p]) * F33;
      kinetic += 0.5 * P.mass[p] * P.velocity[p].squaredNorm();
      spin += P.mass[p] * (P.position[p].x() * P.velocity[p].y() - P.position[p].y() * P.velocity[p].x());
      strain += P.reference_volume[p] * material.energy_density(P.deformation_gradient[p], F33);
      min_J = std::min(min_J, J);
      max_J = std::max(max_J, J);
      const double density = P.mass[p] / P.volume[p];
      const double c = std::sqrt(material.wave_modulus(P.deformation_gradient[p], F33, P.stress[p]) / density);
      mach = std::max(mach, P.velocity[p].norm() / c);
      wave_ratio = std::max(wave_ratio, c / std::sqrt(material.p_wave_modulus() * P.reference_volume[p] / P.mass[p]));
      if constexpr (requires { shape.cell_stretch(p); })
        basis_stiffening = std::max(basis_stiffening, 1.0 / std::min(1.0, shape.cell_stretch(p)));
      else
        basis_stiffening = std::max(basis_stiffening, 1.0);
      const Mat2 s = shape.domain(p);
      if constexpr (has_domain) {
        const double area = std::abs(determinant(s));
        distortion = std::max(distortion, area > 0.0 ? s.squaredNorm() / (2.0 * area)
                                                     : std::numeric_limits<double>::infinity());
      }
      bool edge = false;
      for (const double a : {-1.0, 1.0})
        for (const double b : {-1.0, 1.0}) {
          const Vec2 xi = grid_coordinate(grid, P.position[p] + a * s.col(0) + b * s.col(1));
          edge = edge || !(xi.x() >= 0.5 && xi.y() >= 0.5 && xi.x() <= grid.cells_x - 0.5 && xi.y() <= grid.cells_y - 0.5);
        }
      if (edge) ++near;
      if constexpr (requires { shape.folded(p); })
        if (shape.folded(p)) ++folded;
    }
    sums.keep({kinetic, strain, spin});
    if constexpr (Shape::gradients_beyond_grid_basis) {
      // k_p from each particle's stencil, the lanes' eight at a time where the
      // shape has them. A particle whose kernel bound of sum_g |G_gp| (above
      // the sum itself), lifted past its rounding as signal_speed lifts it,
      // keeps k_p below the largest so far cannot raise it, and is not
      // listed: the largest is the number forming every k_p gives.
      double largest = 1.0;
      for_each_stencil(
          shape, begin, n, true, [](std::size_t, auto) { return true; },
          [&](std::size_t, auto&&, auto&& stencil_of, double gradient_bound) {
            if (gradient_bound >= 0.0 && grid.h * gradient_bound / kGridBasisGradientBound * (1.0 + 1e-12) < largest)
              return;
            largest = std::max(largest, stiffening(stencil_of(), grid.h));
          });
#pragma omp critical
      basis_stiffening = std::max(basis_stiffening, largest);
    }
  }
  const auto [kinetic, strain, spin] = sums.total();
  m.kinetic = kinetic;
  if constexpr (Shape::geometry == Geometry::plane_strain) m.angular_momentum = spin;
  m.strain = strain;
  m.min_J = min_J;
  m.max_J = max_J;
  m.max_mach = mach;
  if constexpr (has_domain) m.max_distortion = distortion;
  m.near_edge = near;
  m.folded_domains = folded;
  m.max_wave_speed_ratio = wave_ratio;
  m.max_basis_stiffening = basis_stiffening;
  return m;
}

// The monitors of a run with two materials, from those of each.
inline Monitors combined(const Monitors& a, const Monitors& b) {
  Monitors m;
  m.kinetic = a.kinetic + b.kinetic;
  m.angular_momentum = std::isnan(a.angular_momentum)   ? b.angular_momentum
                       : std::isnan(b.angular_momentum) ? a.angular_momentum
                                                        : a.angular_momentum + b.angular_momentum;
  m.strain = a.strain + b.strain;
  m.min_J = std::min(a.min_J, b.min_J);
  m.max_J = std::max(a.max_J, b.max_J);
  m.max_mach = std::max(a.max_mach, b.max_mach);
  m.max_distortion = std::isnan(a.max_distortion) ? b.max_distortion
                     : std::isnan(b.max_distortion) ? a.max_distortion
                                                    : std::max(a.max_distortion, b.max_distortion);
  m.near_edge = a.near_edge + b.near_edge;
  m.folded_domains = a.folded_domains + b.folded_domains;
  m.max_wave_speed_ratio = std::max(a.max_wave_speed_ratio, b.max_wave_speed_ratio);
  m.max_basis_stiffening = std::max(a.max_basis_stiffening, b.max_basis_stiffening);
  return m;
}

}  // namespace mpmvv
