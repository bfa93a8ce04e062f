// uGIMP: a top-hat particle of fixed half-size l_p (eq. 1.90) convolved with
// the linear hat, eqs. 1.91-1.92 in each direction and their tensor product in
// 2D (002_c3305cb8b1bc1490.txt sections 1.6.2-1.6.3). The size is not convected
// with F ("UGIMP"); eq. 1.91 holds for l_p <= h/2, which one or more particles
// per cell per direction guarantees.
#pragma once

#include <cstddef>

#include "../particles.hpp"
#include "stencil.hpp"

namespace mpmvv {

// Effective 1D weight (eq. 1.91) and its derivative (eq. 1.92) for a node at
// signed distance d = x_p - x_g, cell size h, particle half-size l <= h/2.
struct GimpWeight1D {
  double weight;
  double derivative;
};

inline GimpWeight1D gimp_weight_1d(double d, double h, double l) {
  if (d <= -h - l || d > h + l) return {0.0, 0.0};
  if (d <= -h + l) {
    const double s = h + l + d;
    return {s * s / (4.0 * h * l), s / (2.0 * h * l)};
  }
  if (d <= -l) return {1.0 + d / h, 1.0 / h};
  if (d <= l) return {1.0 - (d * d + l * l) / (2.0 * h * l), -d / (h * l)};
  if (d <= h - l) return {1.0 - d / h, -1.0 / h};
  const double s = h + l - d;
  return {s * s / (4.0 * h * l), -s / (2.0 * h * l)};
}

struct GimpShape {
  static constexpr int stencil_size = 9;
  static constexpr const char* name = "gimp";

  const GridGeometry* grid;
  const Vec2* position;
  const Vec2* half_size;

  static constexpr bool reads_deformation_gradient = false;

  static GimpShape bind(const GridGeometry& grid, const Particles& particles, const Mat2* = nullptr) {
    return {&grid, particles.position.data(), particles.half_size.data()};
  }

  // With l_p <= h/2 a particle reaches the node nearest to it and one on each
  // side, three per direction.
  void evaluate(std::size_t p, Stencil<stencil_size>& s) const {
    const GridGeometry& g = *grid;
    const Vec2 xi = grid_coordinate(g, position[p]);
    const int i0 = static_cast<int>(std::floor(xi.x() + 0.5)) - 1;
    const int j0 = static_cast<int>(std::floor(xi.y() + 0.5)) - 1;
    GimpWeight1D wx[3], wy[3];
    for (int a = 0; a < 3; ++a) {
      wx[a] = gimp_weight_1d((xi.x() - (i0 + a)) * g.h, g.h, half_size[p].x());
      wy[a] = gimp_weight_1d((xi.y() - (j0 + a)) * g.h, g.h, half_size[p].y());
    }
    int k = 0;
    for (int b = 0; b < 3; ++b) {
      for (int a = 0; a < 3; ++a, ++k) {
        s.node[k] = g.node(i0 + a, j0 + b);
        s.weight[k] = wx[a].weight * wy[b].weight;
        s.gradient[k] = Vec2(wx[a].derivative * wy[b].weight, wx[a].weight * wy[b].derivative);
      }
    }
  }

  // All three nodes along each axis exist.
  bool inside(std::size_t p) const {
    const Vec2 xi = grid_coordinate(*grid, position[p]);
    const double ix = std::floor(xi.x() + 0.5), iy = std::floor(xi.y() + 0.5);
    return ix >= 1.0 && ix <= grid->cells_x - 1 && iy >= 1.0 && iy <= grid->cells_y - 1;
  }
};

}  // namespace mpmvv
