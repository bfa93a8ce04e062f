// The lane kernel of cpdi_lanes.hpp (lane_vectors.hpp says how it is built).
// Each line is the scalar line of CpdiShapeT::evaluate it repeats.
#include "cpdi_lanes.hpp"

#include "../lane_vectors.hpp"
#include "lane_shared.hpp"  // kCornerXi, kCornerEta, kOctagonFactor

namespace mpmvv {

namespace {

using namespace lanes::MPMVV_LANE_BUILD_NS;

// FlipShear: the cpdi-shear-sign fault (faults.hpp), a kernel of its own so
// that a real run's kernel holds no trace of it (chosen once per batch list:
// cpdi_lane_stencils).
template <bool FlipShear>
struct CpdiKernel {
  using Grid = CpdiLaneGrid;
  using In = CpdiLaneInput;
  using Out = CpdiLaneStencils;

  template <int W>
  MPMVV_LANE_INLINE static void body(const CpdiLaneGrid& g, const CpdiLaneInput& in, CpdiLaneStencils& out, int l0);
};

// |G| <= max(|G_x|, |G_y|) + (sqrt 2 - 1) min(|G_x|, |G_y|), each lane
// (stencil.hpp: entry_gradient_sum_bound).
template <class Lanes>
MPMVV_LANE_INLINE Lanes octagon_length(const Lanes& gx, const Lanes& gy) {
  const Lanes ax = lane_abs(gx), ay = lane_abs(gy);
  return (ax > ay ? ax : ay) + kOctagonFactor * (ax > ay ? ay : ax);
}

// Lanes l0, ..., l0 + W - 1.
template <bool FlipShear>
template <int W>
void CpdiKernel<FlipShear>::body(const CpdiLaneGrid& g, const CpdiLaneInput& in, CpdiLaneStencils& out, int l0) {
  using Lanes = typename Width<W>::Lanes;
  using Mask = typename Width<W>::Mask;
  using Ints = typename Width<W>::Ints;
  const Lanes zero = {};
  Lanes position[2], F[4], half[2];
  load_interleaved(in.position + 2 * l0, position);
  load_interleaved(in.deformation_gradient + 4 * l0, F);
  load_interleaved(in.half_size + 2 * l0, half);
  const Lanes x = position[0], y = position[1];
  // s_p = F_p diag(l_p), column by column as CpdiShapeT::domain scales it.
  const Lanes s00 = F[0] * half[0], s10 = F[1] * half[0];
  const Lanes s01 = F[2] * half[1], s11 = F[3] * half[1];
  // s^-T = [[s11, -s10], [-s01, s00]] / det s (corner_gradients).
  const Lanes inv_det = g.gradient_scale / (s00 * s11 - s01 * s10);
  const Ints last_i = Ints{} + (g.cells_x - 1), last_j = Ints{} + (g.cells_y - 1);
  // (a local: read from g it was loaded again after every store to out,
  // which the compiler cannot tell apart from g)
  const bool for_scan = g.for_scan;
  if (for_scan) {
    // CpdiShapeT::inside: the centre between the walls (inside_walls) and
    // the corners' bounding box in grid coordinates in [0, cells] along both
    // axes (inside_cells); NaN fails.
    const Mask centre = (x >= g.wall_lower_x) & (x <= g.wall_upper_x) & (y >= g.wall_lower_y) & (y <= g.wall_upper_y);
    const Lanes reach_x = lane_abs(s00) + lane_abs(s01);
    const Lanes reach_y = lane_abs(s10) + lane_abs(s11);
    const Lanes low_x = (x - reach_x - g.origin_x) / g.h, low_y = (y - reach_y - g.origin_y) / g.h;
    const Lanes high_x = (x + reach_x - g.origin_x) / g.h, high_y = (y + reach_y - g.origin_y) / g.h;
    const double cells_x = g.cells_x, cells_y = g.cells_y;
    const Mask inside = centre & (low_x >= 0.0) & (low_x <= cells_x) & (low_y >= 0.0) & (low_y <= cells_y) &
                        (high_x >= 0.0) & (high_x <= cells_x) & (high_y >= 0.0) & (high_y <= cells_y);
    store(out.inside + l0, to_ints<Ints>(inside));
  }

  Ints cell_i[4], cell_j[4];
  Lanes fx[4], fy[4], hx[4], hy[4], grad_x[4], grad_y[4];  // hx = 1 - fx, hy = 1 - fy
  double corner_weight[4];
  for (int c = 0; c < 4; ++c) {
    const double xi = kCornerXi[c], eta = kCornerEta[c];
    corner_weight[c] = 0.25 * (1.0 + g.weight_skew * xi);
    const double gxi = 0.25 * xi, geta = 0.25 * eta;
    // The cross terms' factors (their sign flipped by cpdi-shear-sign).
    const double cross_xi = FlipShear ? -gxi : gxi, cross_eta = FlipShear ? -geta : geta;
    grad_x[c] = inv_det * (s11 * gxi - s10 * cross_eta);
    grad_y[c] = inv_det * (s00 * geta - s01 * cross_xi);
    // The corner x_p + xi r_1 + eta r_2 in grid coordinates, its cell and
    // its place in the cell.
    const Lanes cx = (x + xi * s00 + eta * s01 - g.origin_x) / g.h;
    const Lanes cy = (y + xi * s10 + eta * s11 - g.origin_y) / g.h;
    cell_i[c] = lane_min(__builtin_convertvector(cx, Ints), last_i);
    cell_j[c] = lane_min(__builtin_convertvector(cy, Ints), last_j);
    fx[c] = cx - to_doubles<Lanes>(cell_i[c]);
    fy[c] = cy - to_doubles<Lanes>(cell_j[c]);
    hx[c] = 1.0 - fx[c];
    hy[c] = 1.0 - fy[c];
  }
  const Ints i0 = lane_min(lane_min(cell_i[0], cell_i[1]), lane_min(cell_i[2], cell_i[3]));
  const Ints j0 = lane_min(lane_min(cell_j[0], cell_j[1]), lane_min(cell_j[2], cell_j[3]));
  store(out.i0 + l0, i0);
  store(out.j0 + l0, j0);
  const Ints span_i = lane_max(lane_max(cell_i[0], cell_i[1]), lane_max(cell_i[2], cell_i[3])) - i0;
  const Ints span_j = lane_max(lane_max(cell_j[0], cell_j[1]), lane_max(cell_j[2], cell_j[3])) - j0;
  store(out.span_i + l0, span_i);
  store(out.span_j + l0, span_j);
  const Ints narrow = (span_i <= 1) & (span_j <= 1);
  const Ints by_corners = Ints{} + kByCorners, no_block = Ints{} + kNoBlock;
  store(out.block_first + l0, (i0 >= 0) & (j0 >= 0) ? (narrow ? i0 + j0 * g.nodes_x : by_corners) : no_block);

  const Ints wide = ~narrow;
  bool any_narrow = false, any_wide = false;
  for (int l = 0; l < W; ++l) {
    any_narrow |= narrow[l] != 0;
    any_wide |= wide[l] != 0;
  }
  Lanes bound = zero;
  if (any_narrow) {
    // Corner c's hat factors along x at the nodes i0, i0 + 1, i0 + 2: in its
    // own cell (offset 0 or 1 from i0) 1 - fx and fx, elsewhere 0; the same
    // along y. Their products are evaluate's bilinear weights b_k.
    Lanes along_x[4][3], along_y[4][3];
    for (int c = 0; c < 4; ++c) {
      const Mask first_x = to_doubles<Lanes>(cell_i[c] - i0) == zero;
      const Mask first_y = to_doubles<Lanes>(cell_j[c] - j0) == zero;
      along_x[c][0] = first_x ? hx[c] : zero;
      along_x[c][1] = first_x ? fx[c] : hx[c];
      along_x[c][2] = first_x ? zero : fx[c];
      along_y[c][0] = first_y ? hy[c] : zero;
      along_y[c][1] = first_y ? fy[c] : hy[c];
      along_y[c][2] = first_y ? zero : fy[c];
    }
    // The bound of stencil.hpp's entry_gradient_sum_bound over the nine.
    for (int b = 0; b < 3; ++b)
      for (int a = 0; a < 3; ++a) {
        Lanes w = zero, gsx = zero, gsy = zero;
        for (int c = 0; c < 4; ++c) {
          const Lanes share = along_x[c][a] * along_y[c][b];
          w += corner_weight[c] * share;
          gsx += grad_x[c] * share;
          gsy += grad_y[c] * share;
        }
        store(out.weight[a + 3 * b] + l0, w);
        store(out.gradient_x[a + 3 * b] + l0, gsx);
        store(out.gradient_y[a + 3 * b] + l0, gsy);
        if (for_scan) bound += octagon_length(gsx, gsy);
      }
  } else {
    // Every lane wide: no transfer reads these slots of the group's lanes,
    // zeros keep them defined for one at another width (the tests').
    for (int slot = 0; slot < 9; ++slot) {
      store(out.weight[slot] + l0, zero);
      store(out.gradient_x[slot] + l0, zero);
      store(out.gradient_y[slot] + l0, zero);
    }
  }
  if (any_wide) {
    // evaluate's wide branch: corner c's bilinear weights b_k at the four
    // nodes of its cell, times its factors.
    for (int c = 0; c < 4; ++c) {
      const Lanes b[4] = {hx[c] * hy[c], fx[c] * hy[c], hx[c] * fy[c], fx[c] * fy[c]};
      for (int k = 0; k < 4; ++k) {
        store(out.wide_weight[4 * c + k] + l0, corner_weight[c] * b[k]);
        store(out.wide_gradient_x[4 * c + k] + l0, grad_x[c] * b[k]);
        store(out.wide_gradient_y[4 * c + k] + l0, grad_y[c] * b[k]);
      }
      store(out.corner_first[c] + l0, cell_i[c] + cell_j[c] * g.nodes_x);  // GridGeometry::node
    }
  }
  if (any_wide && for_scan) {
    const Ints within = (span_i <= 2) & (span_j <= 2);
    const Ints wide_within = wide & within, beyond = wide & ~within;
    bool any_within = false, any_beyond = false;
    for (int l = 0; l < W; ++l) {
      any_within |= wide_within[l] != 0;
      any_beyond |= beyond[l] != 0;
    }
    Lanes wide_bound = zero;
    if (any_within) {
      // The bound over the 4 x 4 nodes from (i0, j0), as above: corner c's
      // hat factors are 1 - f at its cell's offset from i0 and f at the next.
      Lanes wide_x[4][4], wide_y[4][4];
      for (int c = 0; c < 4; ++c) {
        const Lanes off_x = to_doubles<Lanes>(cell_i[c] - i0);
        const Lanes off_y = to_doubles<Lanes>(cell_j[c] - j0);
        for (int a = 0; a < 4; ++a) {
          wide_x[c][a] = off_x == double(a) ? hx[c] : (off_x == double(a - 1) ? fx[c] : zero);
          wide_y[c][a] = off_y == double(a) ? hy[c] : (off_y == double(a - 1) ? fy[c] : zero);
        }
      }
      for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 4; ++a) {
          Lanes gsx = zero, gsy = zero;
          for (int c = 0; c < 4; ++c) {
            const Lanes share = wide_x[c][a] * wide_y[c][b];
            gsx += grad_x[c] * share;
            gsy += grad_y[c] * share;
          }
          wide_bound += octagon_length(gsx, gsy);
        }
    }
    Lanes entry_bound = zero;
    if (any_beyond) {
      // Corners past 4 x 4 nodes: the bound over the sixteen entries as
      // listed (stencil.hpp: entry_gradient_sum_bound, the same sum in the
      // same order), which the scan would otherwise form from the listed
      // stencil (callgrind, A = 1, t = 0.40-0.42 s: 78 instructions a
      // particle-step, besides the listing).
      for (int c = 0; c < 4; ++c) {
        const Lanes b[4] = {hx[c] * hy[c], fx[c] * hy[c], hx[c] * fy[c], fx[c] * fy[c]};
        for (int k = 0; k < 4; ++k) entry_bound += octagon_length(grad_x[c] * b[k], grad_y[c] * b[k]);
      }
    }
    bound = to_mask<Mask>(wide) ? (to_mask<Mask>(within) ? wide_bound : entry_bound) : bound;
  }
  store(out.gradient_bound + l0, for_scan ? bound : zero - 1.0);
}

}  // namespace

namespace lanes::MPMVV_LANE_BUILD_NS {
void cpdi_lane_stencils(const CpdiLaneGrid& grid, const CpdiLaneInput& in, CpdiLaneStencils& out) {
  if (grid.shear_sign < 0.0) run<CpdiKernel<true>>(grid, in, out);
  else run<CpdiKernel<false>>(grid, in, out);
}
}  // namespace lanes::MPMVV_LANE_BUILD_NS

#if defined(MPMVV_LANE_DISPATCH)
MPMVV_LANE_DISPATCH_OF(cpdi_lane_stencils, (const CpdiLaneGrid& grid, const CpdiLaneInput& in, CpdiLaneStencils& out),
                       (grid, in, out))
#endif

}  // namespace mpmvv
