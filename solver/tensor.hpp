// Small fixed-size tensors of a 2D run. A 2D run stores 2D data: in plane strain
// the out-of-plane stretch is 1 and never stored.
#pragma once

#include <cmath>

#include <Eigen/Core>

namespace mpmvv {

using Vec2 = Eigen::Matrix<double, 2, 1>;
using Mat2 = Eigen::Matrix<double, 2, 2>;

inline double determinant(const Mat2& a) { return a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0); }

// Inverse of a 2x2 matrix by cofactors; the caller guarantees det != 0.
inline Mat2 inverse(const Mat2& a) {
  const double inv_det = 1.0 / determinant(a);
  Mat2 r;
  r << a(1, 1) * inv_det, -a(0, 1) * inv_det, -a(1, 0) * inv_det, a(0, 0) * inv_det;
  return r;
}

// Largest eigenvalue of a symmetric 2x2 matrix.
inline double largest_principal(const Mat2& s) {
  const double mean = 0.5 * (s(0, 0) + s(1, 1));
  const double half_diff = 0.5 * (s(0, 0) - s(1, 1));
  return mean + std::sqrt(half_diff * half_diff + s(0, 1) * s(0, 1));
}

// The doubles of an array of Vec2 or Mat2 (a Mat2 column by column), each
// value's back to back: the lane kernels read the particles' arrays in place
// through these (lane_vectors.hpp: load_interleaved).
template <class T>
const double* values_of(const T* a) {
  static_assert(sizeof(T) == T::SizeAtCompileTime * sizeof(double) && !T::IsRowMajor,
                "the lanes read the values back to back, a matrix column by column");
  return a->data();
}
template <class T>
double* values_of(T* a) {  // and write them so (neo_hookean_lanes.hpp: the stress update)
  return const_cast<double*>(values_of(static_cast<const T*>(a)));
}

}  // namespace mpmvv
