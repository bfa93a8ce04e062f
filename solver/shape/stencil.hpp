// The grid nodes a particle talks to, with the effective weight S_gp and the
// effective gradient G_gp of each (002_c3305cb8b1bc1490.txt eqs. 1.69-1.73).
// Every transfer stage fills one of these per particle with the method's
// `evaluate`, so particle-to-grid and grid-to-particle share one computation.
#pragma once

#include <cmath>

#include "../grid.hpp"
#include "../tensor.hpp"

namespace mpmvv {

template <int N>
struct Stencil {
  static constexpr int size = N;
  int node[N];
  double weight[N];
  Vec2 gradient[N];
};

// Grid coordinate of a point, in cells from the domain's lower-left corner.
inline Vec2 grid_coordinate(const GridGeometry& grid, const Vec2& x) {
  return (x - grid.origin) / grid.h;
}

// True when the point lies in the half-open domain [0, cells) along both axes,
// so that the two nodes of its cell exist. NaN coordinates fail the test.
inline bool inside_cells(const GridGeometry& grid, const Vec2& xi) {
  return xi.x() >= 0.0 && xi.x() < grid.cells_x && xi.y() >= 0.0 && xi.y() < grid.cells_y;
}

}  // namespace mpmvv
