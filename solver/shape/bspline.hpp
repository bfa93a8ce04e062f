// Quadratic B-spline MPM (method = "bspline"): the particle is a point, as in
// standard MPM (002_c3305cb8b1bc1490.txt eq. 1.88), but the grid basis is the
// tensor product of uniform quadratic B-splines centred on the nodes instead
// of the bilinear hats of eqs. 1.86-1.87. Along one axis, with d = xi - i0 in
// [-1/2, 1/2) the particle's offset from its nearest node i0 (in cells):
//   N_{i0-1} = (1/2 - d)^2 / 2,   N_{i0} = 3/4 - d^2,   N_{i0+1} = (1/2 + d)^2 / 2,
//   dN/dx    = -(1/2 - d) / h,    -2 d / h,             (1/2 + d) / h.
// They sum to one and reproduce x (sum_i N_i i = i0 + d), so a linear field
// and a uniform motion are carried exactly, as by the hats. Unlike the hats,
// the basis is C1 across cell lines: a particle that crosses one sees no jump
// in its gradients, which is the noise of the cell crossing in standard MPM
// and uGIMP. Its gradients sum over the nodes to at most 2 / h along an axis,
// the bilinear hats' own bound, so the step rule of the hats holds
// (stages.hpp: kGridBasisGradientBound).
//
// The support spans three nodes per axis, one beyond the particle's nearest.
// A particle within half a cell of a wall would weigh the ghost node beyond
// it, and the walls (stages.hpp: apply_walls) overwrite a ghost node with the
// mirror of the node inside instead of adding its mass and force there: the
// particle's share on the ghost would be lost, an error of first order at
// the wall (measured: the axis-aligned problem, which fills its walls,
// converged at order 1.1-1.5 on 8-64 cells against CPDI's 2.0). So a particle
// must stay half a cell clear of every wall; then the images of the
// particles beyond a wall reach no node inside, and the mirror is the exact
// symmetry condition. Plane strain only: in r-z a particle near the axis
// would weigh nodes at r < 0.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "../particles.hpp"
#include "stencil.hpp"

namespace mpmvv {

// The three weights and their derivatives (per cell) along one axis, for the
// offset d of a point from its nearest node.
struct BsplineWeights1D {
  double weight[3];
  double derivative[3];
};

inline BsplineWeights1D bspline_weights_1d(double d) {
  const double a = 0.5 - d, b = 0.5 + d;
  return {{0.5 * a * a, 0.75 - d * d, 0.5 * b * b}, {-a, -2.0 * d, b}};
}

struct BsplineShape {
  static constexpr int stencil_size = 9;
  static constexpr const char* name = "bspline";
  static constexpr Geometry geometry = Geometry::plane_strain;
  static constexpr bool reads_deformation_gradient = false;
  static constexpr bool gradients_beyond_grid_basis = false;  // the grid basis itself
  static constexpr bool has_domain = false;                   // a point, as in standard MPM

  const GridGeometry* grid;
  const Vec2* position;

  static BsplineShape bind(const GridGeometry& grid, const Particles& particles, const Mat2* = nullptr,
                           double = 1.0) {
    return {&grid, particles.position.data()};
  }

  void evaluate(std::size_t p, Stencil<stencil_size>& s) const {
    const GridGeometry& g = *grid;
    const Vec2 xi = grid_coordinate(g, position[p]);
    // The nearest node; a point half a cell from the grid's edge (inside()
    // accepts it) takes the inner one, where d = +-1/2 gives the outer node
    // zero weight.
    const int i0 = std::clamp(static_cast<int>(std::floor(xi.x() + 0.5)), 1, g.cells_x - 1);
    const int j0 = std::clamp(static_cast<int>(std::floor(xi.y() + 0.5)), 1, g.cells_y - 1);
    const BsplineWeights1D wx = bspline_weights_1d(xi.x() - i0), wy = bspline_weights_1d(xi.y() - j0);
    const double inv_h = 1.0 / g.h;
    const int first = g.node(i0 - 1, j0 - 1);
    int k = 0;
    for (int b = 0; b < 3; ++b)
      for (int a = 0; a < 3; ++a, ++k) {
        s.node[k] = first + b * g.nodes_x() + a;
        s.weight[k] = wx.weight[a] * wy.weight[b];
        s.gradient[k] = inv_h * Vec2(wx.derivative[a] * wy.weight[b], wx.weight[a] * wy.derivative[b]);
      }
  }

  // The particle lies between the walls, half a cell clear of each (above),
  // and its three nodes per axis exist.
  bool inside(std::size_t p) const { return inside_walls(*grid, position[p]) && clear_of_walls(p); }

  bool clear_of_walls(std::size_t p) const {
    const Vec2 xi = grid_coordinate(*grid, position[p]);
    const double lo = grid->ghost_layers + 0.5;
    return xi.x() >= lo && xi.y() >= lo && xi.x() <= grid->cells_x - lo && xi.y() <= grid->cells_y - lo;
  }

  // A material point has no domain: its half-vectors are zero.
  Mat2 domain(std::size_t) const { return Mat2::Zero(); }
};

}  // namespace mpmvv
