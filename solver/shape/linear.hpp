// Standard MPM: the particle is a Dirac delta (eq. 1.88), so the effective
// shape function is the bilinear hat of its cell, eqs. 1.86-1.87, with the
// piecewise-constant gradient of eq. 1.89 (002_c3305cb8b1bc1490.txt section 1.6.1).
// In r-z the point quadrature gives <S_g / r> = S_g(x_p) / r_p. In plane
// strain the stencils come eight at a time from a lane kernel
// (linear_lanes.hpp), to the same bits.
#pragma once

#include <algorithm>
#include <cstddef>

#include "../particles.hpp"
#include "linear_lanes.hpp"
#include "stencil.hpp"

namespace mpmvv {

// Bilinear hat weights and gradients of the four nodes of the cell holding x
// (x inside the grid). Shared by linear MPM and by massless tracers.
// `gradient_scale` is 1 but for a deliberate fault (faults.hpp: linear-gradient).
inline void bilinear_cell(const GridGeometry& grid, const Vec2& x, int* node, double* weight, Vec2* gradient,
                          double gradient_scale = 1.0) {
  const Vec2 xi = grid_coordinate(grid, x);
  const int i = cell_index(xi.x(), grid.cells_x);
  const int j = cell_index(xi.y(), grid.cells_y);
  const double fx = xi.x() - i, fy = xi.y() - j;  // in [0, 1]
  const double gx = 1.0 - fx, gy = 1.0 - fy;
  const double inv_h = gradient_scale / grid.h;
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

// Bilinear hat weights alone at grid coordinate xi, for callers that form
// their own gradients.
inline void bilinear_cell_weights_at(const GridGeometry& grid, const Vec2& xi, int* node, double* weight) {
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

// The same at a point x of the plane.
inline void bilinear_cell_weights(const GridGeometry& grid, const Vec2& x, int* node, double* weight) {
  bilinear_cell_weights_at(grid, grid_coordinate(grid, x), node, weight);
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
  double gradient_scale = 1.0;  // 1, but for a deliberate fault (faults.hpp: linear-gradient)

  static LinearShapeT bind(const GridGeometry& grid, const Particles& particles, const Mat2* = nullptr,
                       double gradient_scale = 1.0) {
    return {&grid, particles.position.data(), gradient_scale};
  }

  void evaluate(std::size_t p, Stencil<stencil_size>& s) const {
    bilinear_cell(*grid, position[p], s.node, s.weight, s.gradient, gradient_scale);
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

  // Plane strain evaluates eight particles at a time by the lane kernel
  // (linear_lanes.hpp), to the same bits as evaluate; every lane's nodes are
  // a 2 x 2 block, which the transfers take by rows (stages.hpp:
  // scatter_by_rows, grid_to_particles).
  static constexpr bool lanes = G == Geometry::plane_strain;
  static constexpr bool lane_blocks_only = lanes;

  using LaneBatch = LaneBatchOfStencils<LinearLaneStencils>;

  void compute_lanes(std::size_t first, int count, LaneBatch& batch, bool /*for_scan*/ = true,
                     const LaneBuild* build = nullptr) const
    requires lanes
  {
    const GridGeometry& g = *grid;
    const double* in = values_of(position + first);
    LinearLaneCopy copy;
    if (count < kLanes) {
      for (int l = 0; l < kLanes; ++l)
        std::copy_n(values_of(position + copied_lane_particle(first, count, l)), 2, copy.position + 2 * l);
      in = copy.position;
    }
    batch.first = first;
    const Vec2 wall_lower = g.wall_lower(), wall_upper = g.wall_upper();
    const LinearLaneGrid lane_grid{g.origin.x(),   g.origin.y(),   g.h,            g.cells_x,     g.cells_y,
                                   g.nodes_x(),    wall_lower.x(), wall_lower.y(), wall_upper.x(), wall_upper.y(),
                                   gradient_scale};
    linear_lane_stencils(build ? *build : lane_build(), lane_grid, in, batch.out);
  }

  // inside(p) of the batch's lane l.
  bool lane_inside(const LaneBatch& batch, int l) const
    requires lanes
  {
    return batch.out.inside[l] != 0;
  }

  // Lane l's entries as evaluate lists them, each passed to f(node, S_gp, G_gp).
  template <class F>
  void for_each_lane_entry(const LaneBatch& batch, int l, F&& f) const
    requires lanes
  {
    const LinearLaneStencils& out = batch.out;
    const int n00 = out.first_node[l], row = grid->nodes_x();
    const int node[4] = {n00, n00 + 1, n00 + row, n00 + row + 1};
    constexpr int kSlot[4] = {0, 1, 3, 4};
    for (int k = 0; k < 4; ++k)
      f(node[k], out.weight[kSlot[k]][l], Vec2(out.gradient_x[kSlot[k]][l], out.gradient_y[kSlot[k]][l]));
  }

  // Lane l's block, from its first node (always one: the cell's four nodes).
  std::ptrdiff_t lane_block_first(const LaneBatch& batch, int l) const
    requires lanes
  {
    return batch.out.first_node[l];
  }

  // No bounds of sum_g |G_gp|: the gradients are the grid basis's.
  const double* lane_gradient_bounds(const LaneBatch&) const
    requires lanes
  {
    return nullptr;
  }
};

using LinearShape = LinearShapeT<Geometry::plane_strain>;

}  // namespace mpmvv
