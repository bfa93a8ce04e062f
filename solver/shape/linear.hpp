// Standard MPM: the particle is a Dirac delta (eq. 1.88), so the effective
// shape function is the bilinear hat of its cell, eqs. 1.86-1.87, with the
// piecewise-constant gradient of eq. 1.89 (002_c3305cb8b1bc1490.txt section 1.6.1).
// In r-z the point quadrature gives <S_g / r> = S_g(x_p) / r_p.
#pragma once

#include <cstddef>

#include "../particles.hpp"
#include "stencil.hpp"

namespace mpmvv {

// Bilinear hat weights and gradients of the four nodes of the cell holding x
// (x inside the grid). Shared by linear MPM and by massless tracers.
inline void bilinear_cell(const GridGeometry& grid, const Vec2& x, int* node, double* weight, Vec2* gradient) {
  const Vec2 xi = grid_coordinate(grid, x);
  const int i = cell_index(xi.x(), grid.cells_x);
  const int j = cell_index(xi.y(), grid.cells_y);
  const double fx = xi.x() - i, fy = xi.y() - j;  // in [0, 1]
  const double gx = 1.0 - fx, gy = 1.0 - fy;
  const double inv_h = 1.0 / grid.h;
  const int n00 = grid.node(i, j);
  node[0] = n00;
  node[1] = n00 + 1;
  node[2] = n00 + grid.nodes_x();
  node[3] = n00 + grid.nodes_x() + 1;
  weight[0] = gx * gy;
  weight[1] = fx * gy;
  weight[2] = gx * fy;
  weight[3] = fx * fy;
  gradient[0] = Vec2(-gy, -gx) * inv_h;
  gradient[1] = Vec2(gy, -fx) * inv_h;
  gradient[2] = Vec2(-fy, gx) * inv_h;
  gradient[3] = Vec2(fy, fx) * inv_h;
}

// Bilinear hat weights alone, for callers that form their own gradients.
inline void bilinear_cell_weights(const GridGeometry& grid, const Vec2& x, int* node, double* weight) {
  const Vec2 xi = grid_coordinate(grid, x);
  const int i = cell_index(xi.x(), grid.cells_x);
  const int j = cell_index(xi.y(), grid.cells_y);
  const double fx = xi.x() - i, fy = xi.y() - j;
  const double gx = 1.0 - fx, gy = 1.0 - fy;
  const int n00 = grid.node(i, j);
  node[0] = n00;
  node[1] = n00 + 1;
  node[2] = n00 + grid.nodes_x();
  node[3] = n00 + grid.nodes_x() + 1;
  weight[0] = gx * gy;
  weight[1] = fx * gy;
  weight[2] = gx * fy;
  weight[3] = fx * fy;
}

template <Geometry G>
struct LinearShapeT {
  static constexpr int stencil_size = 4;
  static constexpr const char* name = "linear";
  static constexpr Geometry geometry = G;
  static constexpr bool reads_deformation_gradient = false;
  static constexpr bool gradients_beyond_grid_basis = false;  // the grid basis itself
  static constexpr bool has_domain = false;                   // a point (eq. 1.88)
  using GridBasis = LinearShapeT;  // the basis a grid field is read with at a point

  const GridGeometry* grid;
  const Vec2* position;

  static LinearShapeT bind(const GridGeometry& grid, const Particles& particles, const Mat2* = nullptr,
                       double = 1.0) {
    return {&grid, particles.position.data()};
  }

  void evaluate(std::size_t p, Stencil<stencil_size>& s) const {
    bilinear_cell(*grid, position[p], s.node, s.weight, s.gradient);
    if constexpr (G == Geometry::axisymmetric) {
      const double inv_r = 1.0 / position[p].x();
      for (int k = 0; k < stencil_size; ++k) s.hoop[k] = s.weight[k] * inv_r;
    }
  }

  // The particle lies between the walls (and, in r-z, off the axis).
  bool inside(std::size_t p) const {
    if constexpr (G == Geometry::axisymmetric)
      if (!(position[p].x() > 0.0)) return false;
    return inside_walls(*grid, position[p]);
  }

  // A material point has no domain: its half-vectors are zero.
  Mat2 domain(std::size_t) const { return Mat2::Zero(); }
};

using LinearShape = LinearShapeT<Geometry::plane_strain>;

}  // namespace mpmvv
