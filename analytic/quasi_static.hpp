// Static exact solutions reached by a slow load: the load follows the ramp
//   r(t) = (1 - cos(pi t / T)) / 2 for t < T, and 1 after,
// whose rate vanishes at both ends, and the body settles (with damping) to the
// static state of the full load. A homogeneous static state x = X + D X (the
// uniaxial bar, simple shear) is written as the motion x = X + r(t) D X: at
// t = 0 it is the reference state at rest and from t = T on it is the exact
// static solution; in between it is the quasi-static path, which a dynamic
// run follows only approximately (inertia), so errors are read at the end.
#pragma once

#include <cmath>
#include <numbers>
#include <type_traits>

#include <Eigen/Core>

namespace mpmvv::analytic {

// The value of a scalar or of a (nested) automatic-differentiation jet.
template <class S>
double value_of(const S& s) {
  if constexpr (std::is_arithmetic_v<S>) return double(s);
  else return value_of(s.v);
}

// Analytic on t < T (the cosine is kept for t < 0 too, so that finite
// differences about t = 0 see no kink); constant from T on.
template <class S>
S ramp(const S& t, double ramp_time) {
  using std::cos;
  if (value_of(t) >= ramp_time) return S(1.0);
  return S(0.5) - S(0.5) * cos(S(std::numbers::pi / ramp_time) * t);
}

struct RampedHomogeneousMotion {
  Eigen::Matrix2d displacement_gradient;  // D of the static state x = X + D X
  double ramp_time;                       // T [s]
  double length;                          // the body's size, for the checks' differences [m]

  template <class S>
  Eigen::Matrix<S, 2, 1> displacement(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    const S r = ramp(t, ramp_time);
    Eigen::Matrix<S, 2, 1> u;
    for (int i = 0; i < 2; ++i)
      u[i] = r * (S(displacement_gradient(i, 0)) * X[0] + S(displacement_gradient(i, 1)) * X[1]);
    return u;
  }
  template <class S>
  Eigen::Matrix<S, 2, 1> position(const Eigen::Matrix<S, 2, 1>& X, const S& t) const {
    return X + displacement(X, t);
  }
  // The checks difference over 1e-3 of this. The motion is linear in X, so
  // differences of any step are exact, and a long step keeps the round-off of
  // a material that forms F - I near F = I (lambda x 1e-16 per stress entry
  // for steel) from being divided by a short one: the step is the body's size.
  double length_scale() const { return 1e3 * length; }
  double time_scale() const { return ramp_time; }
};

}  // namespace mpmvv::analytic
