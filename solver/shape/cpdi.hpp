// CPDI with parallelogram particle domains (002_c3305cb8b1bc1490.txt section
// 1.6.4, eqs. 1.94-1.100, in 2D). The domain of particle p is spanned by
// r_1 = F_p (l_x e_x) and r_2 = F_p (l_y e_y) about its centroid (eq. 1.97),
// or by the columns of F_p A_p once its domain has been turned (domain_angle.hpp);
// the grid basis is interpolated bilinearly from its four corners (eq. 1.95),
// which gives
//   S_gp = (1/4) sum_c S_g(x_c),
//   G_gp = (1/4) s_p^-T sum_c (xi_c, eta_c)^T S_g(x_c),   s_p = [r_1 r_2],
// the 2D form of eq. 1.100 (the mean over the square of dN_c/dxi is xi_c / 4).
//
// In r-z the averages carry the weight r = r_p + a xi + b eta over the domain
// (a, b the radial components of r_1, r_2); integrating the corner functions
// exactly:
//   S_gp  = sum_c (1/4)(1 + (a xi_c + b eta_c) / (3 r_p)) S_g(x_c),
//   G_gp  = s_p^-T sum_c ((xi_c/4)(1 + b eta_c / (3 r_p)), (eta_c/4)(1 + a xi_c / (3 r_p))) S_g(x_c),
//   <S/r> = (1 / (4 r_p)) sum_c S_g(x_c).
//
// With corner domains (domain_corners.hpp, plane strain) the domain is the
// quadrilateral of its four corners x_c, x = a_0 + a_1 xi + a_2 eta + a_3 xi eta,
// whose Jacobian is det J = J0 + J1 xi + J2 eta (J0 = a_1 x a_2,
// J1 = a_1 x a_3, J2 = a_3 x a_2) and area 4 J0. The bilinear corner function
// phi_c integrates over it to J0 + (J1 xi_c + J2 eta_c) / 3 and its gradient
// to (1/2) rot(x_{c+1} - x_{c-1}), rot(a) = (a_y, -a_x) (the divergence
// theorem over the corner's two edges), which gives
//   S_gp = sum_c (1/4)(1 + (J1 xi_c + J2 eta_c) / (3 J0)) S_g(x_c),
//   G_gp = (1 / (8 J0)) sum_c rot(x_{c+1} - x_{c-1}) S_g(x_c);
// for a parallelogram (a_3 = 0) these are the two lines above.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "../domain_corners.hpp"
#include "../particles.hpp"
#include "cpdi_lanes.hpp"
#include "linear.hpp"
#include "stencil.hpp"

namespace mpmvv {

// The domain's form, chosen once per run, not once per particle:
enum class CpdiForm {
  convected,  // F_p diag(l_p)
  turned,     // F_p A_p (Particles::domain_axes), held open under shear (domain_angle.hpp)
  corners,    // the quadrilateral of Particles::domain_corner (domain_corners.hpp)
};

template <Geometry G, CpdiForm Form = CpdiForm::convected>
struct CpdiShapeT {
  static constexpr bool Turned = Form == CpdiForm::turned;
  static constexpr bool Corners = Form == CpdiForm::corners;
  static_assert(!Corners || G == Geometry::plane_strain, "corner domains are plane strain only");
  static constexpr int stencil_size = 16;  // four nodes for each of four corners, at most
  static constexpr const char* name = "cpdi";
  static constexpr Geometry geometry = G;
  static constexpr bool reads_deformation_gradient = true;
  static constexpr bool gradients_beyond_grid_basis = true;  // its corner interpolation (stages.hpp: stiffening)
  static constexpr bool has_domain = true;
  static constexpr bool turned_domains = Turned;  // the stepper turns sheared domains (domain_angle.hpp)
  static constexpr bool corner_domains = Corners;  // the stepper moves the corners (domain_corners.hpp)
  using GridBasis = LinearShapeT<G>;  // the corners read the hats

  // Natural coordinates of the corners, counter-clockwise (eq. 1.99 in 2D).
  static constexpr const double (&corner_xi)[4] = kCornerXi;
  static constexpr const double (&corner_eta)[4] = kCornerEta;

  const GridGeometry* grid;
  const Vec2* position;
  const Mat2* deformation_gradient;
  const Vec2* half_size;
  const Mat2* domain_axes;  // Turned: A_p; else null, and the domains span diag(half_size)
  double gradient_scale;  // 1, but for a deliberate fault (faults.hpp: cpdi-gradient)
  const Vec2* corners;    // Corners: x_pc, four per particle (Particles::domain_corner); else null
  // 0, but for a deliberate fault (faults.hpp: cpdi-weight): the corner
  // shares of S_gp are (1/4)(1 + weight_skew xi_c). Parallelogram domains only.
  double weight_skew = 0.0;

