// Axial vibration of a fixed-free bar of two layers (soft against stiff,
// PROBLEMS.md section 6): layer 1 on 0 <= X <= L1 (P-wave modulus M1, density
// rho1, c1 = sqrt(M1 / rho1)), layer 2 on L1 <= X <= L = L1 + L2 (M2, rho2, c2),
// bonded at X = L1, u(0) = 0 and sigma(L) = 0. In each layer u_tt = c_i^2 u_XX,
// so a mode of angular frequency omega is
//   phi(X) = sin(k1 X)                      on layer 1,
//   phi(X) = B cos(k2 (L - X))              on layer 2,   k_i = omega / c_i,
// with u and the traction M u_X continuous at L1:
//   sin(k1 L1) = B cos(k2 L2),   M1 k1 cos(k1 L1) = M2 k2 B sin(k2 L2),
// which leave the frequency equation
//   tan(omega L1 / c1) tan(omega L2 / c2) = Z1 / Z2,   Z_i = sqrt(M_i rho_i)
// (the impedances; M_i k_i = omega Z_i). With equal layers it is
// tan^2(omega L1 / c) = 1, omega = pi c / 2L: the one-layer bar. Its first root
// lies below pi / (2 max(L1 / c1, L2 / c2)), where one tangent has its pole.
// Started in the first mode, v0 = V phi(X), the bar moves as
// u = (V / omega) phi(X) sin(omega t).
#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace mpmvv::analytic {

struct LayeredBar {
  double length_1, length_2;       // L1, L2 [m]
  double modulus_1, modulus_2;     // M1, M2 [Pa]
  double density_1, density_2;     // rho1, rho2 [kg/m^3]

  double length() const { return length_1 + length_2; }
  double wave_speed_1() const { return std::sqrt(modulus_1 / density_1); }
  double wave_speed_2() const { return std::sqrt(modulus_2 / density_2); }
  double impedance_ratio() const { return std::sqrt(modulus_1 * density_1 / (modulus_2 * density_2)); }  // Z1 / Z2

  // sin(a w) sin(b w) - (Z1/Z2) cos(a w) cos(b w): the frequency equation
  // without the tangents' poles (zero where it holds, negative at w = 0).
  double frequency_residual(double omega) const {
    const double a = length_1 / wave_speed_1(), b = length_2 / wave_speed_2();
    return std::sin(a * omega) * std::sin(b * omega) - impedance_ratio() * std::cos(a * omega) * std::cos(b * omega);
  }

  // The first root omega_1 [rad/s], by KINSOL to a residual below `tolerance`
  // from a bisection bracket (layered_bar.cpp); throws when it cannot find it.
  double first_frequency(double tolerance = 1e-14) const;

  // B of the second layer's cos(k2 (L - X)), from the continuity of u at L1.
  double second_amplitude(double omega) const {
    return std::sin(omega / wave_speed_1() * length_1) / std::cos(omega / wave_speed_2() * length_2);
  }
};

// The first mode as a motion x = X + u e_x for the scene's exact fields and
// probes, generic over the scalar like the manufactured motions.
struct LayeredBarMotion {
  LayeredBar bar;
  double omega;               // omega_1, from bar.first_frequency()
  double velocity_amplitude;  // V [m/s]

  template <class S>
  S mode(const S& X) const {
    using std::cos;
    using std::sin;
    if (X < S(bar.length_1)) return sin(S(omega / bar.wave_speed_1()) * X);
    return S(bar.second_amplitude(omega)) * cos(S(omega / bar.wave_speed_2()) * (S(bar.length()) - X));
  }
  template <class S>
  Eigen::Matrix<S, 2, 1> displacement(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    using std::sin;
    return {S(velocity_amplitude / omega) * mode(X.x()) * sin(S(omega) * t), S(0.0)};
  }
  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    return X + displacement(X, t);
  }
  double length_scale() const { return bar.length(); }
  double time_scale() const { return 2.0 * std::numbers::pi / omega; }
};

}  // namespace mpmvv::analytic
