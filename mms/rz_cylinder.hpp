// A pulsating cylinder in r-z (PROBLEMS.md section 2b): the body of revolution
// R_i <= R <= R_o, 0 <= Z <= H breathes radially,
//   u_r = g(t) R q(R) cos(pi Z / H),  u_z = 0,  g(t) = (A/2)(1 - cos 2 pi t / T),
// so the hoop stretch F_theta = r / R = 1 + g q cos(pi Z / H) differs from the
// in-plane stretches and the hoop stress enters the radial balance.
//   hollow (R_i > 0): q = 16 ((R - R_i)(R_o - R))^2 / (R_o - R_i)^4
//   solid  (R_i = 0): q = ((R_o - R) / R_o)^2, nonzero on the axis, where
//                     F_theta = F_rR as symmetry requires.
// q and q' vanish at R_o (and at R_i when hollow), and du_r/dZ vanishes at Z = 0
// and H: the rims are traction-free and roller walls at Z = 0, H are exact.
#pragma once

#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace mpmvv::mms {

struct RzCylinderMotion {
  double inner_radius = 0.25;  // R_i [m]; 0 for a solid cylinder
  double outer_radius = 1.0;   // R_o [m]
  double height = 1.0;         // H [m]
  double amplitude = 0.2;      // A: the largest of g(t)
  double period = 1.0;         // T [s]

  template <class S>
  S q(const S& R) const {
    const S outer = (S(outer_radius) - R) / S(outer_radius - inner_radius);
    if (inner_radius <= 0.0) return outer * outer;
    const S inner = (R - S(inner_radius)) / S(outer_radius - inner_radius);
    return S(16.0) * inner * inner * outer * outer;
  }

  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    using std::cos;
    using std::numbers::pi;
    const S g = S(0.5 * amplitude) * (S(1.0) - cos(S(2.0 * pi / period) * t));
    return {X.x() * (S(1.0) + g * q(X.x()) * cos(S(pi / height) * X.y())), X.y()};
  }
  double length_scale() const { return outer_radius - inner_radius; }
  double time_scale() const { return period; }
};

}  // namespace mpmvv::mms
