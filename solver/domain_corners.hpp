// CPDI domains carried by their corners (cpdi_domain = "corners"): the
// quadrilateral domains of the second-order CPDI of Sadeghirad, Brannon and
// Guilkey (2013), whose corners are material points moved with the grid
// velocity, instead of the parallelograms F_p diag(l_p) of
// 002_c3305cb8b1bc1490.txt eq. 1.97.
//
// Why: a parallelogram follows its own particle's F_p, and neighbours whose F
// differ stop meeting edge to edge; under large shear the gaps and overlaps
// are a fixed share of a domain, and the hats alias them into the node masses
// whatever h is (suites/stiff-vortex.toml). A corner is moved by the grid
// velocity read with the hats at the corner, x_c += dt sum_g S_g(x_c) v_g^L,
// a function of the corner's position alone: two particles that share a
// corner at the start compute the same motion for it, bit for bit, and keep
// sharing it, so the domains tile the body for the whole run without a list
// of shared corners. Each particle keeps its own four (Particles::domain_corner).
//
// A split (split.hpp) cuts a quadrilateral at the midpoints of two opposite
// edges. The neighbour across such an edge has no corner there: the new
// corner starts on the neighbour's edge and leaves it only by the velocity's
// curvature over the edge, a gap of second order in the domain's size.
#pragma once

#include <cstddef>
#include <vector>

#include "grid.hpp"
#include "particles.hpp"
#include "shape/linear.hpp"
#include "shape/lane_shared.hpp"  // kCornerXi, kCornerEta
#include "tensor.hpp"

namespace mpmvv {

// Whether a shape's domains are corners the stepper moves (its `corner_domains` trait).
template <class Shape>
inline constexpr bool kCornerDomains = [] {
  if constexpr (requires { Shape::corner_domains; }) return Shape::corner_domains;
  return false;
}();

// The bilinear map of a quadrilateral, x = a_0 + a_1 xi + a_2 eta + a_3 xi eta:
// its linear part at the centre as the columns [a_1 a_2], the half-vectors a
// parallelogram domain would have (the two coincide for a parallelogram).
inline Mat2 corner_half_vectors(const Vec2* x) {
  Mat2 s;
  s.col(0) = 0.25 * (x[1] + x[2] - x[0] - x[3]);
  s.col(1) = 0.25 * (x[2] + x[3] - x[0] - x[1]);
  return s;
}

// A quadrilateral turned over: the signed area of its linear part, 4 det
// [a_1 a_2], is not positive (NaN corners count as turned). Its corners no
// longer bound the material (cpdi.hpp, cpdi_exact.hpp: folded).
inline bool turned_over(const Mat2& half_vectors) { return !(determinant(half_vectors) > 0.0); }

// The corners of each particle's parallelogram x_p + F_p A_p (xi, eta), the
// domain it starts from. Neighbouring seeded domains meet edge to edge, so
// their corners coincide (to the round-off of x_p +- l_p).
inline void start_domain_corners(Particles& P) {
  P.domain_corner.resize(4 * P.size());
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Mat2 s = P.deformation_gradient[p] * P.reference_domain(p);
    for (int c = 0; c < 4; ++c)
      P.domain_corner[4 * p + c] = P.position[p] + kCornerXi[c] * s.col(0) + kCornerEta[c] * s.col(1);
  }
}

// to_k = from_k + dt sum_g S_g(from_k) v_g, with the bilinear hats of the
// corner's cell (eq. 1.76 for a point). `to` may be `from` itself. A corner
// outside the grid stays where it is: the health scan (CpdiShapeT::inside)
// stops its particle.
inline void move_corners(const GridGeometry& grid, const GridFields& g, const std::vector<Vec2>& from,
                         std::vector<Vec2>& to, double dt) {
  const std::size_t n = from.size();
  to.resize(n);
#pragma omp parallel for schedule(static)
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2 x = from[k];
    if (!inside_cells(grid, grid_coordinate(grid, x))) {
      to[k] = x;
      continue;
    }
    int node[4];
    double w[4];
    bilinear_cell_weights(grid, x, node, w);
    Vec2 v = Vec2::Zero();
    for (int j = 0; j < 4; ++j) v += w[j] * g.velocity[node[j]];
    to[k] = x + dt * v;
  }
}

}  // namespace mpmvv
