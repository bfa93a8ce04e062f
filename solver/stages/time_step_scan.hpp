// Each particle's health and signal speed, from which the time step is set
// (the scan). A stage of solver/stages.hpp.
#pragma once

#include "tracers.hpp"

namespace mpmvv {

// ---------------------------------------------------------------- health and time step

struct ParticleScan {
  double max_signal_speed = 0.0;  // max_p (max(c_p, k_p c0_p) + |v_p|): scan_particles
  std::size_t first_unhealthy;    // lowest index of a particle that stops the run, or size()
};

// Out-of-plane stretch of particle p: F_theta in r-z, 1 in plane strain.
template <Geometry G>
double out_of_plane_stretch(const Particles& P, std::size_t p) {
  if constexpr (G == Geometry::axisymmetric) return P.hoop_stretch[p];
  return 1.0;
}

// `inside`, if given, returns shape.inside(p) (a caller that has it cheaper
// passes its own); it is asked only of a particle whose state is finite and
// unfolded, as before.
template <class Shape, class Inside = std::nullptr_t>
bool particle_healthy(const Shape& shape, const Particles& P, std::size_t p, Inside inside = nullptr) {
  const double F33 = out_of_plane_stretch<Shape::geometry>(P, p);
  const double J = determinant(P.deformation_gradient[p]) * F33;
  // 0 x is +-0 for a finite x and NaN for an infinite or NaN one: the sum of
  // the products is zero exactly when every entry is finite, with no branch
  // per entry (the test runs for every particle every step). Summed as a
  // tree of pairs, not a chain: twelve additions in a row each wait for the
  // last.
  const Mat2& F = P.deformation_gradient[p];
  const Mat2& stress = P.stress[p];
  const Vec2 pairs = (0.0 * P.position[p] + 0.0 * P.velocity[p]) +
                     ((0.0 * F.col(0) + 0.0 * stress.col(0)) + (0.0 * F.col(1) + 0.0 * stress.col(1)));
  double zero = pairs.x() + pairs.y();
  if constexpr (Shape::geometry == Geometry::axisymmetric) zero += 0.0 * P.hoop_stress[p];
  if (!(zero == 0.0 && J > 0.0)) return false;
  if constexpr (std::is_same_v<Inside, std::nullptr_t>) return shape.inside(p);
  else return inside();
}

// The sum over nodes of |G_gp| of a stencil, each node counted once: a full
// stencil may list a node more than once (a stretched CPDI domain, once per
// corner that reaches it); one that is not full (cpdi.hpp) lists each node
// once already.
template <int N>
double entry_gradient_sum(const Stencil<N>& s);

template <int N>
double gradient_sum(const Stencil<N>& s) {
  if (s.count < N) return entry_gradient_sum(s);
  // The nodes merged (merged_gradients); then the lengths, computed apart
  // from the sum so that their square roots do not wait on one another.
  int node[N];
  Vec2 g[N];
  const int nodes = merged_gradients(s, node, g, [](int) { return false; });
  double length[N];
  for (int j = 0; j < nodes; ++j) length[j] = g[j].norm();
  double sum = 0.0;
  for (int j = 0; j < nodes; ++j) sum += length[j];
  return sum;
}

// The sum of |G_gp| over a stencil's entries as listed: at least the sum over
// nodes above (the triangle inequality), and equal to it, in the same order
// of additions, where no node repeats.
template <int N>
double entry_gradient_sum(const Stencil<N>& s) {
  double sum = 0.0;
  for (int k = 0; k < s.count; ++k) sum += s.gradient[k].norm();
  return sum;
}

// The same for particle p's stencil, evaluated here.
template <class Shape>
double gradient_sum(const Shape& shape, std::size_t p) {
  Stencil<Shape::stencil_size> s;
  shape.evaluate(p, s);
  return gradient_sum(s);
}

// How many times higher particle p lifts the grid's frequencies than the
// grid's own basis can: 1, or h sum_g |G_gp| / (2 + sqrt 2) where that is
// larger. The bilinear basis's gradients sum over the four nodes of a point
// to at most (2 + sqrt 2) / h (at a node: sqrt 2 + 1 + 1 + 0), and the step
// cfl h / (c + |v|) is set for them; any average of them over a domain (GIMP,
// exact CPDI) stays within that. CPDI interpolates the basis bilinearly
// between its domain's corners (002_c3305cb8b1bc1490.txt eq. 1.95); where a
// sheared domain's corners straddle cell lines the interpolant is not the
// basis, and its gradient, s_p^-T times differences of S_g between corners,
// grows as 1 / sin of the angle between r_1 and r_2. A particle's stiffness
// grows with the square of its gradients while its mass stays, so the
// frequencies it takes part in grow with them.
inline constexpr double kGridBasisGradientBound = 2.0 + 1.4142135623730951;  // times 1 / h

template <class Shape>
double stiffening(const Shape& shape, std::size_t p, double h) {
  if constexpr (Shape::gradients_beyond_grid_basis) {
    return std::max(1.0, h * gradient_sum(shape, p) / kGridBasisGradientBound);
  } else {
    return 1.0;
  }
}

// The same from the particle's stencil, where the caller has it.
template <int N>
double stiffening(const Stencil<N>& s, double h) {
  return std::max(1.0, h * gradient_sum(s) / kGridBasisGradientBound);
}

// The largest signal speed max(c_p, k_p c0_p) + |v_p| over particles (c_p +
// |v_p| where k_p = 1) and the first particle whose state stops the run. c_p is the material's
// wave speed bound at the particle's current state (it grows with the stress
// along a stretched direction), c0_p the small-strain wave speed
// sqrt((lambda + 2 mu) / rho_p), k_p the particle's stiffening (above), and
// rho_p = m_p / V_p. The corner interpolation's large gradients run across a
// sheared domain's thin width, the stress that stiffens the material along
// its stretched length, so the two lift the largest frequency each on its
// own, not as a product: on the ring at A = 1 (CPDI, 256 cells) the measured
// omega_max (Stepper::largest_frequency) grows 6.6 times by t = 0.5 s, k_p
// to 8.0, c_p / c0_p to about 4. Without k_p the step outgrows 2 / omega_max
// as the ring comes to rest most twisted, and finer meshes, taking more steps
// through that stretch, blow up first.
//
// Particle p's term, given the largest so far: k_p needs the particle's
// stencil, which is costly, and merging its repeated nodes, so it is formed
// only where the particle could set a new largest speed (the bounds below are
// exact-safe: the maximum is what forming every k_p gives). `stencil_of()`
// gives the particle's stencil where the caller has it at the same state
// (ScanInMap; asked for only where the bounds do not settle k_p), else null.
//
// Most particles cannot set a new largest: a bound of their speed without the
// material's logarithm and square roots (its wave_modulus_bound) rules them
// out first. The margin of 1e-9 covers the round-off of the exact terms, so a
// particle left out is one whose speed could not have changed the maximum.
template <class Shape, class Material, class StencilOf = std::nullptr_t>
double signal_speed(const Shape& shape, const Material& material, const Particles& P, double h, std::size_t p,
                    double largest, StencilOf stencil_of = nullptr, double stencil_gradient_bound = -1.0) {
  constexpr bool with_stencil = !std::is_null_pointer_v<StencilOf>;
  const double density = P.mass[p] / P.volume[p];
  const double F33 = out_of_plane_stretch<Shape::geometry>(P, p);
  const double v = P.velocity[p].norm();
  // With the stencil at hand the bound of k_p is its sum of |G| over entries,
  // which is k_p's own sum where no node repeats (a stencil that is not full);
  // the test that rules a particle out reads a bound of that sum without
  // square roots (entry_gradient_sum_bound, or the caller's
  // `stencil_gradient_bound` of the same stencil) and the sum itself only if
  // it has to.
  [[maybe_unused]] double most = 1.0;
  [[maybe_unused]] bool most_exact = true;
  if constexpr (Shape::gradients_beyond_grid_basis) {
    if constexpr (with_stencil) {
      const double bound =
          stencil_gradient_bound >= 0.0 ? stencil_gradient_bound : entry_gradient_sum_bound(stencil_of());
      // h bound / (2 + sqrt 2), lifted past what its rounding could take off:
      // where it is 1, k_p's own bound, no larger, is 1 too.
      constexpr double inverse = 1.0 / kGridBasisGradientBound;
      most = std::max(1.0, h * bound * inverse * (1.0 + 1e-12));
      most_exact = most == 1.0;
    } else {
      most = std::max(1.0, h * shape.gradient_sum_bound(p) / kGridBasisGradientBound);
    }
  }
  if constexpr (!requires { shape.cell_stretch(p); } &&
                requires { material.wave_modulus_bound(P.deformation_gradient[p], F33, P.stress[p]); }) {
    const double room = largest * (1.0 - 1e-9) - v;
    if (room > 0.0) {
      double modulus = material.wave_modulus_bound(P.deformation_gradient[p], F33, P.stress[p]);
      if constexpr (Shape::gradients_beyond_grid_basis)
        modulus = std::max(modulus, most * most * material.p_wave_modulus());
      if (modulus <= density * room * room) return 0.0;
    }
  }
  // Past the test, with the stencil at hand, k_p itself: the sum over
  // entries where no node repeats, else the sum over nodes (stiffening).
  // Either is at most the bound above, so a particle the next test leaves
  // out could not have set the maximum with it.
  if constexpr (Shape::gradients_beyond_grid_basis && with_stencil) {
    if (!most_exact) {
      const auto& stencil = stencil_of();
      most = stencil.count == Shape::stencil_size
                 ? stiffening(stencil, h)
                 : std::max(1.0, h * entry_gradient_sum(stencil) / kGridBasisGradientBound);
    }
  }
  const double c = std::sqrt(material.wave_modulus(P.deformation_gradient[p], F33, P.stress[p]) / density);
  double speed = c;
  // The total Lagrangian formulation: a wave crosses the current image of a
  // reference cell, F_p h along its most compressed direction.
  if constexpr (requires { shape.cell_stretch(p); }) speed = c / std::min(1.0, shape.cell_stretch(p));
  if constexpr (Shape::gradients_beyond_grid_basis) {
    const double c_small = std::sqrt(material.p_wave_modulus() / density);
    if (std::max(c, most * c_small) + v > largest) {
      double k = most;
      if constexpr (!with_stencil) k = stiffening(shape, p, h);
      if (k > 1.0) speed = std::max(c, k * c_small);
    }
  }
  return speed + v;
}

// One pass over particles [begin, end) of one material; first_unhealthy is
// P.size() when none of them stops the run.
template <class Shape, class Material>
ParticleScan scan_particles(const Shape& shape, const Material& material, const Particles& P, double h,
                            std::size_t begin = 0, std::size_t end = kAllParticles) {
  const std::size_t n = std::min(end, P.size());
  double max_speed = 0.0;
  std::size_t first = P.size();
#pragma omp parallel for schedule(static) reduction(max : max_speed) reduction(min : first)
  for (std::size_t p = begin; p < n; ++p) {
    if (!particle_healthy(shape, P, p)) {
      first = std::min(first, p);
      continue;
    }
    max_speed = std::max(max_speed, signal_speed(shape, material, P, h, p, max_speed));
  }
  return {max_speed, first};
}

// The screen's view of particles first, ..., first + count - 1 (count at
// most kLanes) with their stencils' bounds (the shape's lane_gradient_bounds,
// null where it has none: the screen reads them only for a shape that
// stiffens): P's own arrays where the batch is whole, else `copy` with the
// spare lanes repeating the first.
inline NeoHookeanScanLaneInput scan_lane_input(const Particles& P, std::size_t first, int count,
                                               const double* gradient_bound, NeoHookeanScanLaneCopy& copy) {
  if (count == kLanes)
    return {values_of(&P.position[first]),
            values_of(&P.velocity[first]),
            values_of(&P.deformation_gradient[first]),
            values_of(&P.stress[first]),
            P.mass.data() + first,
            P.volume.data() + first,
            gradient_bound};
  for (int l = 0; l < kLanes; ++l) {
    const std::size_t p = copied_lane_particle(first, count, l);
    std::copy_n(values_of(&P.position[p]), 2, copy.position + 2 * l);
    std::copy_n(values_of(&P.velocity[p]), 2, copy.velocity + 2 * l);
    std::copy_n(values_of(&P.deformation_gradient[p]), 4, copy.deformation_gradient + 4 * l);
    std::copy_n(values_of(&P.stress[p]), 4, copy.stress + 4 * l);
    copy.mass[l] = P.mass[p];
    copy.volume[l] = P.volume[p];
  }
  return {copy.position, copy.velocity, copy.deformation_gradient, copy.stress, copy.mass, copy.volume, gradient_bound};
}

// The same scan made by the map of the step to come (particles_to_grid), which
// weighs the state the scan reads and evaluates every particle's stencil
// anyway: the map tests a particle's health before it evaluates the stencil
// (an unhealthy particle's stencil may leave the grid) and skips one that
// fails; then the speed reads the stencil the map has. One material.
template <class Shape, class Material>
struct ScanInMap {
  const Shape& shape;
  const Material& material;
  const Particles& P;
  double h;
  ParticleScan result{0.0, P.size()};