  // The domains span F_p diag(l_p); `deformation_gradient` may point to a copy
  // of F taken at the start of a step, so that every transfer of the step uses
  // the same domains. A shape whose `deformation_gradient` member is null
  // weighs the reference domains diag(l_p), F = I (the total Lagrangian
  // formulation sets it so, total_lagrangian.hpp).
  static CpdiShapeT bind(const GridGeometry& grid, const Particles& particles,
                         const Mat2* deformation_gradient = nullptr, double gradient_scale = 1.0) {
    return {&grid, particles.position.data(),
            deformation_gradient ? deformation_gradient : particles.deformation_gradient.data(),
            particles.half_size.data(),
            Turned ? particles.domain_axes.data() : nullptr, gradient_scale,
            Corners ? particles.domain_corner.data() : nullptr};
  }

  // s_p = [r_1 r_2], the current domain half-vectors as columns (eq. 1.97);
  // for corner domains the linear part [a_1 a_2] of their map.
  Mat2 domain(std::size_t p) const {
    if constexpr (Corners) return corner_half_vectors(corners + 4 * p);
    Mat2 s = deformation_gradient ? deformation_gradient[p] : Mat2::Identity();
    if constexpr (Turned) {
      return s * domain_axes[p];
    } else {
      s.col(0) *= half_size[p].x();
      s.col(1) *= half_size[p].y();
      return s;
    }
  }

  Vec2 corner(std::size_t p, const Mat2& s, int c) const {
    if constexpr (Corners) return corners[4 * p + c];
    return position[p] + corner_xi[c] * s.col(0) + corner_eta[c] * s.col(1);
  }

  // Corner domains: the corner factors of S_gp and G_gp (above), given the
  // quadrilateral's linear part s = domain(p), which every caller has formed.
  void quadrilateral_factors(std::size_t p, const Mat2& s, double* weight, double* gradient_x,
                             double* gradient_y) const {
    const Vec2* x = corners + 4 * p;
    const double a3x = 0.25 * (x[0].x() - x[1].x() + x[2].x() - x[3].x());
    const double a3y = 0.25 * (x[0].y() - x[1].y() + x[2].y() - x[3].y());
    const double J0 = determinant(s);
    const double J1 = s(0, 0) * a3y - s(1, 0) * a3x;
    const double J2 = a3x * s(1, 1) - a3y * s(0, 1);
    const double inv = gradient_scale / (8.0 * J0);
    for (int c = 0; c < 4; ++c) {
      weight[c] = 0.25 * (1.0 + (J1 * corner_xi[c] + J2 * corner_eta[c]) / (3.0 * J0));
      const Vec2& next = x[(c + 1) % 4];
      const Vec2& previous = x[(c + 3) % 4];
      gradient_x[c] = inv * (next.y() - previous.y());
      gradient_y[c] = inv * -(next.x() - previous.x());
    }
  }

  // The corner factors of G_gp = sum_c S_g(x_c) g_c (above, with the r-z
  // weights), for the corners in the order of corner_xi, corner_eta.
  // Scalars, x and y apart (evaluate, below, says why).
  void corner_gradients(std::size_t p, const Mat2& s, double* gx, double* gy) const {
    if constexpr (Corners) {
      double w[4];
      quadrilateral_factors(p, s, w, gx, gy);
      return;
    }
    // s^-T = [[s11, -s10], [-s01, s00]] / det s.
    const double inv_det = gradient_scale / determinant(s);
    double weight_a = 0.0, weight_b = 0.0;
    if constexpr (G == Geometry::axisymmetric) {
      const double weight_r = 1.0 / (3.0 * position[p].x());
      weight_a = s(0, 0) * weight_r;
      weight_b = s(0, 1) * weight_r;
    }
    for (int c = 0; c < 4; ++c) {
      const double xi = corner_xi[c], eta = corner_eta[c];
      double gxi = 0.25 * xi, geta = 0.25 * eta;
      if constexpr (G == Geometry::axisymmetric) {
        gxi *= 1.0 + weight_b * eta;
        geta *= 1.0 + weight_a * xi;
      }
      gx[c] = inv_det * (s(1, 1) * gxi - s(1, 0) * geta);
      gy[c] = inv_det * (s(0, 0) * geta - s(0, 1) * gxi);
    }
  }

