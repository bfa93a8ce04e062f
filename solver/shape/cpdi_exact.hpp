// CPDI domains integrated exactly. The domain of particle p is the
// parallelogram of cpdi.hpp, spanned by r_1 = F_p (l_x e_x), r_2 = F_p (l_y e_y)
// about x_p (002_c3305cb8b1bc1490.txt eq. 1.97), but the averages of eq. 1.94,
//   S_gp = (1 / V_p) int_{Omega_p} S_g dA,   G_gp = (1 / V_p) int_{Omega_p} grad S_g dA,
// are taken over the domain itself rather than over the bilinear interpolation
// of the grid basis from its four corners (eq. 1.95). The corner interpolation
// is exact inside one cell but not across a cell line, where S_g has a kink;
// inside the body the domains share their edges and these errors cancel from
// one domain to the next, but along the body's boundary they do not, and where
// the boundary carries stress (a tangential stress on a curved rim) the nodal
// force keeps an error of relative size (l / h)^2 that does not fall with h.
//
// With corner domains (cpdi_domain = "corners", solver/domain_corners.hpp,
// plane strain) the domain is the quadrilateral of the particle's four
// corners, integrated the same way. The corner interpolation of cpdi.hpp
// reads the hats at the corners only, so a domain whose corners straddle a
// cell line averages the hat's kink with the trapezoid rule; where the shear
// runs along a grid line the particles keep their place across the line for
// the whole passage, the error does not average out from step to step, and
// the ring keeps a residual rotation whose size scales with the domain
// against the cell (suites/stiff-vortex.toml, study "updated-exact").
//
// The integration: the domain is clipped to every cell it meets (Sutherland-
// Hodgman against the cell's four sides, in grid coordinates), and on each
// piece the moments int 1, int u, int v, int u v (u, v the coordinates in the
// cell, 0 to 1) follow from the piece's vertices by Green's theorem. Clipping
// a polygon that is not convex (a piece of a rim, two pieces joined by a
// bridge) against a half-plane may join its pieces along the clipping line;
// such edges lie on the line and enclose nothing, so the moments stay exact. The
// bilinear basis of the cell's nodes, (1-u)(1-v), u(1-v), (1-u)v, uv, and its
// gradient are combinations of these moments. In r-z the averages carry the
// weight r (as in cpdi.hpp): S_gp = int r S_g / int r, G_gp = int r grad S_g /
// int r and <S/r>_p = int S_g / int r, with r linear in u, so the moments
// int u^2 and int u^2 v join. The domain may meet up to 3 x 3
// cells (a 4 x 4 block of nodes); a larger domain is reported by `inside`.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstddef>

#include "../domain_corners.hpp"
#include "../particles.hpp"
#include "linear.hpp"
#include "stencil.hpp"

