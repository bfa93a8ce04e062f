// The outline of a CPDI domain for its exact integration (cpdi_exact.hpp):
// the parallelogram x_p + F_p diag(l_p) of cpdi_domain.hpp, a particle's own
// outline mapped by F_p (a cut piece of a boundary cell, seeding), or with
// corner domains the quadrilateral of its four corners; its box in grid
// coordinates and whether it fits the block of cells a stencil holds.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstddef>

#include "../domain_corners.hpp"
#include "../particles.hpp"
#include "stencil.hpp"

namespace mpmvv {

template <Geometry G, bool Corners = false>
struct CpdiOutlineT {
  static_assert(!Corners || G == Geometry::plane_strain, "corner domains are plane strain only");
  static constexpr int block = 4;                       // nodes per direction the domain may reach
  // Points of a particle's own outline: a cut piece has its sub-cell's
  // corners and the chords of an arc (about 10); one that took in slivers has
  // theirs too, two more per bridge (37 seen on the ring at 128 cells).
  static constexpr int kMaxOutline = 64;

  const GridGeometry* grid;
  const Vec2* position;
  const Mat2* deformation_gradient;
  const Vec2* half_size;
  const std::uint32_t* domain_first;  // null when no particle has an outline of its own
  const Vec2* domain_vertex;
  double gradient_scale;  // 1, but for a deliberate fault (faults.hpp: cpdi-gradient)
  const Vec2* corners;    // Corners: x_pc, four per particle (Particles::domain_corner); else null

  // The map of the domain from the reference: F_p, or I when
  // `deformation_gradient` is null (the reference domains of the total
  // Lagrangian formulation, total_lagrangian.hpp).
  Mat2 domain_map(std::size_t p) const { return deformation_gradient ? deformation_gradient[p] : Mat2::Identity(); }

  // s_p = [r_1 r_2], the current domain half-vectors as columns (eq. 1.97);
  // for corner domains the linear part [a_1 a_2] of their map, or F_p A_p for
  // one turned over (folded).
  Mat2 domain(std::size_t p) const {
    if constexpr (Corners) {
      const Mat2 s = corner_half_vectors(corners + 4 * p);
      if (!turned_over(s)) return s;
    }
    Mat2 s = domain_map(p);
    s.col(0) *= half_size[p].x();
    s.col(1) *= half_size[p].y();
    return s;
  }

  // The domain's current outline in grid coordinates, counter-clockwise when
  // det F > 0: the particle's own outline (Particles::domain_vertex) mapped by
  // F_p, or the parallelogram's four corners. Returns the number of points.
  int outline(std::size_t p, Vec2* c) const {
    if constexpr (Corners) {
      // A crossed quadrilateral (a thin domain whose corners the grid
      // velocity has turned past each other) is integrated as the
      // parallelogram of its linear part, a_0 +- a_1 +- a_2: the same centre
      // and area, counter-clockwise while the area is positive. Its corners
      // stay as they are, shared with its neighbours.
      // One turned over takes its particle's parallelogram (folded, below).
      const Vec2* x = corners + 4 * p;
      if (!folded(p)) {
        if (crossed(x)) {
          const Mat2 s = corner_half_vectors(x) / grid->h;
          const Vec2 a0 = grid_coordinate(*grid, 0.25 * (x[0] + x[1] + x[2] + x[3]));
          for (int k = 0; k < 4; ++k) c[k] = a0 + kCornerXi[k] * s.col(0) + kCornerEta[k] * s.col(1);
          return 4;
        }
        for (int k = 0; k < 4; ++k) c[k] = grid_coordinate(*grid, x[k]);
        return 4;
      }
    }
    const Vec2 x = grid_coordinate(*grid, position[p]);
    if (domain_first != nullptr && domain_first[p + 1] > domain_first[p]) {
      const Mat2 F = domain_map(p) / grid->h;
      const int count = int(domain_first[p + 1] - domain_first[p]);
      const Vec2* d = domain_vertex + domain_first[p];
      for (int k = 0; k < count; ++k) c[k] = x + F * d[k];
      return count;
    }
    const Mat2 s = domain(p) / grid->h;
    c[0] = x - s.col(0) - s.col(1);
    c[1] = x + s.col(0) - s.col(1);
    c[2] = x + s.col(0) + s.col(1);
    c[3] = x - s.col(0) + s.col(1);
    return 4;
  }