  // An upper bound of sum_g |G_gp| without the grid: the factors g_c sum to
  // zero, so G_gp = sum_c (S_g(x_c) - S_g(x_p)) g_c, and over the nodes
  // sum_g |S_g(a) - S_g(b)| is at most 2 (|a_x - b_x| + |a_y - b_y|) / h
  // (the bilinear hats, each a product of 1D hats of slope 1 / h) and at
  // most 2 (two partitions of unity). Any point serves as b: the domain's
  // centre (x_p, or a_0 for corner domains).
  double gradient_sum_bound(std::size_t p) const {
    const Mat2 s = domain(p);
    double gx[4], gy[4];
    corner_gradients(p, s, gx, gy);
    Vec2 centre = Vec2::Zero();
    if constexpr (Corners) centre = 0.25 * (corners[4 * p] + corners[4 * p + 1] + corners[4 * p + 2] + corners[4 * p + 3]);
    double bound = 0.0;
    for (int c = 0; c < 4; ++c) {
      Vec2 offset;
      if constexpr (Corners) offset = corners[4 * p + c] - centre;
      else offset = corner_xi[c] * s.col(0) + corner_eta[c] * s.col(1);
      bound += std::sqrt(gx[c] * gx[c] + gy[c] * gy[c]) * std::min(2.0, 2.0 * offset.cwiseAbs().sum() / grid->h);
    }
    return bound;
  }

  // The corners' shares of the node values: corner c passes S_g(x_c) to each
  // of the four nodes of its cell with the factors of S_gp, G_gp and <S/r>
  // above. A domain within 2 x 2 cells (every domain up to a cell across,
  // which is all of them until shear stretches one) reaches at most the 3 x 3
  // nodes from its lowest corner cell: each is summed and listed once (4, 6 or
  // 9 entries instead of 16), which the transfers then visit once.
  //
  // Written on scalars rather than on 2-vectors: a vector assembled from two
  // scalars and read back whole stalls the load on its two halves' stores, and
  // those stalls were a third of this function's time. Every sum and product
  // is the one of the formulas above, in the same order.
  void evaluate(std::size_t p, Stencil<stencil_size>& st) const {
    const GridGeometry& g = *grid;
    const Mat2 s = domain(p);
    double weight_r = 0.0, weight_a = 0.0, weight_b = 0.0;
    if constexpr (G == Geometry::axisymmetric) {
      weight_r = 1.0 / (3.0 * position[p].x());
      weight_a = s(0, 0) * weight_r;
      weight_b = s(0, 1) * weight_r;
    }
    const double hoop_factor = 0.75 * weight_r;  // <S/r> = (1 / (4 r_p)) sum_c S_g(x_c)
    int cell_i[4], cell_j[4];
    double fx[4], fy[4], corner_weight[4], grad_x[4], grad_y[4];
    if constexpr (Corners) quadrilateral_factors(p, s, corner_weight, grad_x, grad_y);
    else corner_gradients(p, s, grad_x, grad_y);
    const double px = position[p].x(), py = position[p].y();
    const double s00 = s(0, 0), s01 = s(0, 1), s10 = s(1, 0), s11 = s(1, 1);
    const double ox = g.origin.x(), oy = g.origin.y(), h = g.h;
    for (int c = 0; c < 4; ++c) {
      if constexpr (!Corners) {
        double cw = 0.25 * (1.0 + weight_skew * corner_xi[c]);
        if constexpr (G == Geometry::axisymmetric) cw *= 1.0 + weight_a * corner_xi[c] + weight_b * corner_eta[c];
        corner_weight[c] = cw;
      }
      double x, y;  // corner(p, s, c)
      if constexpr (Corners) {
        x = corners[4 * p + c].x();
        y = corners[4 * p + c].y();
      } else {
        x = px + corner_xi[c] * s00 + corner_eta[c] * s01;
        y = py + corner_xi[c] * s10 + corner_eta[c] * s11;
      }
      x = (x - ox) / h;  // grid_coordinate
      y = (y - oy) / h;
      cell_i[c] = cell_index(x, g.cells_x);
      cell_j[c] = cell_index(y, g.cells_y);
      fx[c] = x - cell_i[c];
      fy[c] = y - cell_j[c];
    }
    const int i0 = std::min(std::min(cell_i[0], cell_i[1]), std::min(cell_i[2], cell_i[3]));
    const int j0 = std::min(std::min(cell_j[0], cell_j[1]), std::min(cell_j[2], cell_j[3]));
    const int span_i = std::max(std::max(cell_i[0], cell_i[1]), std::max(cell_i[2], cell_i[3])) - i0;
    const int span_j = std::max(std::max(cell_j[0], cell_j[1]), std::max(cell_j[2], cell_j[3])) - j0;
    // S_g(x_c) of the four nodes of corner c's cell, in node order (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1).
    auto bilinear = [&](int c, double* b) {
      const double gx = 1.0 - fx[c], gy = 1.0 - fy[c];
      b[0] = gx * gy;
      b[1] = fx[c] * gy;
      b[2] = gx * fy[c];
      b[3] = fx[c] * fy[c];
    };
    if (span_i > 1 || span_j > 1) {
      // A domain stretched beyond 2 x 2 cells: four entries per corner.
      for (int c = 0; c < 4; ++c) {
        double b[4];
        bilinear(c, b);
        const int n00 = g.node(cell_i[c], cell_j[c]);
        const int nodes[4] = {n00, n00 + 1, n00 + g.nodes_x(), n00 + g.nodes_x() + 1};
        for (int k = 0; k < 4; ++k) {
          st.node[4 * c + k] = nodes[k];
          st.weight[4 * c + k] = corner_weight[c] * b[k];
          st.gradient[4 * c + k] = Vec2(grad_x[c] * b[k], grad_y[c] * b[k]);
          if constexpr (G == Geometry::axisymmetric) st.hoop[4 * c + k] = hoop_factor * b[k];
        }
      }
      st.count = stencil_size;
      return;
    }
    // Node (i0 + a, j0 + b) sums into slot a + 3 b.
    double w[9] = {}, hoop[9] = {}, gsx[9] = {}, gsy[9] = {};
    for (int c = 0; c < 4; ++c) {
      double b[4];
      bilinear(c, b);
      const int first = (cell_i[c] - i0) + 3 * (cell_j[c] - j0);
      const int slot[4] = {first, first + 1, first + 3, first + 4};
      for (int k = 0; k < 4; ++k) {
        w[slot[k]] += corner_weight[c] * b[k];
        gsx[slot[k]] += grad_x[c] * b[k];
        gsy[slot[k]] += grad_y[c] * b[k];
        if constexpr (G == Geometry::axisymmetric) hoop[slot[k]] += hoop_factor * b[k];
      }
    }
    int n = 0;
    for (int b = 0; b <= span_j + 1; ++b)
      for (int a = 0; a <= span_i + 1; ++a, ++n) {
        const int slot = a + 3 * b;
        st.node[n] = g.node(i0 + a, j0 + b);
        st.weight[n] = w[slot];
        st.gradient[n] = Vec2(gsx[slot], gsy[slot]);
        if constexpr (G == Geometry::axisymmetric) st.hoop[n] = hoop[slot];
      }
    st.count = n;
  }

