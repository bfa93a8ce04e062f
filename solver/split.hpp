// Splitting of stretched CPDI domains. Under large shear a domain vector
// r_i = F_p (l_i e_i) (002_c3305cb8b1bc1490.txt eq. 1.97), or F_p a_i for a
// turned domain whose reference half-vectors are the columns a_i of A_p
// (domain_angle.hpp), grows to span many cells, and the bilinear interpolation of
// the grid basis from the domain's four corners (eq. 1.95) stops describing
// the particle: it skips the kinks of every cell line in between. A particle
// whose domain is longer than a set length along r_i is replaced by its two
// halves along it:
//   x = x_p -+ r_i / 2,   X = X_p -+ a_i / 2,   a_i <- a_i / 2,
//   m, V, V_0 halved;  v, F, stress unchanged
// (a_i = l_i e_i for a domain never turned, where l_i is halved; under APIC each
// half takes the parent's affine velocity field at its own centre,
// v = v_p -+ C_p r_i / 2, and keeps C_p).
// The map of the domain, x = x_p + F_p (X - X_p), is affine, so the halves
// tile their parent exactly in both configurations and together carry its
// mass, momentum, kinetic and strain energy, and first moment of mass.
// Plane strain only (in r-z the halves would not share the volume equally).
//
// Corner domains (domain_corners.hpp) are measured and cut by their corners:
// r_i is the quadrilateral's half-vector [a_1 a_2] along i, and the halves
// are the two quadrilaterals between the cut edges' midpoints, each keeping
// the corners on its side; r_i and its reference a_i still place the halves'
// centres as above.
#pragma once

#include <cstddef>
#include <vector>

#include "domain_corners.hpp"
#include "particles.hpp"

namespace mpmvv {

// Corners 0-3 of particle p at (xi, eta) = (-1, -1), (1, -1), (1, 1), (-1, 1),
// cut across `axis` (0: xi) at the midpoints of the two edges along it: p
// keeps the minus half, and the plus half's corners are appended.
inline void split_corners(std::vector<Vec2>& corners, std::size_t p, int axis) {
  Vec2 x[4];
  for (int c = 0; c < 4; ++c) x[c] = corners[4 * p + c];
  Vec2 minus[4], plus[4];
  if (axis == 0) {
    const Vec2 m01 = 0.5 * (x[0] + x[1]), m32 = 0.5 * (x[3] + x[2]);
    minus[0] = x[0], minus[1] = m01, minus[2] = m32, minus[3] = x[3];
    plus[0] = m01, plus[1] = x[1], plus[2] = x[2], plus[3] = m32;
  } else {
    const Vec2 m03 = 0.5 * (x[0] + x[3]), m12 = 0.5 * (x[1] + x[2]);
    minus[0] = x[0], minus[1] = x[1], minus[2] = m12, minus[3] = m03;
    plus[0] = m03, plus[1] = m12, plus[2] = x[2], plus[3] = x[3];
  }
  for (int c = 0; c < 4; ++c) corners[4 * p + c] = minus[c];
  for (int c = 0; c < 4; ++c) corners.push_back(plus[c]);
}

// Splits, in place, every particle whose domain length 2 |r_i| along either
// vector exceeds `max_length`, as often as it takes (each half is checked
// again). Returns the number of splits; `changed`, when given, receives each
// particle present before that was split (it keeps one half), in order.
inline std::size_t split_long_domains(Particles& P, double max_length, std::vector<std::size_t>* changed = nullptr) {
  const bool turned = !P.domain_axes.empty();
  const bool corners = !P.domain_corner.empty();
  // Particle p's reference and current half-vectors, and the axis along
  // which it is too long (-1 when it is not).
  struct Cut {
    Mat2 a, s;
    int axis;
  };
  auto cut_of = [&](std::size_t p) {
    Cut c;
    c.a = P.reference_domain(p);
    c.s = corners ? corner_half_vectors(&P.domain_corner[4 * p]) : Mat2(P.deformation_gradient[p] * c.a);
    const double long1 = 2.0 * c.s.col(0).norm(), long2 = 2.0 * c.s.col(1).norm();
    c.axis = !(long1 > max_length || long2 > max_length) ? -1  // NaN stays: the health scan reports it
             : long1 >= long2                             ? 0
                                                          : 1;
    return c;
  };
  // The particles present are measured in parallel; the few that split are
  // then cut one after another, in the order of a single pass.
  const std::size_t present = P.size();
  std::vector<unsigned char> too_long(present);
#pragma omp parallel for schedule(static)
  for (std::size_t p = 0; p < present; ++p) too_long[p] = cut_of(p).axis >= 0;
  std::size_t splits = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (p < present && !too_long[p]) continue;
    if (changed && p < present) changed->push_back(p);
    for (;;) {
      const Cut cut = cut_of(p);
      const int axis = cut.axis;
      if (axis < 0) break;
      const Mat2& a = cut.a;
      const Vec2 r = cut.s.col(axis);
      const Vec2 reference_step = 0.5 * a.col(axis);
      const std::size_t q = P.size();
      P.resize(q + 1);
      P.half_size.push_back(P.half_size[p]);
      if (!P.body_force.empty()) P.body_force.push_back(P.body_force[p]);
      if (!P.affine_velocity.empty()) P.affine_velocity.push_back(P.affine_velocity[p]);
      // The halves: p keeps the minus side, q takes the plus side.
      if (turned) {
        P.domain_axes[p].col(axis) *= 0.5;
        P.domain_axes.push_back(P.domain_axes[p]);
      } else {
        P.half_size[p][axis] = P.half_size[q][axis] = 0.5 * P.half_size[p][axis];
      }
      if (corners) split_corners(P.domain_corner, p, axis);
      P.position[q] = P.position[p] + 0.5 * r;
      P.position[p] -= 0.5 * r;
      P.reference_position[q] = P.reference_position[p] + reference_step;
      P.reference_position[p] -= reference_step;
      P.velocity[q] = P.velocity[p];
      if (!P.affine_velocity.empty()) {
        const Vec2 change = 0.5 * (P.affine_velocity[p] * r);
        P.velocity[q] += change;
        P.velocity[p] -= change;
      }
      P.deformation_gradient[q] = P.deformation_gradient[p];
      P.stress[q] = P.stress[p];
      for (std::vector<double>* v : {&P.mass, &P.volume, &P.reference_volume}) {
        (*v)[p] *= 0.5;
        (*v)[q] = (*v)[p];
      }
      ++splits;
    }
  }
  return splits;
}

}  // namespace mpmvv
