// Small-strain linear elastic solid: sigma = lambda tr(eps) I + 2 mu eps with
// eps = sym(F) - I, F = diag(F_inplane, F_33). Valid for small displacement
// gradients only (it is not objective under finite rotation); the reference
// for the uniaxial and Hertz problems (PROBLEMS.md sections 4-5) and the
// small-deformation manufactured solutions.
#pragma once

#include "../tensor.hpp"
#include "stress.hpp"

namespace mpmvv {

struct LinearElastic {
  static constexpr const char* name = "linear-elastic";
  static constexpr bool finite_strain = false;  // not objective; sigma is dW/d(grad u)
  double lambda;  // [Pa]
  double mu;      // [Pa]

  template <class T>
  Stress<T> stress(const Eigen::Matrix<T, 2, 2>& F, const T& F33) const {
    using M = Eigen::Matrix<T, 2, 2>;
    const M eps = T(0.5) * (F + F.transpose()) - M::Identity();
    const T eps33 = F33 - T(1.0);
    const T volumetric = T(lambda) * (eps(0, 0) + eps(1, 1) + eps33);
    return {volumetric * M::Identity() + T(2.0 * mu) * eps, volumetric + T(2.0 * mu) * eps33};
  }

  template <class T>
  Eigen::Matrix<T, 2, 2> cauchy_stress(const Eigen::Matrix<T, 2, 2>& F) const {
    return stress(F, T(1.0)).in_plane;
  }

  // Stored energy per reference volume, lambda/2 (tr eps)^2 + mu eps:eps.
  // Generic over the scalar so that the material driver differentiates it.
  template <class T>
  T energy_density(const Eigen::Matrix<T, 2, 2>& F, const T& F33) const {
    using M = Eigen::Matrix<T, 2, 2>;
    const M eps = T(0.5) * (F + F.transpose()) - M::Identity();
    const T eps33 = F33 - T(1.0);
    const T trace = eps.trace() + eps33;
    return T(0.5 * lambda) * trace * trace + T(mu) * (eps.squaredNorm() + eps33 * eps33);
  }

  double p_wave_modulus() const { return lambda + 2.0 * mu; }
  // The small-strain Lame constants (lambda, mu).
  SmallStrainModuli small_strain_moduli() const { return {lambda, mu}; }
  // The tangent is constant: rho c^2 = lambda + 2 mu in every state.
  double wave_modulus(const Mat2&, double, const Mat2&) const { return p_wave_modulus(); }
  double wave_modulus(const Mat2& F, const Mat2& sigma) const { return wave_modulus(F, 1.0, sigma); }
};

}  // namespace mpmvv
