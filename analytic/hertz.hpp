// Hertz contact (PROBLEMS.md section 4; K. L. Johnson, Contact Mechanics, 1985;
// the setup of 004_5b499dc27e377c32.txt section 4.3).
//   Plane strain, a cylinder of radius R on an elastic half-space, load P per
//   unit length: a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a) = sqrt(P E* / (pi R)),
//   p(x) = p0 sqrt(1 - x^2 / a^2); on the axis below the centre
//   sigma_z = -p0 a / sqrt(a^2 + z^2),
//   sigma_x = -p0 [(a^2 + 2 z^2) / (a sqrt(a^2 + z^2)) - 2 z / a],
//   the largest shear (sigma_x - sigma_z)/2 is 0.300 p0 at z = 0.786 a.
//   A sphere (r-z): a = (3 P R / (4 E*))^(1/3), delta = a^2 / R,
//   p0 = 3 P / (2 pi a^2), P = (4/3) E* sqrt(R) delta^(3/2),
//   p(r) = p0 sqrt(1 - r^2 / a^2); on the axis below the centre (Johnson,
//   section 3.4) sigma_z = -p0 / (1 + z^2 / a^2),
//   sigma_r = p0 [-(1 + nu)(1 - (z / a) atan(a / z)) + 1 / (2 (1 + z^2 / a^2))],
//   the largest shear (sigma_r - sigma_z)/2 about 0.31 p0 at z = 0.48 a for nu = 0.3.
// 1 / E* = (1 - nu1^2) / E1 + (1 - nu2^2) / E2; a rigid indenter has E* = E / (1 - nu^2).
#pragma once

#include <cmath>
#include <numbers>

namespace mpmvv::analytic {

inline double contact_modulus(double E1, double nu1, double E2, double nu2) {
  return 1.0 / ((1.0 - nu1 * nu1) / E1 + (1.0 - nu2 * nu2) / E2);
}
inline double contact_modulus_rigid(double E, double nu) { return E / (1.0 - nu * nu); }

struct HertzCylinder {
  double load;            // P per unit length [N/m]
  double radius;          // R [m]
  double contact_modulus; // E* [Pa]

  double half_width() const { return std::sqrt(4.0 * load * radius / (std::numbers::pi * contact_modulus)); }
  double peak_pressure() const { return 2.0 * load / (std::numbers::pi * half_width()); }
  double pressure(double x) const {
    const double a = half_width();
    return std::abs(x) < a ? peak_pressure() * std::sqrt(1.0 - x * x / (a * a)) : 0.0;
  }
  // Stresses on the axis at depth z >= 0 (compression negative).
  double axis_sigma_z(double z) const {
    const double a = half_width();
    return -peak_pressure() * a / std::sqrt(a * a + z * z);
  }
  double axis_sigma_x(double z) const {
    const double a = half_width();
    const double root = std::sqrt(a * a + z * z);
    return -peak_pressure() * ((a * a + 2.0 * z * z) / (a * root) - 2.0 * z / a);
  }
  double axis_shear(double z) const { return 0.5 * std::abs(axis_sigma_x(z) - axis_sigma_z(z)); }
};

struct HertzSphere {
  double load;            // P [N]
  double radius;          // R [m]
  double contact_modulus; // E* [Pa]

  double contact_radius() const { return std::cbrt(3.0 * load * radius / (4.0 * contact_modulus)); }
  double approach() const {
    const double a = contact_radius();
    return a * a / radius;
  }
  double peak_pressure() const {
    const double a = contact_radius();
    return 3.0 * load / (2.0 * std::numbers::pi * a * a);
  }
  double pressure(double r) const {
    const double a = contact_radius();
    return std::abs(r) < a ? peak_pressure() * std::sqrt(1.0 - r * r / (a * a)) : 0.0;
  }
  // Stresses on the axis at depth z >= 0 (compression negative); the radial
  // (and hoop) one depends on the half-space's Poisson ratio.
  double axis_sigma_z(double z) const {
    const double a = contact_radius();
    return -peak_pressure() / (1.0 + z * z / (a * a));
  }
  double axis_sigma_r(double z, double poisson_ratio) const {
    const double a = contact_radius();
    const double arc = z > 0.0 ? (z / a) * std::atan(a / z) : 0.0;
    return peak_pressure() * (-(1.0 + poisson_ratio) * (1.0 - arc) + 0.5 / (1.0 + z * z / (a * a)));
  }
  // The load that gives approach delta.
  static double load_at_approach(double delta, double radius, double contact_modulus) {
    return 4.0 / 3.0 * contact_modulus * std::sqrt(radius) * std::pow(delta, 1.5);
  }
};

}  // namespace mpmvv::analytic
