// B-spline MPM (method = "bspline", quadratic; "bspline-cubic"): the particle
// is a point, as in standard MPM (002_c3305cb8b1bc1490.txt eq. 1.88), but the
// grid basis is the tensor product of uniform B-splines of degree p centred
// on the nodes instead of the bilinear hats of eqs. 1.86-1.87 (the hat is the
// B-spline of degree 1). With r the distance from a node in cells:
//   p = 2:  N = 3/4 - r^2                         |r| < 1/2
//             = (3/2 - |r|)^2 / 2                 1/2 <= |r| < 3/2
//   p = 3:  N = 2/3 - r^2 + |r|^3 / 2             |r| < 1
//             = (2 - |r|)^3 / 6                   1 <= |r| < 2
// and dN/dx = N'(r) / h. Each sums to one over the nodes and reproduces x, so
// a linear field and a uniform motion are carried exactly, as by the hats.
// Unlike the hats, the basis is C^(p-1) across cell lines: a particle that
// crosses one sees no jump in its gradients, which is the noise of the cell
// crossing in standard MPM and uGIMP, and the basis approximates a smooth
// field one (p = 2) or two (p = 3) orders better. Its gradients sum over the
// nodes along an axis to at most 2 / h (p = 2) and 3 / (2 h) (p = 3), within
// the bilinear hats' own bound, so the step rule of the hats holds
// (stages.hpp: kGridBasisGradientBound).
//
// A point reaches the p + 1 nodes per axis whose splines cover it. One within
// (p - 1) / 2 cells of a wall (half a cell for p = 2, one for p = 3) would
// weigh the ghost node beyond it, and the walls (stages.hpp: apply_walls)
// overwrite a ghost node with the mirror of the node inside instead of adding
// its mass and force there: the particle's share on the ghost would be lost,
// an error of first order at the wall (measured: the axis-aligned problem,
// which fills its walls, converged at order 1.1-1.5 on 8-64 cells against
// CPDI's 2.0 with quadratic splines). So a particle must stay that far clear
// of every wall; then the images of the particles beyond a wall reach no node
// inside, and the mirror is the exact symmetry condition. Plane strain only:
// in r-z a particle near the axis would weigh nodes at r < 0.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "../particles.hpp"
#include "stencil.hpp"

namespace mpmvv {

// The centred B-spline of degree Degree and its derivative at distance r
// (in cells) from its node.
struct BsplineValue {
  double value;
  double derivative;
};

template <int Degree>
inline BsplineValue bspline_1d(double r) {
  const double a = std::abs(r), sign = r < 0.0 ? -1.0 : 1.0;
  if constexpr (Degree == 2) {
    if (a < 0.5) return {0.75 - a * a, -2.0 * r};
    if (a < 1.5) return {0.5 * (1.5 - a) * (1.5 - a), -sign * (1.5 - a)};
  } else {
    static_assert(Degree == 3, "quadratic and cubic B-splines");
    if (a < 1.0) return {2.0 / 3.0 - a * a + 0.5 * a * a * a, sign * (1.5 * a * a - 2.0 * a)};
    if (a < 2.0) return {(2.0 - a) * (2.0 - a) * (2.0 - a) / 6.0, -sign * 0.5 * (2.0 - a) * (2.0 - a)};
  }
  return {0.0, 0.0};
}

template <int Degree>
struct BsplineShapeT {
  static constexpr int width = Degree + 1;  // nodes per axis
  static constexpr int stencil_size = width * width;
  static constexpr const char* name = Degree == 2 ? "bspline" : "bspline-cubic";
  static constexpr Geometry geometry = Geometry::plane_strain;
  static constexpr bool reads_deformation_gradient = false;
  static constexpr bool gradients_beyond_grid_basis = false;  // the grid basis itself
  static constexpr bool has_domain = false;                   // a point, as in standard MPM
  using GridBasis = BsplineShapeT;  // the basis a grid field is read with at a point
  // How far, in cells, a particle keeps from every wall (above).
  static constexpr double wall_clearance = 0.5 * (Degree - 1);

  const GridGeometry* grid;
  const Vec2* position;

  static BsplineShapeT bind(const GridGeometry& grid, const Particles& particles, const Mat2* = nullptr,
                            double = 1.0) {
    return {&grid, particles.position.data()};
  }

  void evaluate(std::size_t p, Stencil<stencil_size>& s) const {
    const GridGeometry& g = *grid;
    const Vec2 xi = grid_coordinate(g, position[p]);
    // The first of the nodes whose splines cover the point. A point exactly
    // at the last position inside() accepts takes the inner set, on which the
    // outer node's spline is zero.
    const int i0 = std::clamp(static_cast<int>(std::floor(xi.x() - 0.5 * (Degree - 1))), 0, g.cells_x - Degree);
    const int j0 = std::clamp(static_cast<int>(std::floor(xi.y() - 0.5 * (Degree - 1))), 0, g.cells_y - Degree);
    BsplineValue wx[width], wy[width];
    for (int a = 0; a < width; ++a) {
      wx[a] = bspline_1d<Degree>(xi.x() - (i0 + a));
      wy[a] = bspline_1d<Degree>(xi.y() - (j0 + a));
    }
    const double inv_h = 1.0 / g.h;
    const int first = g.node(i0, j0);
    int k = 0;
    for (int b = 0; b < width; ++b)
      for (int a = 0; a < width; ++a, ++k) {
        s.node[k] = first + b * g.nodes_x() + a;
        s.weight[k] = wx[a].value * wy[b].value;
        s.gradient[k] = inv_h * Vec2(wx[a].derivative * wy[b].value, wx[a].value * wy[b].derivative);
      }
  }

  // The particle lies between the walls, clear of each (above), and its
  // nodes exist.
  bool inside(std::size_t p) const { return inside_walls(*grid, position[p]) && clear_of_walls(p); }

  bool clear_of_walls(std::size_t p) const {
    const Vec2 xi = grid_coordinate(*grid, position[p]);
    const double lo = grid->ghost_layers + wall_clearance;
    return xi.x() >= lo && xi.y() >= lo && xi.x() <= grid->cells_x - lo && xi.y() <= grid->cells_y - lo;
  }

  // A material point has no domain: its half-vectors are zero.
  Mat2 domain(std::size_t) const { return Mat2::Zero(); }
};

using BsplineShape = BsplineShapeT<2>;
using CubicBsplineShape = BsplineShapeT<3>;

}  // namespace mpmvv
