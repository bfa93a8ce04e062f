// Expanding ring, plane strain (PROBLEMS.md section 2a, the "ExpandingRing"
// problem of the Uintah MPM code): a radial motion of the ring r_i <= R <= r_o,
//   u(X, t) = A sin(C pi t / (2 r_b)) (c1 + c2 R + c3 R^2) X,
//   C = sqrt(E / rho_0), r_b = (r_i + r_o) / 2,
//   c1 = -6 r_i / (r_o (r_o - 3 r_i)), c2 = 3 (r_o + r_i) / (r_o^2 (r_o - 3 r_i)),
//   c3 = -2 / (r_o^2 (r_o - 3 r_i)).
// d u_r / dR vanishes at both rims, so with nu = 0 (lambda = 0) the rims are
// traction-free; they still carry hoop stress. The `bubble` profile
// 16 ((R - r_i)(r_o - R))^2 / (r_o - r_i)^4 in place of c1 + c2 R + c3 R^2
// vanishes with its slope at both rims, so F = I there and the rims carry no
// stress at all (as the ring of PROBLEMS.md section 1): the control case that
// tells a curved stressed free surface from the rest of the method.
#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace mpmvv::mms {

struct ExpandingRingMotion {
  double inner_radius = 0.4;   // r_i [m]
  double outer_radius = 0.6;   // r_o [m]
  double amplitude = 0.1;      // A
  double wave_speed = 100.0;   // C = sqrt(E / rho_0) [m/s]
  bool bubble = false;         // the stress-free-rim profile instead of Uintah's

  double c1() const { return -6.0 * inner_radius / (outer_radius * (outer_radius - 3.0 * inner_radius)); }
  double c2() const {
    return 3.0 * (outer_radius + inner_radius) /
           (outer_radius * outer_radius * (outer_radius - 3.0 * inner_radius));
  }
  double c3() const { return -2.0 / (outer_radius * outer_radius * (outer_radius - 3.0 * inner_radius)); }
  double mean_radius() const { return 0.5 * (inner_radius + outer_radius); }

  // The radial profile f(R) of u = A g(t) f(R) X.
  template <class S>
  S profile(const S& R) const {
    if (bubble) {
      const double w = outer_radius - inner_radius;
      const S b = (R - S(inner_radius)) * (S(outer_radius) - R);
      return S(16.0 / (w * w * w * w)) * b * b;
    }
    return S(c1()) + S(c2()) * R + S(c3()) * R * R;
  }

  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    using std::numbers::pi;
    using std::sin;
    using std::sqrt;
    const S R = sqrt(X.x() * X.x() + X.y() * X.y());
    const S stretch = S(1.0) + S(amplitude) * sin(S(wave_speed * pi / (2.0 * mean_radius())) * t) * profile(R);
    return {stretch * X.x(), stretch * X.y()};
  }
  double length_scale() const { return outer_radius - inner_radius; }
  double time_scale() const { return 2.0 * mean_radius() / wave_speed; }
};

}  // namespace mpmvv::mms
