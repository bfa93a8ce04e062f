// The uniaxial bar (PROBLEMS.md section 5; 004_5b499dc27e377c32.txt sections
// 4.1-4.2), each form stated with its assumptions.
//
// Small strain, axial strain eps = dL / L:
//   3D and plane stress (sigma_yy = sigma_zz = 0, resp. sigma_zz = 0):
//     sigma = E eps, lateral strain -nu eps;
//   plane strain (eps_zz = 0, sigma_yy = 0):
//     sigma = E / (1 - nu^2) eps, lateral strain -nu / (1 - nu) eps;
//   the seed's lateral change (3D, logarithmic in the stretch):
//     delta_d = -d (1 - (1 + dL / L)^(-nu)).
// Shear (small strain): tau = G gamma, G = E / (2 (1 + nu)).
// Finite strain, neo-Hookean (000_1dbcb8acb6dddab9.txt eq. 2.2), axial stretch
// l1: the lateral stretch l2 solves sigma_yy(l1, l2) = 0 (plane strain: F_zz = 1;
// uniaxial stress in 3D: l3 = l2 by symmetry), a scalar root found with KINSOL.
#pragma once

#include <cmath>

namespace mpmvv::analytic {

struct SmallStrainBar {
  double youngs_modulus;  // E [Pa]
  double poisson_ratio;   // nu

  double stress_3d(double axial_strain) const { return youngs_modulus * axial_strain; }
  double lateral_strain_3d(double axial_strain) const { return -poisson_ratio * axial_strain; }
  double stress_plane_stress(double axial_strain) const { return stress_3d(axial_strain); }
  double lateral_strain_plane_stress(double axial_strain) const { return lateral_strain_3d(axial_strain); }
  double stress_plane_strain(double axial_strain) const {
    return youngs_modulus / (1.0 - poisson_ratio * poisson_ratio) * axial_strain;
  }
  double lateral_strain_plane_strain(double axial_strain) const {
    return -poisson_ratio / (1.0 - poisson_ratio) * axial_strain;
  }
  // The seed's formula for the change of a lateral dimension d.
  double seed_lateral_change(double d, double axial_strain) const {
    return -d * (1.0 - std::pow(1.0 + axial_strain, -poisson_ratio));
  }
  double shear_modulus() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }
  double shear_stress(double shear_strain) const { return shear_modulus() * shear_strain; }
};

// A neo-Hookean bar in uniaxial stress at axial stretch l1.
struct NeoHookeanBar {
  double lambda;  // [Pa]
  double mu;      // [Pa]

  struct State {
    double lateral_stretch;  // l2
    double axial_stress;     // Cauchy sigma_xx [Pa]
    double J;
    long iterations;         // of KINSOL
  };
  // Plane strain: F = diag(l1, l2, 1), sigma_yy = 0.
  State plane_strain(double axial_stretch) const;
  // Uniaxial stress in 3D: F = diag(l1, l2, l2), sigma_yy = sigma_zz = 0.
  State uniaxial_stress(double axial_stretch) const;
};

}  // namespace mpmvv::analytic