namespace mpmvv {

// int 1, int u, int v, int u v over a polygon, counter-clockwise vertices
// (u_k, v_k): with c_k = u_k v_{k+1} - u_{k+1} v_k,
//   A = (1/2) sum c_k,  int u = (1/6) sum (u_k + u_{k+1}) c_k  (v alike),
//   int u v = (1/24) sum c_k (u_k v_{k+1} + 2 u_k v_k + 2 u_{k+1} v_{k+1} + u_{k+1} v_k).
// With `radial` also the moments an r weight needs (r linear in u):
//   int u^2 = (1/12) sum c_k (u_k^2 + u_k u_{k+1} + u_{k+1}^2),
//   int u^2 v = (1/60) sum c_k (u_k^2 (3 v_k + v_{k+1}) + 2 u_k u_{k+1} (v_k + v_{k+1})
//                               + u_{k+1}^2 (v_k + 3 v_{k+1})).
struct PolygonMoments {
  double area = 0.0, u = 0.0, v = 0.0, uv = 0.0;
  double uu = 0.0, uuv = 0.0;  // radial moments only
};

template <bool radial = false>
inline PolygonMoments polygon_moments(const Vec2* vertex, int count) {
  PolygonMoments m;
  for (int k = 0; k < count; ++k) {
    const Vec2& a = vertex[k];
    const Vec2& b = vertex[k + 1 == count ? 0 : k + 1];
    const double c = a.x() * b.y() - b.x() * a.y();
    m.area += c;
    m.u += (a.x() + b.x()) * c;
    m.v += (a.y() + b.y()) * c;
    m.uv += c * (a.x() * b.y() + 2.0 * a.x() * a.y() + 2.0 * b.x() * b.y() + b.x() * a.y());
    if constexpr (radial) {
      m.uu += c * (a.x() * a.x() + a.x() * b.x() + b.x() * b.x());
      m.uuv += c * (a.x() * a.x() * (3.0 * a.y() + b.y()) + 2.0 * a.x() * b.x() * (a.y() + b.y()) +
                    b.x() * b.x() * (a.y() + 3.0 * b.y()));
    }
  }
  m.area /= 2.0;
  m.u /= 6.0;
  m.v /= 6.0;
  m.uv /= 24.0;
  m.uu /= 12.0;
  m.uuv /= 60.0;
  return m;
}

// The part of a polygon on the side axis-coordinate >= bound (keep_above)
// or <= bound: each edge gives at most two points, and no more than
// `capacity` are written (the callers' buffers hold every realistic outline).
inline int clip_polygon(const Vec2* in, int count, int axis, double bound, bool keep_above, Vec2* out,
                        int capacity) {
  int n = 0;
  for (int k = 0; k < count && n + 2 <= capacity; ++k) {
    const Vec2& a = in[k];
    const Vec2& b = in[k + 1 == count ? 0 : k + 1];
    const double da = keep_above ? a[axis] - bound : bound - a[axis];
    const double db = keep_above ? b[axis] - bound : bound - b[axis];
    if (da >= 0.0) out[n++] = a;
    if ((da >= 0.0) != (db >= 0.0)) out[n++] = a + (da / (da - db)) * (b - a);
  }
  return n;
}

template <Geometry G, bool Corners = false>
struct CpdiExactShapeT {
  static_assert(!Corners || G == Geometry::plane_strain, "corner domains are plane strain only");
  static constexpr int block = 4;                       // nodes per direction the domain may reach
  static constexpr int stencil_size = block * block;
  // Points of a particle's own outline: a cut piece has its sub-cell's
  // corners and the chords of an arc (about 10); one that took in slivers has
  // theirs too, two more per bridge (37 seen on the ring at 128 cells).
  static constexpr int kMaxOutline = 64;
  static constexpr int kClipBuffer = 8 * kMaxOutline;
  static constexpr const char* name = "cpdi-exact";
  static constexpr Geometry geometry = G;
  static constexpr bool reads_deformation_gradient = true;
  static constexpr bool gradients_beyond_grid_basis = false;  // exact averages of the grid basis
  static constexpr bool has_domain = true;
  static constexpr bool corner_domains = Corners;  // the stepper moves the corners (domain_corners.hpp)
  using GridBasis = LinearShapeT<G>;  // the domain averages the hats
  // Clipping costs as much as the rest of a step: USL evaluates it once
  // (stored_stencils.hpp).
  static constexpr bool stores_stencils = true;

  const GridGeometry* grid;
  const Vec2* position;
  const Mat2* deformation_gradient;
  const Vec2* half_size;
  const std::uint32_t* domain_first;  // null when no particle has an outline of its own
  const Vec2* domain_vertex;
  double gradient_scale;  // 1, but for a deliberate fault (faults.hpp: cpdi-gradient)
  const Vec2* corners;    // Corners: x_pc, four per particle (Particles::domain_corner); else null

