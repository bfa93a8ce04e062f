// CPDI domains held open under shear. A domain x_p + s xi, xi in [-1, 1]^2,
// s = F_p A_p (002_c3305cb8b1bc1490.txt eq. 1.97 with A_p = diag(l_p)), has area
// 4 |det s|, centroid x_p and second moment of area about it
// (4/3) |det s| s s^T. Under shear its sides r_1, r_2 close on each other,
// and the CPDI gradient, s^-T times differences of the grid basis between
// corners (shape/cpdi.hpp), grows as 1 / sin of the angle between them: the
// grid field's interpolation error across the domain's thin width is divided
// by that width (in the sheared bands of the stiff vortex, suites/
// stiff-vortex.toml, J spreads from 0.1 to 4.4 where the exact J is 1) and the
// step falls with the stiffening it causes (stages.hpp: stiffening).
//
// Every parallelogram s W, W a rotation, has the centroid, area and second
// moment of area of s (s W W^T s^T = s s^T, det W = 1), and the angle between
// its sides runs from that of s up to a right angle (the rectangle along the
// principal stretches of s). A domain whose sides meet at less than a set
// angle is turned within that family, s' = s W and A_p <- A_p W, by the
// smallest rotation that opens them to the set angle; under continued shear
// each step turns it a little further and its sides stay at that angle. The
// turn is continuous in time: a jump to the rectangle would move the
// corners by a good part of a domain at once, and the grid fields with them,
// every time a domain skews anew. The reference domain X_p + A_p xi keeps its
// moments (A' A'^T = A A^T): the particle's mass, momentum and first and
// second moments of mass are unchanged, and nothing of its state (x, v, F,
// stress) moves. What it gives up: turned domains of neighbours no longer
// tile the body as their sheared parallelograms did (they overlap and leave
// gaps by the difference of the two shapes, which a quadrature of quadratic
// fields does not see). A manufactured body force averaged over the
// reference domain (mms/force_field.hpp) keeps its Gauss points until the
// particle set changes: both domains are centrally symmetric with the same
// moments up to the second, so the two means differ at fourth order in the
// domain's size. Plane strain, updated formulation (the total formulation's
// domains never deform).
//
// Measured on the stiff vortex (APIC, split beyond a cell, rims at rest,
// domains held at 30 degrees): the smallest step on 30 cells is 1.8e-4 s
// instead of 8.7e-5, and 120 cells complete in 17,199 steps where the
// skewed domains took the step to 1.2e-6 s. The cost is noise: the turned
// domains' overlaps and gaps move mass by a fixed share of a domain whatever
// h is, and the particles' J picks it up. To t = 0.1 s the particle L2
// error is 0.00068 m on 120 cells and 0.00067 on 240 (0.00070 and 0.00017
// without turning), and J's spread in the outer shear band grows from 0.030
// to 0.034 where without turning it falls from 0.011 to 0.009.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include "particles.hpp"

namespace mpmvv {

// Whether a shape's domains are turned by the stepper (its `turned_domains` trait).
template <class Shape>
inline constexpr bool kTurnedDomains = [] {
  if constexpr (requires { Shape::turned_domains; }) return Shape::turned_domains;
  return false;
}();

// Gives every particle its reference domain's half-vectors A_p = diag(l_p),
// the form open_sheared_domains updates.
inline void start_domain_axes(Particles& P) {
  std::vector<Mat2> axes(P.size());
  for (std::size_t p = 0; p < P.size(); ++p) axes[p] = P.reference_domain(p);
  P.domain_axes = std::move(axes);
}

// Turns, in place, every domain whose sides meet at an angle whose cosine is
// larger than `max_cos` in size, by the smallest rotation W that brings that
// cosine down to max_cos (0: the rectangle; max_cos < 1). Returns how many it
// turned.
//
// With P = (r11 + r22) / 2, Q = (r11 - r22) / 2, R = r12 (r_ij = r_i.r_j)
// and psi = atan2(R, Q) - 2t, the columns of s W(t) have
//   r_1'.r_2' = rho sin psi,  |r_1'|^2 |r_2'|^2 = P^2 - rho^2 cos^2 psi,
// rho = sqrt(Q^2 + R^2), P^2 - rho^2 = (det s)^2, so the cosine between them
// is max_cos where sin^2 psi = max_cos^2 (det s)^2 / ((1 - max_cos^2) rho^2);
// psi moves from its start towards the nearer of 0 and +-pi (the rectangle)
// and stops there.
inline std::size_t open_sheared_domains(Particles& P, double max_cos) {
  const std::size_t n = P.size();
  const double pi = std::numbers::pi;
  std::size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
  for (std::size_t p = 0; p < n; ++p) {
    const Mat2 s = P.deformation_gradient[p] * P.domain_axes[p];
    const double r12 = s.col(0).dot(s.col(1)), r11 = s.col(0).squaredNorm(), r22 = s.col(1).squaredNorm();
    if (!(std::abs(r12) > max_cos * std::sqrt(r11 * r22))) continue;  // NaN too: the health scan reports it
    const double Q = 0.5 * (r11 - r22), rho = std::hypot(Q, r12);
    const double psi0 = std::atan2(r12, Q);
    const double target =
        std::asin(std::min(1.0, max_cos * std::abs(determinant(s)) / (std::sqrt(1.0 - max_cos * max_cos) * rho)));
    const double psi = std::abs(psi0) <= 0.5 * pi ? std::copysign(target, psi0) : std::copysign(pi - target, psi0);
    const double t = 0.5 * (psi0 - psi);
    const double c = std::cos(t), sn = std::sin(t);
    Mat2 W;
    W << c, -sn, sn, c;
    P.domain_axes[p] = P.domain_axes[p] * W;
    ++count;
  }
  return count;
}

}  // namespace mpmvv
