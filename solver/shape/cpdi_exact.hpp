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
#include <cstddef>

#include "../particles.hpp"
#include "cpdi_outline.hpp"
#include "linear.hpp"
#include "polygon_moments.hpp"
#include "stencil.hpp"

namespace mpmvv {

template <Geometry G, bool Corners = false>
struct CpdiExactShapeT : CpdiOutlineT<G, Corners> {
  using Outline = CpdiOutlineT<G, Corners>;
  using Outline::grid;
  using Outline::position;
  using Outline::gradient_scale;
  using Outline::block;
  using Outline::kMaxOutline;
  using Outline::outline;
  using Outline::bounds;
  using Outline::block_origin;
  using Outline::outline_box;
  using Outline::within_block;
  static constexpr int stencil_size = block * block;
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
  // A node reached by a sliver of the domain (a side on a grid line to
  // round-off) with under 1e-14 of the particle's weight is left empty by
  // the grid update (grid_conditions.hpp: unresolved_node_mass).
  static constexpr double unresolved_mass = 1e-14;

  static CpdiExactShapeT bind(const GridGeometry& grid, const Particles& particles,
                              const Mat2* deformation_gradient = nullptr, double gradient_scale = 1.0) {
    const bool outlines = !particles.domain_first.empty();
    return {{&grid,
             particles.position.data(),
             deformation_gradient ? deformation_gradient : particles.deformation_gradient.data(),
             particles.half_size.data(),
             outlines ? particles.domain_first.data() : nullptr,
             outlines ? particles.domain_vertex.data() : nullptr,
             gradient_scale,
             Corners ? particles.domain_corner.data() : nullptr}};
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
        // Nodes (0,0), (1,0), (0,1), (1,1) of the cell in the block.
        const int k00 = cj * block + ci, k10 = k00 + 1, k01 = k00 + block, k11 = k01 + 1;
        if constexpr (!radial) {
          // The moments about the cell corner nearest the piece (u' = 1 - u
          // past the cell's middle, v' alike): a sliver along a cell side
          // then has small coordinates, and the weights and gradients of the
          // nodes across from it, differences of its moments, keep the
          // precision of the sliver's own size rather than of the cell's.
          Vec2 piece_lo, piece_hi;
          bounds(cell, m, piece_lo, piece_hi);
          const bool flip_u = piece_lo.x() + piece_hi.x() > 2.0 * (i0 + ci) + 1.0;
          const bool flip_v = piece_lo.y() + piece_hi.y() > 2.0 * (j0 + cj) + 1.0;
          for (int k = 0; k < m; ++k)
            piece[k] = Vec2(flip_u ? i0 + ci + 1 - cell[k].x() : cell[k].x() - (i0 + ci),
                            flip_v ? j0 + cj + 1 - cell[k].y() : cell[k].y() - (j0 + cj));
          PolygonMoments q = polygon_moments<false>(piece, m);
          if (flip_u != flip_v) {  // one reflection turns the vertices clockwise
            q.area = -q.area, q.u = -q.u, q.v = -q.v, q.uv = -q.uv;
          }
          // Node (a', b') of the reflected cell is node (a' xor flip_u, b' xor flip_v),
          // and d/du = -d/du' where u is reflected.
          const int n00 = (flip_v ? k01 : k00) + (flip_u ? 1 : 0), n10 = n00 + (flip_u ? -1 : 1),
                    n01 = n00 + (flip_v ? -block : block), n11 = n01 + (flip_u ? -1 : 1);
          const double su = flip_u ? -1.0 : 1.0, sv = flip_v ? -1.0 : 1.0;
          area += q.area;
          // Integrals of non-negative functions; a sliver's may round to -1e-17.
          mass[n00] += std::max(0.0, q.area - q.u - q.v + q.uv);
          mass[n10] += std::max(0.0, q.u - q.uv);
          mass[n01] += std::max(0.0, q.v - q.uv);
          mass[n11] += std::max(0.0, q.uv);
          grad[n00] += Vec2(-su * (q.area - q.v), -sv * (q.area - q.u));
          grad[n10] += Vec2(su * (q.area - q.v), -sv * q.u);
          grad[n01] += Vec2(-su * q.v, sv * (q.area - q.u));
          grad[n11] += Vec2(su * q.v, sv * q.u);
        } else {
          // In r-z the moments are about the cell's lower-left corner (non-negative
          // integrals; a sliver's may round to -1e-17).
          for (int k = 0; k < m; ++k) piece[k] = cell[k] - Vec2(i0 + ci, j0 + cj);
          const PolygonMoments q = polygon_moments<radial>(piece, m);
          mass[k00] += std::max(0.0, q.area - q.u - q.v + q.uv);
          mass[k10] += std::max(0.0, q.u - q.uv);
          mass[k01] += std::max(0.0, q.v - q.uv);
          mass[k11] += std::max(0.0, q.uv);
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
};

using CpdiExactShape = CpdiExactShapeT<Geometry::plane_strain>;

}  // namespace mpmvv
