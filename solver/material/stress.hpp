// The Cauchy stress of a 2D run: the in-plane block and the out-of-plane
// normal component (sigma_zz in plane strain, the hoop stress sigma_theta in
// r-z). A material computes both from the in-plane block of F and the
// out-of-plane stretch F_33 (1 in plane strain, r / R in r-z).
#pragma once

#include <Eigen/Core>

namespace mpmvv {

// A material's Lame constants at small strain: the tangent an implicit step
// preconditions its Newton systems with.
struct SmallStrainModuli {
  double lambda, mu;
};

template <class T>
struct Stress {
  Eigen::Matrix<T, 2, 2> in_plane;
  T out_of_plane;
};

}  // namespace mpmvv
