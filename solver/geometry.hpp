// The two 2D kinematics the solver runs.
#pragma once

namespace mpmvv {

enum class Geometry {
  // Cartesian (x, y), out-of-plane stretch 1; volumes per unit thickness.
  plane_strain,
  // Cylindrical (r, z) about the axis x = 0 (Sulsky and Schreyer 1996, cited in
  // 002_c3305cb8b1bc1490.txt section 1.1). Volumes and masses are per radian
  // (V = integral of r dA); the hoop stretch F_theta = r / R evolves with the
  // hoop rate v_r / r, and the hoop stress enters the radial internal force.
  axisymmetric,
};

inline const char* to_string(Geometry g) { return g == Geometry::axisymmetric ? "axisymmetric" : "plane-strain"; }

}  // namespace mpmvv
