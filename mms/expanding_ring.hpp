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

  // Separable (manufactured.hpp): f(|X|), and the sine of t.
  static constexpr int kSpaceFactors = 1, kTimeFactors = 1;
  template <class S>
  std::array<S, 1> space_factors(const Eigen::Matrix<S, 2, 1>& X) const {
    using std::sqrt;
    return {profile(S(sqrt(X.x() * X.x() + X.y() * X.y())))};
  }
  template <class S>
  std::array<S, 1> time_factors(const S& t) const {
    using std::numbers::pi;
    using std::sin;
    return {sin(S(wave_speed * pi / (2.0 * mean_radius())) * t)};
  }
  template <class S>
  MPMVV_JET_INLINE Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const std::array<S, 1>& space,
                                                   const std::array<S, 1>& time) const {
    const S stretch = S(1.0) + S(amplitude) * time[0] * space[0];
    return {stretch * X.x(), stretch * X.y()};
  }
  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    return position(X, space_factors(X), time_factors(t));
  }
  double length_scale() const { return outer_radius - inner_radius; }
  double time_scale() const { return 2.0 * mean_radius() / wave_speed; }

  // f(R) and its first two derivatives.
  struct Profile {
    double f, df, ddf;
  };
  Profile profile_derivatives(double R) const {
    if (bubble) {
      const double w = outer_radius - inner_radius, k = 16.0 / (w * w * w * w);
      const double b = (R - inner_radius) * (outer_radius - R), db = outer_radius + inner_radius - 2.0 * R;
      return {k * b * b, 2.0 * k * b * db, 2.0 * k * (db * db - 2.0 * b)};
    }
    return {c1() + c2() * R + c3() * R * R, c2() + 2.0 * c3() * R, 2.0 * c3()};
  }
};

// The expanding ring's body force in the neo-Hookean solid, in closed form.
// With g = A sin(omega t), omega = C pi / (2 r_b), the motion x = s X,
// s = 1 + g f(R), stretches radially by a = s + R s' = 1 + g (f + R f') and
// around by s; J = a s (plane strain), and P = mu (F - F^-T) + lambda ln J F^-T
// is diagonal in the polar basis:
//   P_RR = mu (a - 1/a) + lambda L / a,  P_ThTh = mu (s - 1/s) + lambda L / s,  L = ln J,
//   (Div P)_R = dP_RR / dR + (P_RR - P_ThTh) / R,
//   dP_RR / dR = mu (1 + 1/a^2) a' + lambda (L' / a - L a' / a^2),
//   a' = g (2 f' + R f''),  L' = a' / a + g f' / s.
// The force is radial: b = (R g'' f - (Div P)_R / rho_0) X / R, g'' = -omega^2 g.
// tests/test_manufactured.cpp shows it equals the derived force to round-off.
class ExpandingRingClosedFormField final : public ForceField {
 public:
  ExpandingRingClosedFormField(const ExpandingRingMotion& motion, const NeoHookean& material, double density)
      : motion_(motion), material_(material), density_(density) {}

  void place(std::size_t count, const std::vector<std::size_t>& index, const std::vector<Vec2>& at) override {
    point_.resize(count);
    for (std::size_t i = 0; i < index.size(); ++i) {
      const double R = at[i].norm();
      const ExpandingRingMotion::Profile f = motion_.profile_derivatives(R);
      point_[index[i]] = {R, f.f, f.df, f.ddf, at[i] / R};
    }
  }

  void evaluate(double t, std::vector<Vec2>& b) const override {
    using std::numbers::pi;
    const double omega = motion_.wave_speed * pi / (2.0 * motion_.mean_radius());
    const double g = motion_.amplitude * std::sin(omega * t), g_ddot = -omega * omega * g;
    const double lambda = material_.lambda, mu = material_.mu, rho = density_;
    const std::size_t n = point_.size();
#pragma omp parallel for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      const Point& x = point_[p];
      const double R = x.R;
      const double s = 1.0 + g * x.f, s_R = g * x.df;
      const double a = 1.0 + g * (x.f + R * x.df), a_R = g * (2.0 * x.df + R * x.ddf);
      const double L = std::log(a * s), L_R = a_R / a + s_R / s;
      const double P_RR = mu * (a - 1.0 / a) + lambda * L / a;
      const double P_thth = mu * (s - 1.0 / s) + lambda * L / s;
      const double dP_RR = mu * (1.0 + 1.0 / (a * a)) * a_R + lambda * (L_R / a - L * a_R / (a * a));
      const double div_R = dP_RR + (P_RR - P_thth) / R;
      b[p] = (R * g_ddot * x.f - div_R / rho) * x.direction;
    }
  }

  std::size_t bytes() const override { return bytes_held(point_); }

 private:
  struct Point {
    double R, f, df, ddf;  // the reference radius and the profile f(R) with its derivatives
    Vec2 direction;        // X / R
  };
  ExpandingRingMotion motion_;
  NeoHookean material_;
  double density_;
  std::vector<Point> point_;
};

}  // namespace mpmvv::mms
