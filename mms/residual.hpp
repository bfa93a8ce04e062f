// The residual check of a manufactured solution: at a reference point X,
//   r = a - Div P / rho_0 - b
// must vanish, with Div P taken by an independent fourth-order central
// difference of the exact first Piola-Kirchhoff stress in the reference
// coordinates. It can only pass if the force, the motion and the material agree.
#pragma once

#include <algorithm>

#include "solver/tensor.hpp"

namespace mpmvv::mms {

struct Residual {
  Vec2 residual;
  double scale;  // |a| + |Div P / rho_0| + |b|, for a relative measure
  double relative() const { return residual.norm() / std::max(scale, 1e-300); }
};

// `Solution` provides state(X, t).first_piola, state(X, t).acceleration,
// body_force(X, t) and parameters().density.
template <class Solution>
Vec2 divergence_of_first_piola(const Solution& s, const Vec2& X, double t, double step) {
  Vec2 div = Vec2::Zero();
  for (int J = 0; J < 2; ++J) {
    Vec2 e = Vec2::Zero();
    e[J] = step;
    const Mat2 p2 = s.state(X + 2.0 * e, t).first_piola, p1 = s.state(X + e, t).first_piola;
    const Mat2 m1 = s.state(X - e, t).first_piola, m2 = s.state(X - 2.0 * e, t).first_piola;
    const Mat2 dP = (-p2 + 8.0 * p1 - 8.0 * m1 + m2) / (12.0 * step);  // d P_iJ / d X_J, column J
    div += dP.col(J);
  }
  return div;
}

template <class Solution>
Residual body_force_residual(const Solution& s, const Vec2& X, double t, double step = 1e-3) {
  const Vec2 a = s.state(X, t).acceleration;
  const Vec2 div_p = divergence_of_first_piola(s, X, t, step) / s.parameters().density;
  const Vec2 b = s.body_force(X, t);
  return {a - div_p - b, a.norm() + div_p.norm() + b.norm()};
}

}  // namespace mpmvv::mms