  // The outline's bounding box in grid coordinates.
  static void bounds(const Vec2* c, int count, Vec2& lo, Vec2& hi) {
    lo = hi = c[0];
    for (int k = 1; k < count; ++k) {
      lo = lo.cwiseMin(c[k]);
      hi = hi.cwiseMax(c[k]);
    }
  }

  // The lowest cell of the block the outline starts in.
  static void block_origin(const Vec2& lo, const GridGeometry& grid, int& i0, int& j0) {
    i0 = std::clamp(int(std::floor(lo.x())), 0, grid.cells_x - 1);
    j0 = std::clamp(int(std::floor(lo.y())), 0, grid.cells_y - 1);
  }

  // A corner domain turned over: its signed area, 4 det [a_1 a_2], is not
  // positive, and no outline of it bounds the material. Its particle is then
  // integrated over its own parallelogram x_p + F_p A_p (the domain of the
  // parallelogram form above, of area J_p V_0p = V_p), whose F_p the domain
  // averages keep updating with det F_p > 0; its corners keep moving with the
  // grid and are used again once they bound a positive area. The corners turn
  // over where the grid's velocity gradient is wrong by its own size across a
  // thin domain: the corner motion reads the velocity at four points, F_p its
  // exact average over the domain, and across a cell line the two part by the
  // hat's kink (the stiff vortex on 30 cells: 4 of 20,607 domains at t = 1 s,
  // all in the row of particles at reference radius 0.808 next to the inner
  // rim, where the corner interpolation of cpdi.hpp turns the same 4 over).
  // Monitors::folded_domains counts them at every output.
  bool folded(std::size_t p) const {
    if constexpr (Corners) return turned_over(corner_half_vectors(corners + 4 * p));
    return false;
  }

  // Whether a quadrilateral crosses itself (a bow tie: two opposite edges
  // meet). A quadrilateral with one reflex corner is simple and integrates
  // exactly; a crossed one does not (its two lobes enter with opposite signs).
  static bool crossed(const Vec2* x) {
    auto cross = [](const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); };
    // Segments ab and cd meet where each separates the other's ends.
    auto meet = [&](const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
      const double c1 = cross(b - a, c - a), c2 = cross(b - a, d - a);
      const double c3 = cross(d - c, a - c), c4 = cross(d - c, b - c);
      return ((c1 > 0.0) != (c2 > 0.0)) && ((c3 > 0.0) != (c4 > 0.0));
    };
    return meet(x[0], x[1], x[2], x[3]) || meet(x[1], x[2], x[3], x[0]);
  }

  // Whether the domain fits the 3 x 3 cells of the stencil (a domain stretched
  // further stops the run with the reason "domain too wide").
  bool within_stencil(std::size_t p) const {
    Vec2 lo, hi;
    outline_box(p, lo, hi);
    return within_block(lo, hi);
  }

  // The bounding box of particle p's current outline, in grid coordinates.
  void outline_box(std::size_t p, Vec2& lo, Vec2& hi) const {
    Vec2 c[kMaxOutline];
    bounds(c, outline(p, c), lo, hi);
  }

  bool within_block(const Vec2& lo, const Vec2& hi) const {
    int i0, j0;
    block_origin(lo, *grid, i0, j0);
    return hi.x() <= i0 + block - 1 && hi.y() <= j0 + block - 1;
  }
};

}  // namespace mpmvv
