// The locking remedies: each particle given its cell's or its nodes' mean
// dilatation (eqs. 1.82-1.84). A stage of solver/stages.hpp.
#pragma once

#include "grid_to_particle.hpp"

namespace mpmvv {

// ---------------------------------------------------------------- locking remedy

// Scales particle p's F to the dilatation J_target, F_p <- (J_target / J_p)^(1/d) F_p
// (eq. 1.84 with d = 2 for the in-plane block; in r-z the hoop stretch takes its
// share, d = 3), and sets V_p = J_target V_p0. The isochoric part of F is kept.
// A particle with no positive J is left to the health scan.
template <Geometry G>
void scale_to_dilatation(Particles& P, std::size_t p, double J_target) {
  const double J = P.volume[p] / P.reference_volume[p];
  if (!(J > 0.0 && J_target > 0.0)) return;
  if constexpr (G == Geometry::axisymmetric) {
    const double scale = std::cbrt(J_target / J);
    P.deformation_gradient[p] *= scale;
    P.hoop_stretch[p] *= scale;
  } else {
    P.deformation_gradient[p] *= std::sqrt(J_target / J);
  }
  P.volume[p] = J_target * P.reference_volume[p];
}

// The cell-averaged dilatation of 002_c3305cb8b1bc1490.txt eqs. 1.82-1.84: in
// each cell c (by the particles' centres), V_c0 = sum V_p0 and V_c = sum V_p
// give J_c = V_c / V_c0 (eqs. 1.82-1.83), and each particle's F is scaled to
// that dilatation, F_p <- (J_c / J_p)^(1/d) F_p (eq. 1.84 with d = 3; here
// d = 2 for the in-plane block, and in r-z the hoop stretch takes its share:
// d = 3 over (F_inplane, F_theta)), with V_p = J_c V_p0. It relaxes the
// volumetric constraint to one per cell, which is what unlocks a nearly
// incompressible material. `cell_volume` holds two sums per cell, per thread.
template <Geometry G>
void average_cell_dilatation(const GridGeometry& grid, Particles& P, std::vector<std::vector<double>>& cell_volume) {
  const std::size_t n = P.size();
  const std::size_t cells = std::size_t(grid.cells_x) * std::size_t(grid.cells_y);
  const int threads = int(cell_volume.size());
  auto cell_of = [&](std::size_t p) {
    const Vec2 xi = grid_coordinate(grid, P.position[p]);
    return std::size_t(cell_index(std::max(xi.y(), 0.0), grid.cells_y)) * std::size_t(grid.cells_x) +
           std::size_t(cell_index(std::max(xi.x(), 0.0), grid.cells_x));
  };
#pragma omp parallel num_threads(threads)
  {
    std::vector<double>& own = cell_volume[std::size_t(thread_id())];
    own.assign(2 * cells, 0.0);
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      const std::size_t c = cell_of(p);
      own[2 * c] += P.reference_volume[p];
      own[2 * c + 1] += P.volume[p];
    }
    sum_into_first(cell_volume, 2 * cells);
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      const std::size_t c = cell_of(p);
      const double J_cell = cell_volume[0][2 * c + 1] / cell_volume[0][2 * c];
      scale_to_dilatation<G>(P, p, J_cell);
    }
  }
}

// The same remedy with the grid's nodes in place of cells and the method's
// own weights in place of "the cell holding the centre": each node takes
// J_g = sum_p S_gp V_p / sum_p S_gp V_p0 (eqs. 1.82-1.83 with S_gp as the
// share of a particle a node holds), each particle reads back
// Jbar_p = sum_g S_gp J_g and is scaled to it as in eq. 1.84. A dilatation
// that varies from particle to particle within a node's reach, which the
// grid cannot push back on, is smoothed away; one the grid resolves is kept
// to second order. `node_volume` holds two sums per node, per thread.
template <class Shape>
void smooth_node_dilatation(const Shape& shape, Particles& P, std::vector<std::vector<double>>& node_volume,
                            std::size_t nodes) {
  constexpr Geometry G = Shape::geometry;
  const std::size_t n = P.size();
  const int threads = int(node_volume.size());
#pragma omp parallel num_threads(threads)
  {
    std::vector<double>& own = node_volume[std::size_t(thread_id())];
    own.assign(2 * nodes, 0.0);
    Stencil<Shape::stencil_size> s;
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      shape.evaluate(p, s);
      for (int k = 0; k < s.count; ++k) {
        own[2 * std::size_t(s.node[k])] += s.weight[k] * P.reference_volume[p];
        own[2 * std::size_t(s.node[k]) + 1] += s.weight[k] * P.volume[p];
      }
    }
    sum_into_first(node_volume, 2 * nodes);
    const std::vector<double>& sums = node_volume[0];
#pragma omp for schedule(static)
    for (std::size_t p = 0; p < n; ++p) {
      shape.evaluate(p, s);
      double J_bar = 0.0, weight = 0.0;
      for (int k = 0; k < s.count; ++k) {
        const std::size_t i = std::size_t(s.node[k]);
        if (!(sums[2 * i] > 0.0)) continue;
        J_bar += s.weight[k] * sums[2 * i + 1] / sums[2 * i];
        weight += s.weight[k];
      }
      J_bar /= weight;
      scale_to_dilatation<G>(P, p, J_bar);
    }
  }
}

}  // namespace mpmvv
