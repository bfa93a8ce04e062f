// The lane kernel of gimp_lanes.hpp (lane_vectors.hpp says how it is built).
// Each line is the scalar line of gimp.hpp it repeats.
#include "gimp_lanes.hpp"

#include "../lane_vectors.hpp"

namespace mpmvv {

namespace {

using namespace lanes::MPMVV_LANE_BUILD_NS;

// gimp_weight_1d of each lane. Every piece of it is w = c + a / q and
// dw = b / r (1 - x / h as 1 + (-x) / h, the same number), so each lane picks
// its piece's c, a, q, b and r (the last piece first, then each earlier one
// where its test holds: the first test that holds decides, as in the scalar
// chain of ifs) and two divisions serve every piece: the scalar operations,
// so the same bits, for a quarter of the divisions.
template <class Lanes, class Mask>
MPMVV_LANE_INLINE void gimp_1d(const Lanes& d, double h, const Lanes& l, Lanes& w, Lanes& dw) {
  const Lanes zero = {}, one = zero + 1.0, h_lanes = zero + h;
  const Lanes hl = h * l, two_hl = 2.0 * h * l, four_hl = 4.0 * h * l;
  Lanes s = h + l - d;
  Lanes c = zero, a = s * s, q = four_hl, b = -s, r = two_hl;
  auto pick = [&](const Mask& m, const Lanes& c_m, const Lanes& a_m, const Lanes& q_m, const Lanes& b_m,
                  const Lanes& r_m) {
    c = m ? c_m : c;
    a = m ? a_m : a;
    q = m ? q_m : q;
    b = m ? b_m : b;
    r = m ? r_m : r;
  };
  pick(d <= h - l, one, -d, h_lanes, zero - 1.0, h_lanes);
  pick(d <= l, one, -(d * d + l * l), two_hl, -d, hl);
  pick(d <= -l, one, d, h_lanes, one, h_lanes);
  s = h + l + d;
  pick(d <= -h + l, zero, s * s, four_hl, s, two_hl);
  const Mask outside = (d <= -h - l) | (d > h + l);
  w = outside ? zero : c + a / q;
  dw = outside ? zero : b / r;
}

// Scaled: the gimp-gradient fault (faults.hpp), a kernel of its own so that
// a real run's kernel holds no trace of it (chosen once per batch list:
// gimp_lane_stencils).
template <bool Scaled>
struct GimpKernel {
  using Grid = GimpLaneGrid;
  using In = GimpLaneInput;
  using Out = GimpLaneStencils;

  template <int W>
  MPMVV_LANE_INLINE static void body(const GimpLaneGrid& g, const GimpLaneInput& in, GimpLaneStencils& out, int l0);
};

// Lanes l0, ..., l0 + W - 1.
template <bool Scaled>
template <int W>
void GimpKernel<Scaled>::body(const GimpLaneGrid& g, const GimpLaneInput& in, GimpLaneStencils& out, int l0) {
  using Lanes = typename Width<W>::Lanes;
  using Mask = typename Width<W>::Mask;
  using Ints = typename Width<W>::Ints;
  const Lanes zero = {};
  const Ints none = {};
  Lanes position[2], half[2];
  load_interleaved(in.position + 2 * l0, position);
  load_interleaved(in.half_size + 2 * l0, half);
  const Lanes x = position[0], y = position[1], lx = half[0], ly = half[1];
  // inside: the centre between the walls and the domain in the grid; NaN fails.
  const Mask inside = (x >= g.wall_lower_x) & (x <= g.wall_upper_x) & (y >= g.wall_lower_y) &
                      (y <= g.wall_upper_y) & (x - lx >= g.origin_x) & (y - ly >= g.origin_y) &
                      (x + lx <= g.upper_x) & (y + ly <= g.upper_y);
  store(out.inside + l0, to_ints<Ints>(inside));
  const Lanes xi_x = (x - g.origin_x) / g.h, xi_y = (y - g.origin_y) / g.h;  // grid_coordinate
  // floor(xi + 0.5) - 1: truncation, less one where it rounded up.
  auto floor_int = [](const Lanes& v) {
    const Ints t = __builtin_convertvector(v, Ints);
    return t + to_ints<Ints>(to_doubles<Lanes>(t) > v);
  };
  const Ints i0 = floor_int(xi_x + 0.5) - 1, j0 = floor_int(xi_y + 0.5) - 1;
  const Ints last_i = none + g.cells_x, last_j = none + g.cells_y;
  Lanes wx[3], dx[3], wy[3], dy[3];
  Ints node_i[3], node_j[3];
  const double gradient_scale = Scaled ? g.gradient_scale : 1.0;  // a local: g is read again after every store
  for (int a = 0; a < 3; ++a) {
    const Ints i = i0 + a, j = j0 + a;
    const Mask in_x = to_mask<Mask>((i >= none) & (i <= last_i));
    const Mask in_y = to_mask<Mask>((j >= none) & (j <= last_j));
    node_i[a] = lane_min(lane_max(i, none), last_i);
    node_j[a] = lane_min(lane_max(j, none), last_j);
    store(out.node_i[a] + l0, node_i[a]);
    store(out.node_j[a] + l0, node_j[a]);
    const Lanes node_x = g.origin_x + to_doubles<Lanes>(i) * g.h;
    Lanes w, dw;
    gimp_1d<Lanes, Mask>(x - node_x, g.h, lx, w, dw);
    wx[a] = in_x ? w : zero;
    dx[a] = in_x ? (Scaled ? gradient_scale * dw : dw) : zero;
    gimp_1d<Lanes, Mask>((xi_y - to_doubles<Lanes>(j)) * g.h, g.h, ly, w, dw);
    wy[a] = in_y ? w : zero;
    dy[a] = in_y ? (Scaled ? gradient_scale * dw : dw) : zero;
  }
  const Ints block = (node_i[2] == node_i[0] + 2) & (node_j[2] == node_j[0] + 2);
  store(out.block_first + l0, block ? node_i[0] + node_j[0] * g.nodes_x : none - 1);
  for (int b = 0; b < 3; ++b)
    for (int a = 0; a < 3; ++a) {
      store(out.weight[a + 3 * b] + l0, wx[a] * wy[b]);
      store(out.gradient_x[a + 3 * b] + l0, dx[a] * wy[b]);
      store(out.gradient_y[a + 3 * b] + l0, wx[a] * dy[b]);
    }
}

}  // namespace

namespace lanes::MPMVV_LANE_BUILD_NS {
void gimp_lane_stencils(const GimpLaneGrid& grid, const GimpLaneInput& in, GimpLaneStencils& out) {
  if (grid.gradient_scale != 1.0) run<GimpKernel<true>>(grid, in, out);
  else run<GimpKernel<false>>(grid, in, out);
}
}  // namespace lanes::MPMVV_LANE_BUILD_NS

#if defined(MPMVV_LANE_DISPATCH)
MPMVV_LANE_DISPATCH_OF(gimp_lane_stencils, (const GimpLaneGrid& grid, const GimpLaneInput& in, GimpLaneStencils& out),
                       (grid, in, out))
#endif

}  // namespace mpmvv
