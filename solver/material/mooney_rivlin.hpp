// Compressible Mooney-Rivlin solid. 000_1dbcb8acb6dddab9.txt eq. 2.18 as
// printed is not stress-free at F = I; the code it was typeset from
// (appendix C, MOONR.F, the STRESS lines) adds the volumetric term K ln J:
//   sigma = (1/J) [ K ln J I + 2 J^(-2/3) (C1 + I1b C2) B - 2 J^(-4/3) C2 B.B
//                   - (2/3)(C1 I1b + 2 C2 I2b) I ],
// I1b = J^(-2/3) I1, I2b = J^(-4/3) I2, the invariants of the 3D B = F F^T.
// This is the stress of W = C1 (I1b - 3) + C2 (I2b - 3) + (K/2)(ln J)^2.
// With F = diag(F_inplane, F_33): B = diag(B2, F_33^2), so
// I1 = tr B2 + F_33^2 and I2 = det B2 + tr B2 F_33^2.
#pragma once

#include <algorithm>
#include <cmath>

#include "../tensor.hpp"
#include "stress.hpp"

namespace mpmvv {

struct MooneyRivlin {
  static constexpr const char* name = "mooney-rivlin";
  static constexpr bool finite_strain = true;  // objective; sigma is J^-1 dW/dF F^T
  double c1;             // [Pa]
  double c2;             // [Pa]
  double bulk_modulus;   // K [Pa]

  template <class T>
  Stress<T> stress(const Eigen::Matrix<T, 2, 2>& F, const T& F33) const {
    using std::log;
    using std::pow;
    using M = Eigen::Matrix<T, 2, 2>;
    const T J = (F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0)) * F33;
    const M B = F * F.transpose();
    const T b33 = F33 * F33;
    const T trace_b = B(0, 0) + B(1, 1);
    const T det_b = B(0, 0) * B(1, 1) - B(0, 1) * B(1, 0);
    const T j23 = pow(J, T(-2.0 / 3.0));
    const T j43 = j23 * j23;
    const T i1_bar = j23 * (trace_b + b33);
    const T i2_bar = j43 * (det_b + trace_b * b33);
    const T a = T(2.0) * j23 * (T(c1) + i1_bar * T(c2));  // factor of B
    const T c = T(2.0) * j43 * T(c2);                      // factor of B.B
    const T p = T(bulk_modulus) * log(J) - T(2.0 / 3.0) * (T(c1) * i1_bar + T(2.0) * T(c2) * i2_bar);
    return {(p * M::Identity() + a * B - c * (B * B)) / J, (p + a * b33 - c * b33 * b33) / J};
  }

  template <class T>
  Eigen::Matrix<T, 2, 2> cauchy_stress(const Eigen::Matrix<T, 2, 2>& F) const {
    return stress(F, T(1.0)).in_plane;
  }

  // Stored energy per reference volume, W above.
  // Generic over the scalar so that the material driver differentiates it.
  template <class T>
  T energy_density(const Eigen::Matrix<T, 2, 2>& F, const T& F33) const {
    using std::log;
    using std::pow;
    const T J = (F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0)) * F33;
    const Eigen::Matrix<T, 2, 2> B = F * F.transpose();
    const T b33 = F33 * F33;
    const T j23 = pow(J, -2.0 / 3.0);
    const T i1_bar = j23 * (B.trace() + b33);
    const T i2_bar = j23 * j23 * ((B(0, 0) * B(1, 1) - B(0, 1) * B(1, 0)) + B.trace() * b33);
    const T lnJ = log(J);
    return T(c1) * (i1_bar - T(3.0)) + T(c2) * (i2_bar - T(3.0)) + T(0.5 * bulk_modulus) * lnJ * lnJ;
  }

  double shear_modulus() const { return 2.0 * (c1 + c2); }
  double p_wave_modulus() const { return bulk_modulus + 4.0 / 3.0 * shear_modulus(); }
  // The small-strain Lame constants: mu = 2 (C1 + C2), lambda = K - 2 mu / 3.
  SmallStrainModuli small_strain_moduli() const { return {bulk_modulus - 2.0 / 3.0 * shear_modulus(), shear_modulus()}; }

  // Estimate of rho c^2 at the current state, for the time step. The volumetric
  // Kirchhoff stress K ln J I has the spatial tangent K I(x)I - 2 K ln J II,
  // whose largest acoustic eigenvalue is at most K (1 + 2 |ln J|). The
  // isochoric stress is built from B_bar and B_bar^2, so its stiffness grows
  // with the largest principal value b of B_bar: bounded here by
  // (4/3) 2 (|C1| + |C2| I1b) b + 4 |C2| b^2 (which at F = I is at most three
  // times the exact 4/3 G). The stress adds its geometric term. Checked against
  // the numerically computed acoustic tensor over random F in compression and
  // tension (tests/test_materials.cpp); not a proof.
  double wave_modulus(const Mat2& F, double F33, const Mat2& sigma) const {
    const double J = determinant(F) * F33;
    const double j23 = std::pow(J, -2.0 / 3.0);
    const Mat2 B = F * F.transpose();
    const double i1_bar = j23 * (B.trace() + F33 * F33);
    const double b = j23 * std::max(largest_principal(B), F33 * F33);
    const double isochoric = 4.0 / 3.0 * 2.0 * (std::abs(c1) + std::abs(c2) * i1_bar) * b + 4.0 * std::abs(c2) * b * b;
    return (bulk_modulus * (1.0 + 2.0 * std::abs(std::log(J))) + isochoric) / J +
           std::max(largest_principal(sigma), 0.0);
  }
  double wave_modulus(const Mat2& F, const Mat2& sigma) const { return wave_modulus(F, 1.0, sigma); }
};

}  // namespace mpmvv
