// The exact stress and stored energy of the hyperelastic materials under any
// homogeneous deformation, written in principal stretches: a second road to
// the numbers the solver's materials (solver/material/) compute from B, for
// the material-point driver (`mpmvv material drive`, F-tables).
//
// For an isotropic W(l1, l2, l3) the Cauchy stress is coaxial with
// B = F F^T and its principal values are
//   sigma_i = (l_i / J) dW/dl_i,  J = l1 l2 l3
// (sigma = (2/J) B dW/dB of an isotropic energy, read on B's eigenvectors), so the in-plane block
// comes from the eigenvectors of the in-plane B and the out-of-plane
// component from l3 = F_33. The derivatives l_i dW/dl_i are written out by
// hand for each energy below, not taken from the solver's code:
//
// Neo-Hookean (000_1dbcb8acb6dddab9.txt eq. 2.2):
//   W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,
//   l_i dW/dl_i = mu (l_i^2 - 1) + lambda ln J.
// Mooney-Rivlin (eq. 2.18 with K ln J, solver/material/mooney_rivlin.hpp):
//   W = C1 (J^-2/3 I1 - 3) + C2 (J^-4/3 I2 - 3) + K/2 (ln J)^2,
//   I1 = sum l_i^2, I2 = sum_{i<j} l_i^2 l_j^2, l_i dJ/dl_i = J,
//   l_i dI1/dl_i = 2 l_i^2, l_i dI2/dl_i = 2 l_i^2 (I1 - l_i^2), so
//   l_i dW/dl_i = C1 J^-2/3 (2 l_i^2 - 2/3 I1)
//               + C2 J^-4/3 (2 l_i^2 (I1 - l_i^2) - 4/3 I2) + K ln J.
// The small-strain linear solid is not a function of the principal
// stretches (it is not objective) and has no second road: its stress is its
// definition, so the driver checks it only against its energy.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace mpmvv::analytic {

// A homogeneous state in the 2D setting of the solver: the in-plane block of
// F and the out-of-plane stretch F_33.
struct Deformation {
  Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
  double F33 = 1.0;
};

struct ExactStress {
  Eigen::Matrix2d in_plane;
  double out_of_plane;
};

struct NeoHookeanStretches {
  double lambda, mu;
  double energy(const Eigen::Vector3d& l) const {
    const double lnJ = std::log(l.prod());
    return 0.5 * mu * (l.squaredNorm() - 3.0) - mu * lnJ + 0.5 * lambda * lnJ * lnJ;
  }
  // l_i dW/dl_i, the principal Kirchhoff stresses.
  Eigen::Vector3d kirchhoff(const Eigen::Vector3d& l) const {
    const double lnJ = std::log(l.prod());
    return (mu * (l.array().square() - 1.0) + lambda * lnJ).matrix();
  }
};

struct MooneyRivlinStretches {
  double c1, c2, bulk_modulus;
  double energy(const Eigen::Vector3d& l) const {
    const double J = l.prod();
    const Eigen::Vector3d s = l.array().square();
    const double I1 = s.sum(), I2 = s(0) * s(1) + s(1) * s(2) + s(2) * s(0);
    const double lnJ = std::log(J);
    return c1 * (std::pow(J, -2.0 / 3.0) * I1 - 3.0) + c2 * (std::pow(J, -4.0 / 3.0) * I2 - 3.0) +
           0.5 * bulk_modulus * lnJ * lnJ;
  }
  Eigen::Vector3d kirchhoff(const Eigen::Vector3d& l) const {
    const double J = l.prod();
    const Eigen::Vector3d s = l.array().square();
    const double I1 = s.sum(), I2 = s(0) * s(1) + s(1) * s(2) + s(2) * s(0);
    Eigen::Vector3d tau;
    for (int i = 0; i < 3; ++i)
      tau(i) = c1 * std::pow(J, -2.0 / 3.0) * (2.0 * s(i) - 2.0 / 3.0 * I1) +
               c2 * std::pow(J, -4.0 / 3.0) * (2.0 * s(i) * (I1 - s(i)) - 4.0 / 3.0 * I2) +
               bulk_modulus * std::log(J);
    return tau;
  }
};

// The principal stretches of a deformation and the in-plane principal
// directions (columns), from the eigen decomposition of the in-plane B.
struct PrincipalStretches {
  Eigen::Vector3d stretch;
  Eigen::Matrix2d directions;
};

inline PrincipalStretches principal_stretches(const Deformation& d) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(d.F * d.F.transpose());
  const Eigen::Vector2d b = eigen.eigenvalues();
  return {Eigen::Vector3d(std::sqrt(b(0)), std::sqrt(b(1)), d.F33), eigen.eigenvectors()};
}

// sigma = sum_i (tau_i / J) n_i n_i^T of an isotropic energy given in
// principal stretches.
template <class Stretches>
ExactStress principal_stress(const Stretches& material, const Deformation& d) {
  const PrincipalStretches p = principal_stretches(d);
  const Eigen::Vector3d sigma = material.kirchhoff(p.stretch) / p.stretch.prod();
  const Eigen::Matrix2d& n = p.directions;
  return {n * sigma.head<2>().asDiagonal() * n.transpose(), sigma(2)};
}

template <class Stretches>
double principal_energy(const Stretches& material, const Deformation& d) {
  return material.energy(principal_stretches(d).stretch);
}

}  // namespace mpmvv::analytic
