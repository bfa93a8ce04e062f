// The constitutive update of every particle, and the artificial bulk viscosity
// (eqs. 1.66-1.67). A stage of solver/stages.hpp.
#pragma once

#include "dilatation.hpp"

namespace mpmvv {

// ---------------------------------------------------------------- constitutive update

// Particles [begin, end) of the material (a run with two materials calls it
// once for each, SceneStages::second_material); by default every particle.
inline constexpr std::size_t kAllParticles = std::size_t(-1);

template <Geometry G, class Material>
void update_stress(const Material& material, Particles& P, std::size_t begin = 0, std::size_t end = kAllParticles) {
  const std::size_t n = std::min(end, P.size());
  if constexpr (G == Geometry::axisymmetric) {
#pragma omp parallel for schedule(static)
    for (std::size_t p = begin; p < n; ++p) {
      const Stress<double> sigma = material.stress(P.deformation_gradient[p], P.hoop_stretch[p]);
      P.stress[p] = sigma.in_plane;
      P.hoop_stress[p] = sigma.out_of_plane;
    }
  } else if constexpr (requires { material.cauchy_stress_array(n, P.deformation_gradient.data(), P.stress.data()); }) {
    // A material that forms its stresses by lanes takes each thread's block at once.
#pragma omp parallel
    {
      const auto [first, last] = static_block(begin, n);
      if (last > first) material.cauchy_stress_array(last - first, &P.deformation_gradient[first], &P.stress[first]);
    }
  } else {
#pragma omp parallel for schedule(static)
    for (std::size_t p = begin; p < n; ++p) P.stress[p] = material.cauchy_stress(P.deformation_gradient[p]);
  }
}

// ---------------------------------------------------------------- bulk viscosity

// The artificial bulk viscosity of 002_c3305cb8b1bc1490.txt eqs. 1.66-1.67,
// sigma_p <- sigma_p - q_p I, with
//   q_p = -rho_p l_p (C0 c_p + C1 l_p |tr d_p|) tr d_p,
// c_p = sqrt(M / rho_p) the p-wave speed (eq. 1.66 writes sqrt(K / rho); the
// coefficient takes up the ratio) and tr d_p the particle's rate of
// dilatation over the step, ln(V_p / V_p_before) / dt. Eq. 1.66 puts |tr d| in
// the linear term, which would make q a pressure in expansion too; here q
// takes the sign of -tr d, so the stress power -q tr d V_p =
// rho l (C0 c + C1 l |tr d|) (tr d)^2 V_p is never negative: it dissipates in
// compression and expansion alike. A motion that keeps volume (the ring's,
// J = 1) feels it only through the dilatation the method gets wrong. In r-z
// the hoop stress takes the same -q.
// The length l_p is the particle's own thinnest width, the area of the
// method's domain (shape.domain, as the monitors read it) over its longest
// side (at most the cell size h; h for a method without one, linear and
// B-spline MPM). Eq. 1.66 suggests h; but a viscous stress is stable only to a
// step that shrinks with the square of the width its gradients act across,
// and a sheared CPDI domain grows thin: with l = h the ring at A = 1 on 256
// cells, which completes without viscosity, stopped with nan at t = 0.315 s
// (C0 = 0.2) and 0.398 s (C0 = 0.05).
struct ViscousStep {
  double dissipated = 0.0;  // sum_p -q_p tr d_p V_p dt >= 0 [J per unit depth]
  double max_ratio = 0.0;   // max_p C0 + C1 l_p |tr d_p| / c_p, the damping ratio xi of the fastest mode
};

template <class Shape>
ViscousStep add_bulk_viscosity(const Shape& shape, Particles& P, const std::vector<double>& volume_before,
                               double wave_modulus, double h, double c0, double c1, double dt, std::size_t begin = 0,
                               std::size_t end = kAllParticles) {
  constexpr Geometry G = Shape::geometry;
  constexpr bool has_domain = Shape::has_domain;
  const std::size_t n = std::min(end, P.size());
  double max_ratio = 0.0;
  ThreadOrderedSums<1> dissipated;
#pragma omp parallel
  {
    double own = 0.0;
#pragma omp for schedule(static) reduction(max : max_ratio)
    for (std::size_t p = begin; p < n; ++p) {
      const double rate = std::log(P.volume[p] / volume_before[p]) / dt;
      if (!std::isfinite(rate)) continue;  // the health scan reports the particle
      double l = h;
      if constexpr (has_domain) {  // the method's domain, half-vectors r1, r2: area over longest side
        const Mat2 s = shape.domain(p);
        l = std::min(h, 2.0 * std::abs(determinant(s)) / std::max(s.col(0).norm(), s.col(1).norm()));
      }
      const double density = P.mass[p] / P.volume[p];
      const double c = std::sqrt(wave_modulus / density);
      const double q = -density * l * (c0 * c + c1 * l * std::abs(rate)) * rate;
      P.stress[p](0, 0) -= q;
      P.stress[p](1, 1) -= q;
      if constexpr (G == Geometry::axisymmetric) P.hoop_stress[p] -= q;
      own += -q * rate * P.volume[p] * dt;
      max_ratio = std::max(max_ratio, c0 + c1 * l * std::abs(rate) / c);
    }
    dissipated.keep({own});
  }
  return {dissipated.total()[0], max_ratio};
}

// A run's bulk viscosity between its stages: the coefficients, the volumes
// before a deformation update (from which the step's dilatation is taken)
// and the damping ratio of the last step.
struct BulkViscosity {
  double linear = 0.0, quadratic = 0.0;  // C0, C1 (add_bulk_viscosity); 0: none
  double ratio = 0.0;                    // xi of the last step (ViscousStep::max_ratio)
  std::vector<double> volume_before;     // V_p before the deformation update
  bool on() const { return linear > 0.0 || quadratic > 0.0; }
  void remember_volumes(const Particles& P) {
    if (on()) volume_before = P.volume;
  }
  // With bulk viscosity the fastest grid mode is damped at the ratio xi of the
  // last step, and central differences are stable to dt = (2 / omega)
  // (sqrt(1 + xi^2) - xi): the signal speed grows by sqrt(1 + xi^2) + xi.
  double signal_speed_factor() const { return std::sqrt(1.0 + ratio * ratio) + ratio; }
};

}  // namespace mpmvv
