// The self-check of a manufactured solution (manufactured.hpp): the balance of
// momentum checked independently of the automatic differentiation, with a
// from a finite difference of the motion in time, F from finite differences
// in X, and Div P from finite differences of P(F) in X, against the derived
// body force; and the verdict over a set of points.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "manufactured.hpp"

namespace mpmvv::mms {

// The finite-difference step of the residual check, in units of the motion's
// length and time scales.
inline constexpr double kCheckStep = 1e-3;

struct ResidualCheck {
  Vec2 residual;   // a - Div P / rho_0 - b
  double scale;    // |a| + |Div P / rho_0| + |b|
  double relative() const { return residual.norm() / std::max(scale, 1e-300); }
};

// The verdict over a set of points, each checked with the steps s = kCheckStep
// (`fine`) and 2 s (`coarse`). The exact residual, zero for a right force, is
// the same at both steps; what differs is the differences' own error:
// truncation (s^6, 64 times larger at 2 s) or round-off (about s^-2, 4 times
// smaller at 2 s). Either way |r_s - r_2s| is at least of the order of r_s's
// own error, so the largest of it over the points estimates how small a
// residual the check can tell from zero. Relative to the largest scale |a| +
// |Div P / rho_0| + |b| over the points: the check passes when the largest
// residual is within kCheckMargin times that estimate (or within a fixed
// tolerance, when one is given), and so fails on a force wrong by more than
// the differences can resolve, never on their own error. Measured (1000
// points, seeds 1-5): the largest residual over the largest difference is
// 0.03-1.33 over every solution `mms list` names and the Mooney-Rivlin ring
// at A = 2 (where both are about 2e-8, above the former fixed tolerance 1e-8).
inline constexpr double kCheckMargin = 3.0;
// Below this fraction of the scale a residual passes whatever the estimate:
// differences that happen to be exact (a linear motion) estimate nothing.
inline constexpr double kCheckFloor = 1e-13;

struct ResidualVerdict {
  double scale = 0.0;       // the largest |a| + |Div P / rho_0| + |b|
  double worst = 0.0;       // the largest |r_s| / scale
  std::size_t worst_at = 0;
  double mean = 0.0;        // the mean |r_s| / scale
  double difference = 0.0;  // the largest |r_s - r_2s| / scale
  double tolerance = 0.0;   // what `worst` is held to
  bool pass = false;
};

// `fixed_tolerance` > 0 replaces the estimate.
inline ResidualVerdict judge_residuals(const std::vector<ResidualCheck>& fine, const std::vector<ResidualCheck>& coarse,
                                       double fixed_tolerance = 0.0) {
  ResidualVerdict v;
  for (const ResidualCheck& c : fine) v.scale = std::max(v.scale, c.scale);
  const double scale = std::max(v.scale, 1e-300);
  for (std::size_t k = 0; k < fine.size(); ++k) {
    const double r = fine[k].residual.norm() / scale;
    if (r > v.worst) v.worst_at = k;
    v.worst = std::max(v.worst, r);
    v.mean += r / double(fine.size());
    if (k < coarse.size()) v.difference = std::max(v.difference, (fine[k].residual - coarse[k].residual).norm() / scale);
  }
  v.tolerance = fixed_tolerance > 0.0 ? fixed_tolerance : std::max(kCheckMargin * v.difference, kCheckFloor);
  v.pass = !fine.empty() && v.worst <= v.tolerance;
  return v;
}

// f' from f at -3h .. 3h.
template <class T>
T sixth_order_derivative(const T* f, double h) {
  return (-f[0] + 9.0 * f[1] - 45.0 * f[2] + 45.0 * f[4] - 9.0 * f[5] + f[6]) / (60.0 * h);
}

// F at X, t by sixth-order central differences of the displacement.
template <class Motion, class Material>
Mat2 finite_difference_F(const Manufactured<Motion, Material>& m, const Vec2& X, double t, double dx) {
  Mat2 F;
  for (int K = 0; K < 2; ++K) {
    Vec2 e = Vec2::Zero();
    e[K] = dx;
    Vec2 x[7];
    for (int k = -3; k <= 3; ++k) x[k + 3] = m.displacement(Vec2(X + double(k) * e), t);
    F.col(K) = sixth_order_derivative(x, dx);
  }
  return Mat2::Identity() + F;
}

// The residual of the balance of momentum at X, t by finite differences only
// (sixth-order central differences with steps `step` = 1e-3 of the motion's
// length and time scales: truncation mostly falls below the round-off of
// the nested differences), against the derived body force.
template <class Motion, class Material>
ResidualCheck check_residual(const Manufactured<Motion, Material>& m, const Vec2& X, double t,
                             double step = kCheckStep) {
  const double dt = step * m.motion().time_scale();
  const double dx = step * m.motion().length_scale();
  auto x = [&](double time) { return m.displacement(X, time); };
  const Vec2 a = (2.0 * x(t - 3 * dt) - 27.0 * x(t - 2 * dt) + 270.0 * x(t - dt) - 490.0 * x(t) + 270.0 * x(t + dt) -
                  27.0 * x(t + 2 * dt) + 2.0 * x(t + 3 * dt)) /
                 (180.0 * dt * dt);
  Vec2 div = Vec2::Zero();
  Mat2 P0 = Mat2::Zero();
  double P0_33 = 0.0;
  for (int J = 0; J < 2; ++J) {
    Vec2 e = Vec2::Zero();
    e[J] = dx;
    Mat2 p[7];
    for (int k = -3; k <= 3; ++k) {
      const Vec2 Xk = X + double(k) * e;
      const Mat2 F = finite_difference_F(m, Xk, t, dx);
      const double F33 = m.hoop_stretch(m.motion().position(Xk, t), Xk);
      const Stress<double> s = m.material().stress(F, F33);
      const double Jdet = determinant(F) * F33;
      p[k + 3] = Jdet * s.in_plane * inverse(F).transpose();
      if (k == 0) {
        P0 = p[3];
        P0_33 = Jdet * s.out_of_plane / F33;
      }
    }
    div += sixth_order_derivative(p, dx).col(J);
  }
  if (m.geometry() == Geometry::axisymmetric) {
    div.x() += (P0(0, 0) - P0_33) / X.x();
    div.y() += P0(1, 0) / X.x();
  }
  div /= m.density();
  const Vec2 b = m.body_force(X, t);
  return {a - div - b, a.norm() + div.norm() + b.norm()};
}

}  // namespace mpmvv::mms