  // Where the material has a lane kernel of the scan's first tests
  // (neo_hookean_lanes.hpp), in plane strain, the batch's particles are
  // screened together into `screen`: the scan then asks each only of what
  // the screen left open. A shape whose gradients reach beyond the grid
  // basis needs the lane kernel's bounds of its stencils for that, so it is
  // screened only where it evaluates by lanes. Otherwise the screen stays
  // empty.
  static constexpr bool screens = std::is_same_v<Material, NeoHookean> &&
                                  (evaluates_lanes<Shape>() || !Shape::gradients_beyond_grid_basis) &&
                                  Shape::geometry == Geometry::plane_strain &&
                                  !requires(const Shape& s) { s.cell_stretch(std::size_t(0)); };

  void screen_lanes(std::size_t first, int count, const double* gradient_bounds, double largest,
                    ScanScreen& screen) const {
    if constexpr (screens) {
      const NeoHookeanScanLaneParams params{material.lambda, material.mu, material.p_wave_modulus(), largest, h,
                                            1.0 / kGridBasisGradientBound, Shape::gradients_beyond_grid_basis};
      NeoHookeanScanLaneCopy copy;
      const NeoHookeanScanLaneInput in = scan_lane_input(P, first, count, gradient_bounds, copy);
      neo_hookean_scan_lanes(params, in, screen.verdict);
      screen.first = first;
      screen.valid = true;
    }
  }

  template <class Inside>
  bool healthy(std::size_t p, Inside inside, const ScanScreen& screen = {}) const {
    if constexpr (screens) {
      if (screen.valid) return screen.verdict.sound[p - screen.first] != 0 && inside();
    }
    return particle_healthy(shape, P, p, inside);
  }
  // `stencil_of()` gives the particle's stencil; `gradient_bound` is its
  // entry_gradient_sum_bound where the caller has it, else negative.
  template <class StencilOf>
  double speed(std::size_t p, StencilOf stencil_of, double largest, double gradient_bound = -1.0,
               const ScanScreen& screen = {}) const {
    if constexpr (screens) {
      if (screen.valid && screen.verdict.may_set_speed[p - screen.first] == 0) return 0.0;
    }
    return signal_speed(shape, material, P, h, p, largest, stencil_of, gradient_bound);
  }
};

// The scan of a run with two materials: the larger speed, the first particle.
inline ParticleScan combined(const ParticleScan& a, const ParticleScan& b) {
  return {std::max(a.max_signal_speed, b.max_signal_speed), std::min(a.first_unhealthy, b.first_unhealthy)};
}

}  // namespace mpmvv
