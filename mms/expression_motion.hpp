// A manufactured motion written as formulas (expression.hpp) of the reference
// coordinates and time, X, Y, t in plane strain and R, Z, t in r-z: the
// displacement u = x - X, so that a small motion keeps its digits in the
// checks (manufactured.hpp). Everything else a manufactured solution holds
// (F, v, a, the stress of any of the materials and the body force) is derived
// from it by automatic differentiation, as for the motions written in C++.
#pragma once

#include <Eigen/Core>

#include "expression.hpp"

namespace mpmvv::mms {

struct ExpressionMotion {
  Expression displacement_x, displacement_y;  // in r-z: u_r and u_z
  double length = 1.0;  // the length and time over which the motion varies
  double time = 1.0;    // (the steps of the finite-difference checks)

  template <class S>
  Eigen::Matrix<S, 2, 1> displacement(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    return {displacement_x(X.x(), X.y(), t), displacement_y(X.x(), X.y(), t)};
  }
  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    return X + displacement(X, t);
  }
  double length_scale() const { return length; }
  double time_scale() const { return time; }
};

}  // namespace mpmvv::mms
