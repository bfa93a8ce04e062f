// Axial vibration of a fixed-free bar (PROBLEMS.md section 5): u(0, t) = 0,
// sigma(L, t) = 0, u_tt = c^2 u_XX with c = sqrt(M / rho) (M = E for a thin
// bar; M = lambda + 2 mu in uniaxial strain, a 2D strip between rollers).
// Modes phi_n = sin(k_n X), k_n = (2n - 1) pi / (2 L), omega_n = c k_n; from
// u(X, 0) = u0(X) and v(X, 0) = v0(X),
//   u(X, t) = sum_n [A_n cos(omega_n t) + B_n sin(omega_n t)] phi_n(X),
//   A_n = (2/L) int u0 phi_n,  B_n = (2 / (L omega_n)) int v0 phi_n.
// Two initial states are given in closed form: the first mode alone
// (v0 = V phi_1) and a uniform initial velocity (B_n = 2 V / (L omega_n k_n)),
// whose series is summed to N terms (its terms fall as 1/n^2).
#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace mpmvv::analytic {

struct VibratingBar {
  double length;      // L [m]
  double wave_speed;  // c [m/s]

  double wavenumber(int n) const { return (2 * n - 1) * std::numbers::pi / (2.0 * length); }
  double frequency(int n) const { return wave_speed * wavenumber(n); }  // omega_n [rad/s]
  double period(int n = 1) const { return 2.0 * std::numbers::pi / frequency(n); }

  // v0 = V sin(k_1 X): u = (V / omega_1) sin(k_1 X) sin(omega_1 t).
  double first_mode_displacement(double V, double X, double t) const {
    return V / frequency(1) * std::sin(wavenumber(1) * X) * std::sin(frequency(1) * t);
  }
  double first_mode_velocity(double V, double X, double t) const {
    return V * std::sin(wavenumber(1) * X) * std::cos(frequency(1) * t);
  }

  // v0 = V everywhere, u0 = 0: the series to `terms` terms.
  double uniform_velocity_displacement(double V, double X, double t, int terms) const {
    double u = 0.0;
    for (int n = 1; n <= terms; ++n)
      u += 2.0 * V / (length * frequency(n) * wavenumber(n)) * std::sin(wavenumber(n) * X) * std::sin(frequency(n) * t);
    return u;
  }
};

// The first mode as a motion x = X + u e_x for the scenes' exact fields and
// probes, generic over the scalar like the manufactured motions.
struct VibratingBarMotion {
  VibratingBar bar;
  double velocity_amplitude;  // V [m/s]

  template <class S>
  Eigen::Matrix<S, 2, 1> displacement(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    using std::sin;
    const S k(bar.wavenumber(1)), omega(bar.frequency(1));
    return {S(velocity_amplitude / bar.frequency(1)) * sin(k * X.x()) * sin(omega * t), S(0.0)};
  }
  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    return X + displacement(X, t);
  }
  double length_scale() const { return bar.length; }
  double time_scale() const { return bar.period(1); }
};

}  // namespace mpmvv::analytic
