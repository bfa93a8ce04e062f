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

#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include <Eigen/Core>

#include "force_field.hpp"
#include "jet.hpp"
#include "solver/material/neo_hookean.hpp"

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

  // Separable (manufactured.hpp): q(R) and cos(pi Z / H), and g(t).
  static constexpr int kSpaceFactors = 2, kTimeFactors = 1;
  template <class S>
  std::array<S, 2> space_factors(const Eigen::Matrix<S, 2, 1>& X) const {
    using std::cos;
    using std::numbers::pi;
    return {q(X.x()), cos(S(pi / height) * X.y())};
  }
  template <class S>
  std::array<S, 1> time_factors(const S& t) const {
    using std::cos;
    using std::numbers::pi;
    return {S(0.5 * amplitude) * (S(1.0) - cos(S(2.0 * pi / period) * t))};
  }
  template <class S>
  MPMVV_JET_INLINE Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const std::array<S, 2>& space,
                                                   const std::array<S, 1>& time) const {
    return {X.x() * (S(1.0) + time[0] * space[0] * space[1]), X.y()};
  }
  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    return position(X, space_factors(X), time_factors(t));
  }
  double length_scale() const { return outer_radius - inner_radius; }
  double time_scale() const { return period; }

  // q(R) and its first two derivatives.
  struct Profile {
    double q, dq, ddq;
  };
  Profile profile(double R) const {
    const double W = outer_radius - inner_radius, v = (outer_radius - R) / W;
    if (inner_radius <= 0.0) return {v * v, -2.0 * v / W, 2.0 / (W * W)};
    const double u = (R - inner_radius) / W;
    return {16.0 * u * u * v * v, 32.0 * u * v * (v - u) / W, 32.0 * ((v - u) * (v - u) - 2.0 * u * v) / (W * W)};
  }
};

// The pulsating cylinder's body force in the neo-Hookean solid, in closed
// form. With c = cos(pi Z / H) and s = 1 + g q c, the motion r = R s, z = Z has
//   F = [[a, b], [0, 1]] in (r, z) x (R, Z),  F_theta = s,  J = a s,
//   a = 1 + g c (q + R q'),  b = R g q c',
// and P = mu (F - F^-T) + lambda ln J F^-T (F^-T = [[1/a, 0], [-b/a, 1]], 1/s):
//   P_rR = mu (a - 1/a) + lambda L / a,  P_rZ = mu b,
//   P_zR = (mu - lambda L) b / a,        P_zZ = lambda L,
//   P_thth = mu (s - 1/s) + lambda L / s,  L = ln J,
// whose divergence in cylindrical coordinates (mms/manufactured.hpp) takes
// the derivatives of a, b, s and L along R and Z. The acceleration is
// R g'' q c along r. tests/test_manufactured.cpp shows it equals the derived
// force to round-off.
class RzCylinderClosedFormField final : public ForceField {
 public:
  RzCylinderClosedFormField(const RzCylinderMotion& motion, const NeoHookean& material, double density)
      : motion_(motion), material_(material), density_(density) {}

  void place(std::size_t count, const std::vector<std::size_t>& index, const std::vector<Vec2>& at) override {
    point_.resize(count);
    using std::numbers::pi;
    const double k = pi / motion_.height;
    for (std::size_t i = 0; i < index.size(); ++i) {
      const double R = at[i].x(), Z = at[i].y();
      const RzCylinderMotion::Profile q = motion_.profile(R);
      point_[index[i]] = {R, q.q, q.dq, q.ddq, std::cos(k * Z), -k * std::sin(k * Z), -k * k * std::cos(k * Z)};
    }
  }

  void evaluate(double t, std::vector<Vec2>& b) const override {
    using std::numbers::pi;
    const double omega = 2.0 * pi / motion_.period;
    const double g = 0.5 * motion_.amplitude * (1.0 - std::cos(omega * t));
    const double g_ddot = 0.5 * motion_.amplitude * omega * omega * std::cos(omega * t);
    const double lambda = material_.lambda, mu = material_.mu, rho = density_;
    const std::size_t n = point_.size();
#pragma omp parallel for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      const Point& x = point_[p];
      const double R = x.R, q = x.q, dq = x.dq, ddq = x.ddq, c = x.c, dc = x.dc, ddc = x.ddc;
      const double s = 1.0 + g * q * c, s_R = g * dq * c, s_Z = g * q * dc;
      const double a = 1.0 + g * c * (q + R * dq), a_R = g * c * (2.0 * dq + R * ddq), a_Z = g * dc * (q + R * dq);
      const double bb = R * g * q * dc, b_R = g * dc * (q + R * dq), b_Z = R * g * q * ddc;
      const double L = std::log(a * s), L_R = a_R / a + s_R / s, L_Z = a_Z / a + s_Z / s;
      const double P_rR = mu * (a - 1.0 / a) + lambda * L / a;
      const double P_thth = mu * (s - 1.0 / s) + lambda * L / s;
      const double P_zR = (mu - lambda * L) * bb / a;
      const double dP_rR = mu * (1.0 + 1.0 / (a * a)) * a_R + lambda * (L_R / a - L * a_R / (a * a));
      const double dP_rZ = mu * b_Z;
      const double dP_zR = -lambda * L_R * bb / a + (mu - lambda * L) * (b_R / a - bb * a_R / (a * a));
      const double dP_zZ = lambda * L_Z;
      const double div_r = dP_rR + dP_rZ + (P_rR - P_thth) / R;
      const double div_z = dP_zR + dP_zZ + P_zR / R;
      b[p] = Vec2(R * g_ddot * q * c - div_r / rho, -div_z / rho);
    }
  }

  std::size_t bytes() const override { return bytes_held(point_); }

 private:
  struct Point {
    double R, q, dq, ddq;  // the radius and the profile q(R) with its derivatives
    double c, dc, ddc;     // cos(pi Z / H) and its derivatives in Z
  };
  RzCylinderMotion motion_;
  NeoHookean material_;
  double density_;
  std::vector<Point> point_;
};

}  // namespace mpmvv::mms
