// Compressible neo-Hookean solid in plane strain,
//   sigma = (lambda ln J / J) I + (mu / J)(F F^T - I)
// (000_1dbcb8acb6dddab9.txt eq. 2.2). With F_zz = 1 the in-plane block of B is
// the in-plane F F^T and J is the in-plane determinant.
#pragma once

#include <cmath>

#include "../tensor.hpp"

namespace mpmvv {

struct NeoHookean {
  static constexpr const char* name = "neo-hookean";
  double lambda;  // first Lame constant [Pa]
  double mu;      // shear modulus [Pa]

  // Generic over the scalar so that exact solutions can differentiate it.
  template <class T>
  Eigen::Matrix<T, 2, 2> cauchy_stress(const Eigen::Matrix<T, 2, 2>& F) const {
    using std::log;
    const T J = F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
    const Eigen::Matrix<T, 2, 2> B = F * F.transpose();
    return (T(lambda) * log(J) / J) * Eigen::Matrix<T, 2, 2>::Identity() +
           (T(mu) / J) * (B - Eigen::Matrix<T, 2, 2>::Identity());
  }

  // Small-strain P-wave modulus lambda + 2 mu.
  double p_wave_modulus() const { return lambda + 2.0 * mu; }

  // Upper bound of rho c^2 over in-plane directions at the current state, for
  // the time step. The spatial tangent of the Kirchhoff stress is
  // lambda I(x)I + 2 (mu - lambda ln J) II, and a stressed medium adds the
  // geometric term sigma_nn to the acoustic tensor, so
  //   rho c^2 <= (lambda + 2 |mu - lambda ln J|) / J + max(sigma_max, 0).
  // Under the ring's shear of 3 this is four times lambda + 2 mu.
  double wave_modulus(const Mat2& F, const Mat2& sigma) const {
    const double J = determinant(F);
    return (std::abs(lambda) + 2.0 * std::abs(mu - lambda * std::log(J))) / J +
           std::max(largest_principal(sigma), 0.0);
  }
};

}  // namespace mpmvv
