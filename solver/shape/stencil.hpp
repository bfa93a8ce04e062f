// The grid nodes a particle talks to, with the effective weight S_gp and the
// effective gradient G_gp of each (002_c3305cb8b1bc1490.txt eqs. 1.69-1.73).
// Every transfer stage fills one of these per particle with the method's
// `evaluate`, so particle-to-grid and grid-to-particle share one computation.
#pragma once

#include <algorithm>
#include <cmath>

#include "../geometry.hpp"
#include "../grid.hpp"
#include "../tensor.hpp"
#include "lane_shared.hpp"

namespace mpmvv {

// In r-z runs `hoop` holds <S_g / r>_p, the r-weighted average of S_g / r over
// the particle, which carries the hoop stress to the radial force and the
// radial velocity to the hoop rate (the same weight both ways, so the hoop
// work is conserved). Plane-strain shapes leave it unset.
//
// The first `count` entries are in use: N for every shape but CPDI, whose
// corners often share nodes and which then lists each node once (cpdi.hpp).
template <int N>
struct Stencil {
  static constexpr int size = N;
  int count = N;
  int node[N];
  double weight[N];
  Vec2 gradient[N];
  double hoop[N];
};

// A stencil's entries as a stage takes them: entries_of(s)(f) passes each
// to f(node, S_gp, G_gp, <S_g / r>_p) in turn (the lane kernels' batches pass
// theirs the same way, without a stencil: cpdi.hpp, for_each_lane_entry).
template <int N>
auto entries_of(const Stencil<N>& s) {
  return [&s](auto&& f) {
    for (int k = 0; k < s.count; ++k) f(s.node[k], s.weight[k], s.gradient[k], s.hoop[k]);
  };
}

// A stencil's nodes each once, in the order they first appear, with the sum
// of its entries' gradients in the order they are listed (a stretched CPDI
// domain lists a node once per corner that reaches it); an entry k for which
// skip(k) holds is passed over. Returns how many nodes.
template <int N, class Skip>
int merged_gradients(const Stencil<N>& s, int* node, Vec2* gradient, Skip skip) {
  int nodes = 0;
  for (int k = 0; k < s.count; ++k) {
    if (skip(k)) continue;
    int j = 0;
    while (j < nodes && node[j] != s.node[k]) ++j;
    if (j == nodes) {
      node[nodes] = s.node[k];
      gradient[nodes++] = s.gradient[k];
    } else {
      gradient[j] += s.gradient[k];
    }
  }
  return nodes;
}

// An upper bound of sum_k |G_k| over a stencil's entries as listed, without
// a square root, entry by entry
//   |G| <= max(|G_x|, |G_y|) + (sqrt 2 - 1) min(|G_x|, |G_y|)
// (the chord of the convex sqrt(1 + t^2) over t in [0, 1], equal at its
// ends): the time-step scan (stages.hpp: signal_speed) runs it for every
// particle every step, where nine square roots in a row cost more than the
// rest of the particle's test. kOctagonFactor: lane_shared.hpp.

template <int N>
double entry_gradient_sum_bound(const Stencil<N>& s) {
  double sum = 0.0;
  for (int k = 0; k < s.count; ++k) {
    const double x = std::abs(s.gradient[k].x()), y = std::abs(s.gradient[k].y());
    sum += std::max(x, y) + kOctagonFactor * std::min(x, y);
  }
  return sum;
}

// Grid coordinate of a point, in cells from the domain's lower-left corner.
inline Vec2 grid_coordinate(const GridGeometry& grid, const Vec2& x) {
  return (x - grid.origin) / grid.h;
}

// True when the point lies in the closed domain [0, cells] along both axes,
// so that the nodes of its cell exist (a point on the upper wall belongs to
// the last cell). NaN coordinates fail the test.
inline bool inside_cells(const GridGeometry& grid, const Vec2& xi) {
  return xi.x() >= 0.0 && xi.x() <= grid.cells_x && xi.y() >= 0.0 && xi.y() <= grid.cells_y;
}

// True when the point lies between the walls (closed). A particle's centre
// must; its support may reach into the ghost layers beyond.
inline bool inside_walls(const GridGeometry& grid, const Vec2& x) {
  const Vec2 lo = grid.wall_lower(), hi = grid.wall_upper();
  return x.x() >= lo.x() && x.x() <= hi.x() && x.y() >= lo.y() && x.y() <= hi.y();
}

// Index of the cell holding grid coordinate xi >= 0 along an axis of n cells;
// the upper wall belongs to the last cell.
inline int cell_index(double xi, int n) { return std::min(static_cast<int>(xi), n - 1); }

}  // namespace mpmvv
