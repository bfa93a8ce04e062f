// Compressible neo-Hookean solid,
//   sigma = (lambda ln J / J) I + (mu / J)(F F^T - I)
// (000_1dbcb8acb6dddab9.txt eq. 2.2), with F = diag(F_inplane, F_33), so
// B = diag(F F^T, F_33^2) and J = det(F_inplane) F_33.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "../tensor.hpp"
#include "neo_hookean_lanes.hpp"
#include "stress.hpp"

namespace mpmvv {

struct NeoHookean {
  static constexpr const char* name = "neo-hookean";
  static constexpr bool finite_strain = true;  // objective; sigma is J^-1 dW/dF F^T
  double lambda;  // first Lame constant [Pa]
  double mu;      // shear modulus [Pa]

  // Generic over the scalar so that manufactured solutions can differentiate it.
  template <class T>
  Stress<T> stress(const Eigen::Matrix<T, 2, 2>& F, const T& F33) const {
    using std::log;
    using M = Eigen::Matrix<T, 2, 2>;
    const T J = (F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0)) * F33;
    const T pressure_like = T(lambda) * log(J) / J;
    const T shear = T(mu) / J;
    const M B = F * F.transpose();
    return {pressure_like * M::Identity() + shear * (B - M::Identity()), pressure_like + shear * (F33 * F33 - T(1.0))};
  }

  // Plane strain (F_33 = 1): the in-plane block.
  template <class T>
  Eigen::Matrix<T, 2, 2> cauchy_stress(const Eigen::Matrix<T, 2, 2>& F) const {
    return stress(F, T(1.0)).in_plane;
  }

  // cauchy_stress of n particles at once, in lanes (neo_hookean_lanes.hpp):
  // the same operations with the lanes' ln J, within a unit in the last
  // place. A J that is not positive, finite and normal (the state the scan
  // then stops on) takes the scalar stress above.
  void cauchy_stress_array(std::size_t n, const Mat2* F, Mat2* sigma) const {
    if (neo_hookean_lane_stress({lambda, mu}, n, values_of(F), values_of(sigma)) == 0) return;
    for (std::size_t p = 0; p < n; ++p)
      if (!lane_stress_takes(determinant(F[p]))) sigma[p] = cauchy_stress(F[p]);
  }

  // Stored energy per reference volume, psi = mu/2 (I1 - 3) - mu ln J +
  // lambda/2 (ln J)^2, whose Kirchhoff stress is the stress above. Generic
  // over the scalar so that the material driver differentiates it.
  template <class T>
  T energy_density(const Eigen::Matrix<T, 2, 2>& F, const T& F33) const {
    using std::log;
    const T J = (F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0)) * F33;
    const T I1 = (F * F.transpose()).trace() + F33 * F33;
    const T lnJ = log(J);
    return T(0.5 * mu) * (I1 - T(3.0)) - T(mu) * lnJ + T(0.5 * lambda) * lnJ * lnJ;
  }

  // Small-strain P-wave modulus lambda + 2 mu.
  double p_wave_modulus() const { return lambda + 2.0 * mu; }
  // The small-strain Lame constants (lambda, mu).
  SmallStrainModuli small_strain_moduli() const { return {lambda, mu}; }

  // Upper bound of rho c^2 over in-plane directions at the current state, for
  // the time step. The spatial tangent of the Kirchhoff stress is
  // lambda I(x)I + 2 (mu - lambda ln J) II, and a stressed medium adds the
  // geometric term sigma_nn to the acoustic tensor, so
  //   rho c^2 <= (lambda + 2 |mu - lambda ln J|) / J + max(sigma_max, 0).
  // Under the ring's shear of 3 this is four times lambda + 2 mu.
  double wave_modulus(const Mat2& F, double F33, const Mat2& sigma) const {
    const double J = determinant(F) * F33;
    return (std::abs(lambda) + 2.0 * std::abs(mu - lambda * std::log(J))) / J +
           std::max(largest_principal(sigma), 0.0);
  }
  double wave_modulus(const Mat2& F, const Mat2& sigma) const { return wave_modulus(F, 1.0, sigma); }

  // An upper bound of wave_modulus without its logarithm and square root, for
  // the time-step scan's early test (stages.hpp: signal_speed): ln J lies in
  // [1 - 1/J, J - 1], and |mu - lambda x| is largest at an end of it; the
  // largest principal stress mean + sqrt(d^2 + s_xy^2) is at most
  // max(s_xx, s_yy) + |s_xy|.
  double wave_modulus_bound(const Mat2& F, double F33, const Mat2& sigma) const {
    const double J = determinant(F) * F33;
    const double shear = std::max(std::abs(mu - lambda * (J - 1.0)), std::abs(mu - lambda * (1.0 - 1.0 / J)));
    return (std::abs(lambda) + 2.0 * shear) / J +
           std::max(std::max(sigma(0, 0), sigma(1, 1)) + std::abs(sigma(0, 1)), 0.0);
  }
};

}  // namespace mpmvv