  static CpdiExactShapeT bind(const GridGeometry& grid, const Particles& particles,
                              const Mat2* deformation_gradient = nullptr, double gradient_scale = 1.0) {
    const bool outlines = !particles.domain_first.empty();
    return {&grid,
            particles.position.data(),
            deformation_gradient ? deformation_gradient : particles.deformation_gradient.data(),
            particles.half_size.data(),
            outlines ? particles.domain_first.data() : nullptr,
            outlines ? particles.domain_vertex.data() : nullptr,
            gradient_scale,
            Corners ? particles.domain_corner.data() : nullptr};
  }

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

  void evaluate(std::size_t p, Stencil<stencil_size>& st) const {
    const GridGeometry& g = *grid;
    constexpr bool radial = G == Geometry::axisymmetric;
    const double axis = -g.origin.x() / g.h;  // grid coordinate of r = 0
    Vec2 c[kClipBuffer];
    int count = outline(p, c);
    Vec2 lo, hi;
    bounds(c, count, lo, hi);
    if constexpr (radial) {
      // In r-z a domain that reaches over the axis keeps its part at r >= 0:
      // the mirrored ghost nodes stand for the rest, and r must not turn negative.
      if (lo.x() < axis) {
        Vec2 kept[kClipBuffer];
        count = clip_polygon(c, count, 0, axis, true, kept, kClipBuffer);
        for (int k = 0; k < count; ++k) c[k] = kept[k];
        lo.x() = axis;
      }
    }
    int i0, j0;
    block_origin(lo, g, i0, j0);
    double mass[stencil_size] = {}, radial_mass[stencil_size] = {};
    Vec2 grad[stencil_size];
    for (Vec2& v : grad) v.setZero();
    // Each cell of the block: clip, take the moments about the cell's corner.
    // A clip whose half-plane holds every point of the polygon would return
    // it point for point, so it is skipped: a domain within one cell is not
    // clipped at all.
    Vec2 row_a[kClipBuffer], row_b[kClipBuffer], a[kClipBuffer], piece[kClipBuffer];
    double area = 0.0;  // int dA, or in r-z int r dA (cells^3)
    int last_ci = 0, last_cj = 0;  // the farthest cell of the block the domain meets
    // The rows the polygon's points span (in r-z after the cut at the axis,
    // whose new points may round beyond the outline's box).
    double y_lo = lo.y(), y_hi = hi.y();
    if constexpr (radial) {
      Vec2 cut_lo, cut_hi;
      bounds(c, count, cut_lo, cut_hi);
      y_lo = cut_lo.y(), y_hi = cut_hi.y();
    }
    for (int cj = 0; cj < block - 1 && j0 + cj < g.cells_y; ++cj) {
      if (j0 + cj >= hi.y()) break;
      const Vec2* row = c;
      int n = count;
      if (!(y_lo >= j0 + cj)) n = clip_polygon(row, n, 1, j0 + cj, true, row_a, kClipBuffer), row = row_a;
      if (!(y_hi <= j0 + cj + 1)) n = clip_polygon(row, n, 1, j0 + cj + 1, false, row_b, kClipBuffer), row = row_b;
      if (n < 3) continue;
      Vec2 row_lo, row_hi;
      bounds(row, n, row_lo, row_hi);
      for (int ci = 0; ci < block - 1 && i0 + ci < g.cells_x; ++ci) {
        if (i0 + ci >= hi.x()) break;
        const Vec2* cell = row;
        int m = n;
        if (!(row_lo.x() >= i0 + ci)) m = clip_polygon(cell, m, 0, i0 + ci, true, a, kClipBuffer), cell = a;
        if (!(row_hi.x() <= i0 + ci + 1)) m = clip_polygon(cell, m, 0, i0 + ci + 1, false, piece, kClipBuffer), cell = piece;
        if (m < 3) continue;
        last_ci = std::max(last_ci, ci);
        last_cj = std::max(last_cj, cj);
        for (int k = 0; k < m; ++k) piece[k] = cell[k] - Vec2(i0 + ci, j0 + cj);
        const PolygonMoments q = polygon_moments<radial>(piece, m);
        // Nodes (0,0), (1,0), (0,1), (1,1) of the cell in the block.
        const int k00 = cj * block + ci, k10 = k00 + 1, k01 = k00 + block, k11 = k01 + 1;
        // Integrals of non-negative functions; a sliver's may round to -1e-17.
        mass[k00] += std::max(0.0, q.area - q.u - q.v + q.uv);
        mass[k10] += std::max(0.0, q.u - q.uv);
        mass[k01] += std::max(0.0, q.v - q.uv);
        mass[k11] += std::max(0.0, q.uv);
        if constexpr (radial) {
          // r = h (rho + u) with rho the cell's left edge: int r f = h (rho int f + int u f).
          const double rho = i0 + ci - axis;
          area += rho * q.area + q.u;
          radial_mass[k00] += std::max(0.0, rho * (q.area - q.u - q.v + q.uv) + (q.u - q.uu - q.uv + q.uuv));
          radial_mass[k10] += std::max(0.0, rho * (q.u - q.uv) + (q.uu - q.uuv));
          radial_mass[k01] += std::max(0.0, rho * (q.v - q.uv) + (q.uv - q.uuv));
          radial_mass[k11] += std::max(0.0, rho * q.uv + q.uuv);
          grad[k00] += rho * Vec2(-(q.area - q.v), -(q.area - q.u)) + Vec2(-(q.u - q.uv), -(q.u - q.uu));
          grad[k10] += rho * Vec2(q.area - q.v, -q.u) + Vec2(q.u - q.uv, -q.uu);
          grad[k01] += rho * Vec2(-q.v, q.area - q.u) + Vec2(-q.uv, q.u - q.uu);
          grad[k11] += rho * Vec2(q.v, q.u) + Vec2(q.uv, q.uu);
        } else {
          area += q.area;
          grad[k00] += Vec2(-(q.area - q.v), -(q.area - q.u));
          grad[k10] += Vec2(q.area - q.v, -q.u);
          grad[k01] += Vec2(-q.v, q.area - q.u);
          grad[k11] += Vec2(q.v, q.u);
        }
      }
    }
    // Divide by the domain's area (in cells^2; in r-z its int r dA, in cells^3)
    // and turn d/du into d/dx. In r-z <S/r> = int S dA / int r dA. Only the
    // nodes of the cells the domain meets are listed, each once (a domain
    // within one cell has 4 of the block's 16): the others' entries are zero,
    // and the transfers and the stored stencils (stored_stencils.hpp) skip them.
    const double inv_area = 1.0 / area, gradient_factor = gradient_scale * inv_area / g.h;
    const int nx = g.nodes_x();
    int n = 0;
    for (int kj = 0; kj <= last_cj + 1; ++kj)
      for (int ki = 0; ki <= last_ci + 1; ++ki, ++n) {
        const int k = kj * block + ki;
        st.node[n] = (j0 + kj) * nx + i0 + ki;
        st.gradient[n] = gradient_factor * grad[k];
        if constexpr (radial) {
          st.weight[n] = radial_mass[k] * inv_area;
          st.hoop[n] = mass[k] * inv_area / g.h;
        } else {
          st.weight[n] = mass[k] * inv_area;
        }
      }
    st.count = n;
  }

  // The centre between the walls (in r-z off the axis), the whole outline in
  // the grid, and within the 3 x 3 cells the stencil holds.
  bool inside(std::size_t p) const {
    if (!inside_walls(*grid, position[p])) return false;
    if constexpr (G == Geometry::axisymmetric)
      if (!(position[p].x() > 0.0)) return false;
    Vec2 lo, hi;
    outline_box(p, lo, hi);
    return inside_cells(*grid, lo) && inside_cells(*grid, hi) && within_block(lo, hi);
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

using CpdiExactShape = CpdiExactShapeT<Geometry::plane_strain>;

}  // namespace mpmvv
