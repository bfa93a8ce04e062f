// Axis-aligned MMS (PROBLEMS.md section 3, after Wallstedt & Guilkey 2008 and
// Steffen et al. 2008): a smooth small-deformation motion of the unit square
// with no geometry error, which isolates the spatial and temporal order.
//   2D: u_x = A sin(pi X) sin(c pi t),  u_y = A sin(pi Y) sin(pi (2/3 + c t))
//   1D: u_x = A sin(2 pi X / L) cos(c pi t / L), u_y = 0 (a strip in uniaxial strain)
// with c = sqrt(E / rho_0). Both vanish on the boundary of the body, so roller
// walls there are exact.
#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace mpmvv::mms {

struct AxisAlignedMotion {
  double amplitude = 0.05;     // A [m]
  double wave_speed = 100.0;   // c = sqrt(E / rho_0) [m/s]
  double length = 1.0;         // L, the side of the square or the strip [m]
  bool one_dimensional = false;

  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    using std::cos;
    using std::numbers::pi;
    using std::sin;
    const S A(amplitude), c(wave_speed), L(length);
    if (one_dimensional) return {X.x() + A * sin(S(2.0 * pi) * X.x() / L) * cos(c * S(pi) * t / L), X.y()};
    return {X.x() + A * sin(S(pi) * X.x() / L) * sin(c * S(pi) * t / L),
            X.y() + A * sin(S(pi) * X.y() / L) * sin(S(pi) * (S(2.0 / 3.0) + c * t / L))};
  }
  double length_scale() const { return length; }
  double time_scale() const { return length / wave_speed; }
};

}  // namespace mpmvv::mms