  // Plane-strain parallelogram domains are evaluated eight particles at a
  // time by the lane kernel (cpdi_lanes.hpp), to the same bits as evaluate.
  static constexpr bool lanes = G == Geometry::plane_strain && !Corners;

  // Eight particles' stencils in two steps: compute_lanes runs the kernel on
  // particles first, ..., first + count - 1 (count at most kLanes), then
  // for_each_lane_entry gives lane l's entries as evaluate lists them, and
  // lane_gradient_bounds upper bounds of their sum_g |G_gp| (the time-step
  // scan's, negative where there is none; stages.hpp: signal_speed, and
  // list_lane for the entries as a stencil). In between, lane_inside is
  // `inside` of the lane's particle from the kernel's values, for the scan's
  // health test: a particle that fails it is not listed (its domain may
  // leave the grid). `for_scan` asks the kernel for what lane_inside and
  // lane_gradient_bounds need (the time-step scan), `build` for a build of
  // the kernel (tests; by default the widest the CPU has).
  using LaneBatch = LaneBatchOfStencils<CpdiLaneStencils>;

  void compute_lanes(std::size_t first, int count, LaneBatch& batch, bool for_scan = true,
                     const LaneBuild* build = nullptr) const
    requires lanes
  {
    const GridGeometry& g = *grid;
    CpdiLaneInput in;
    CpdiLaneCopy copy;
    if (count == kLanes && deformation_gradient && !Turned) {
      in = {values_of(position + first), values_of(deformation_gradient + first), values_of(half_size + first)};
    } else {
      for (int l = 0; l < kLanes; ++l) {
        const std::size_t p = copied_lane_particle(first, count, l);
        std::copy_n(values_of(position + p), 2, copy.position + 2 * l);
        const Mat2 s = domain(p);
        std::copy_n(values_of(&s), 4, copy.deformation_gradient + 4 * l);
        std::fill_n(copy.half_size + 2 * l, 2, 1.0);
      }
      in = {copy.position, copy.deformation_gradient, copy.half_size};
    }
    batch.first = first;
    const Vec2 wall_lower = g.wall_lower(), wall_upper = g.wall_upper();
    const CpdiLaneGrid lane_grid{g.origin.x(),   g.origin.y(),   g.h,
                                 g.cells_x,      g.cells_y,      g.nodes_x(),    gradient_scale,
                                 weight_skew,    wall_lower.x(), wall_lower.y(),
                                 wall_upper.x(), wall_upper.y(), for_scan};
    if (build) cpdi_lane_stencils(*build, lane_grid, in, batch.out);
    else cpdi_lane_stencils(lane_grid, in, batch.out);
  }

