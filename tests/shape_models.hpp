// What the shape-function tests share (test_shape_functions.cpp,
// test_shape_1d.cpp): a small grid, particles at given positions, random
// interior positions, and the round-off the properties hold to.
#pragma once

#include <cstddef>
#include <random>
#include <vector>

#include "solver/particles.hpp"
#include "solver/shape/bspline.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/cpdi_exact.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/linear.hpp"

namespace mpmvv::testing::shape_models {

using mpmvv::BsplineShape;
using mpmvv::CubicBsplineShape;
using mpmvv::CpdiExactShape;
using mpmvv::CpdiShape;
using mpmvv::GimpShape;
using mpmvv::GridGeometry;
using mpmvv::LinearShape;
using mpmvv::Mat2;
using mpmvv::Particles;
using mpmvv::Stencil;
using mpmvv::Vec2;

// Sums of a few products of numbers of order one (weights) or 1/h (gradients):
// round-off is a few 1e-16; 1e-12 leaves four orders of margin.
inline constexpr double kRoundOff = 1e-12;

inline GridGeometry small_grid() {
  GridGeometry g;
  g.origin = Vec2(-2.0, -2.0);
  g.h = 0.5;
  g.cells_x = 8;
  g.cells_y = 8;
  return g;
}

// One particle per position; two particles per cell per direction, so the
// half-size is h/4 (uGIMP and CPDI both need l <= h/2).
inline Particles particles_at(const GridGeometry& grid, const std::vector<Vec2>& positions,
                       const std::vector<Mat2>& deformation = {}) {
  Particles P;
  P.resize(positions.size());
  P.half_size.assign(positions.size(), Vec2(0.25 * grid.h, 0.25 * grid.h));
  for (std::size_t p = 0; p < positions.size(); ++p) {
    P.position[p] = positions[p];
    if (!deformation.empty()) P.deformation_gradient[p] = deformation[p];
    P.volume[p] = P.reference_volume[p] = 4.0 * P.half_size[p].x() * P.half_size[p].y();
  }
  return P;
}

inline Vec2 node_position(const GridGeometry& grid, int node) {
  return grid.node_position(node % grid.nodes_x(), node / grid.nodes_x());
}

inline std::vector<Vec2> random_interior_positions(const GridGeometry& grid, std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(1.5, grid.cells_x - 1.5);
  std::vector<Vec2> x;
  for (std::size_t k = 0; k < count; ++k) x.push_back(grid.origin + grid.h * Vec2(u(rng), u(rng)));
  return x;
}

}  // namespace mpmvv::testing::shape_models
