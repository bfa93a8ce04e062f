// F-tables: homogeneous deformations prescribed by their deformation
// gradient along a path s in [0, 1], the standard way to drive a material
// model (003_0440bbfcfbc3a876.txt, its abstract: uniaxial strain, simple and
// pure shear, biaxial stretch, each with and without a superimposed
// rotation). In the solver's 2D setting F = diag(F_inplane, F_33): F_33 = 1
// is plane strain, F_33 != 1 the hoop stretch of an r-z body.
//
// A superimposed rotation turns the deformed body rigidly by theta(s) =
// s theta_end: F_rotated = R(theta) F. An objective material answers with
// the rotated stress R sigma R^T and the same energy.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "principal_stress.hpp"

namespace mpmvv::analytic {

struct FTable {
  std::string name;
  std::string description;
  Deformation (*at)(double s);  // F along the path, s in [0, 1]
};

inline Eigen::Matrix2d rotation(double angle) {
  Eigen::Matrix2d R;
  R << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  return R;
}

// The standard tables. Their end states are large (stretches 0.6 to 1.5, a
// shear of 1) so that a material's nonlinearity shows.
inline const std::vector<FTable>& standard_f_tables() {
  static const std::vector<FTable> tables = {
      {"uniaxial-strain", "F = diag(1 + 0.5 s, 1, 1): stretch to 1.5 along x, no lateral strain",
       [](double s) { return Deformation{Eigen::Vector2d(1.0 + 0.5 * s, 1.0).asDiagonal(), 1.0}; }},
      {"uniaxial-compression", "F = diag(1 - 0.4 s, 1, 1): compression to 0.6 along x, no lateral strain",
       [](double s) { return Deformation{Eigen::Vector2d(1.0 - 0.4 * s, 1.0).asDiagonal(), 1.0}; }},
      {"simple-shear", "F = [1, s; 0, 1]: shear gamma to 1 (isochoric, principal axes turning)",
       [](double s) {
         Deformation d;
         d.F(0, 1) = s;
         return d;
       }},
      {"pure-shear", "F = diag(1.5^s, 1.5^-s, 1): isochoric stretch to 1.5 and 1/1.5, fixed axes",
       [](double s) {
         const double l = std::pow(1.5, s);
         return Deformation{Eigen::Vector2d(l, 1.0 / l).asDiagonal(), 1.0};
       }},
      {"biaxial-stretch", "F = diag(1 + 0.25 s, 1 + 0.25 s, 1): equal in-plane stretch to 1.25",
       [](double s) { return Deformation{Eigen::Vector2d(1.0 + 0.25 * s, 1.0 + 0.25 * s).asDiagonal(), 1.0}; }},
      {"hoop-stretch", "F = diag(1 - 0.1 s, 1, 1 + 0.4 s): an r-z ring widening to 1.4 R, thinning radially",
       [](double s) { return Deformation{Eigen::Vector2d(1.0 - 0.1 * s, 1.0).asDiagonal(), 1.0 + 0.4 * s}; }},
  };
  return tables;
}

}  // namespace mpmvv::analytic
