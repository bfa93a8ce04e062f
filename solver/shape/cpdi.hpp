// CPDI (002_c3305cb8b1bc1490.txt section 1.6.4, eqs. 1.94-1.100, in 2D): the
// grid basis read at the four corners of each particle's domain and
// interpolated bilinearly between them (eq. 1.95), with the corner factors
// of cpdi_domain.hpp, which has the formulas in plane strain and in r-z and
// for parallelogram and corner domains. This file lists each particle's
// nodes and their S_gp, G_gp (and <S/r> in r-z), one particle at a time
// (evaluate) or eight at a time (the lane kernel, cpdi_lanes.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "../particles.hpp"
#include "cpdi_domain.hpp"
#include "cpdi_lanes.hpp"
#include "linear.hpp"
#include "stencil.hpp"

namespace mpmvv {

template <Geometry G, CpdiForm Form = CpdiForm::convected>
struct CpdiShapeT : CpdiDomainT<G, Form> {
  using Domain = CpdiDomainT<G, Form>;
  using Domain::grid;
  using Domain::position;
  using Domain::deformation_gradient;
  using Domain::half_size;
  using Domain::domain_axes;
  using Domain::gradient_scale;
  using Domain::corners;
  using Domain::weight_skew;
  using Domain::shear_sign;
  using Domain::corner_xi;
  using Domain::corner_eta;
  using Domain::Turned;
  using Domain::Corners;
  using Domain::domain;
  using Domain::corner_gradients;
  using Domain::quadrilateral_factors;
  static constexpr int stencil_size = 16;  // four nodes for each of four corners, at most
  static constexpr const char* name = "cpdi";
  static constexpr Geometry geometry = G;
  static constexpr bool reads_deformation_gradient = true;
  static constexpr bool gradients_beyond_grid_basis = true;  // its corner interpolation (stages.hpp: stiffening)
  static constexpr bool has_domain = true;
  static constexpr bool turned_domains = Turned;  // the stepper turns sheared domains (domain_angle.hpp)
  static constexpr bool corner_domains = Corners;  // the stepper moves the corners (domain_corners.hpp)
  using GridBasis = LinearShapeT<G>;  // the corners read the hats

  // The domains span F_p diag(l_p); `deformation_gradient` may point to a copy
  // of F taken at the start of a step, so that every transfer of the step uses
  // the same domains. A shape whose `deformation_gradient` member is null
  // weighs the reference domains diag(l_p), F = I (the total Lagrangian
  // formulation sets it so, total_lagrangian.hpp).
  static CpdiShapeT bind(const GridGeometry& grid, const Particles& particles,
                         const Mat2* deformation_gradient = nullptr, double gradient_scale = 1.0) {
    return {{&grid, particles.position.data(),
             deformation_gradient ? deformation_gradient : particles.deformation_gradient.data(),
             particles.half_size.data(), Turned ? particles.domain_axes.data() : nullptr, gradient_scale,
             Corners ? particles.domain_corner.data() : nullptr}};
  }

  // The corners' shares of the node values: corner c passes S_g(x_c) to each
  // of the four nodes of its cell with the factors of S_gp, G_gp and <S/r>
  // (cpdi_domain.hpp). A domain within 2 x 2 cells (every domain up to a cell across,
  // which is all of them until shear stretches one) reaches at most the 3 x 3
  // nodes from its lowest corner cell: each is summed and listed once (4, 6 or
  // 9 entries instead of 16), which the transfers then visit once.
  //
  // Written on scalars rather than on 2-vectors: a vector assembled from two
  // scalars and read back whole stalls the load on its two halves' stores, and
  // those stalls were a third of this function's time. Every sum and product
  // is the one of the formulas of cpdi_domain.hpp, in the same order.
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
                                 wall_upper.x(), wall_upper.y(), for_scan,       shear_sign};
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
};

using CpdiShape = CpdiShapeT<Geometry::plane_strain>;

}  // namespace mpmvv