  bool lane_inside(const LaneBatch& batch, int l) const
    requires lanes
  {  // the batch computed for_scan
    return batch.out.inside[l] != 0;
  }

  // Lane l's entries as evaluate lists them, each passed to f(node, S_gp,
  // G_gp) in turn without a stencil between: a stencil written and read back
  // at once stalls on its stores.
  template <class F>
  void for_each_lane_entry(const LaneBatch& batch, int l, F&& f) const
    requires lanes
  {
    const CpdiLaneStencils& out = batch.out;
    const int row = grid->nodes_x();
    if (out.span_i[l] > 1 || out.span_j[l] > 1) {  // four entries per corner
      for (int c = 0; c < 4; ++c) {
        const int n00 = out.corner_first[c][l];
        const int nodes[4] = {n00, n00 + 1, n00 + row, n00 + row + 1};
        for (int k = 0; k < 4; ++k) {
          const int slot = 4 * c + k;
          f(nodes[k], out.wide_weight[slot][l], Vec2(out.wide_gradient_x[slot][l], out.wide_gradient_y[slot][l]));
        }
      }
      return;
    }
    const int first = grid->node(out.i0[l], out.j0[l]);
    for (int b = 0; b <= out.span_j[l] + 1; ++b)
      for (int a = 0; a <= out.span_i[l] + 1; ++a) {
        const int slot = a + 3 * b;
        f(first + a + b * row, out.weight[slot][l], Vec2(out.gradient_x[slot][l], out.gradient_y[slot][l]));
      }
  }

  // Where lane l's entries form a 3 x 3 block of nodes, slot a + 3 b at
  // node first + a + b nodes_x (scatter_lanes.hpp), its first node; for a
  // wide lane kByCorners (lanes.hpp: the blocks of its corners' cells), and
  // kNoBlock for nodes that start off the grid (its particle fails inside).
  // A stencil of two columns or rows has zeros in the third.
  std::ptrdiff_t lane_block_first(const LaneBatch& batch, int l) const
    requires lanes
  {
    return batch.out.block_first[l];
  }

  // The bounds of sum_g |G_gp| the kernel gives with the lanes' entries, the
  // eight lanes' back to back (the spare lanes' the first's).
  const double* lane_gradient_bounds(const LaneBatch& batch) const
    requires lanes
  {
    return batch.out.gradient_bound;
  }

  // A corner domain turned over, 4 det [a_1 a_2] <= 0 (monitors.hpp:
  // folded_domains). The factors above stay those of the signed integral over
  // the quadrilateral as it stands, finite while det [a_1 a_2] is not zero.
  bool folded(std::size_t p) const {
    if constexpr (Corners) return turned_over(corner_half_vectors(corners + 4 * p));
    return false;
  }

  // The centre lies between the walls (in r-z off the axis) and every corner
  // of the domain in the grid (ghost layers included).
  bool inside(std::size_t p) const {
    if constexpr (G == Geometry::axisymmetric)
      if (!(position[p].x() > 0.0)) return false;
    if (!inside_walls(*grid, position[p])) return false;
    if constexpr (Corners) {
      const Vec2* x = corners + 4 * p;
      const Vec2 low = x[0].cwiseMin(x[1]).cwiseMin(x[2].cwiseMin(x[3]));
      const Vec2 high = x[0].cwiseMax(x[1]).cwiseMax(x[2].cwiseMax(x[3]));
      return inside_cells(*grid, grid_coordinate(*grid, low)) && inside_cells(*grid, grid_coordinate(*grid, high));
    }
    // The corners x_p +- r_1 +- r_2 reach |r_1| + |r_2| along each axis: their
    // bounding box, without forming the four corners (the scan runs every step).
    const Vec2 reach = domain(p).cwiseAbs().rowwise().sum();
    return inside_cells(*grid, grid_coordinate(*grid, position[p] - reach)) &&
           inside_cells(*grid, grid_coordinate(*grid, position[p] + reach));
  }
};

using CpdiShape = CpdiShapeT<Geometry::plane_strain>;

}  // namespace mpmvv
