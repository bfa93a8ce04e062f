// The kernel of gather_lanes.hpp (lane_vectors.hpp says how it is built).
// Each sum is the line of grid_to_particles' update it repeats: Eigen's Vec2
// and Mat2 sums there are these sums entry by entry.
#include "gather_lanes.hpp"

#include "lane_vectors.hpp"

namespace mpmvv {

namespace {

using namespace lanes::MPMVV_LANE_BUILD_NS;

// The four values of lane l's node at[l] as four vectors over the lanes:
// a_x, a_y, v_x, v_y.
template <int W>
MPMVV_LANE_INLINE void node_motion(const double* motion, const long long* at, typename Width<W>::Lanes (&m)[4]) {
  using Lanes = typename Width<W>::Lanes;
  using Index = typename Width<W>::Mask;
  if constexpr (W == 4) {
    // One load a lane, then a 4 x 4 transpose (store_interleaved's, reversed).
    Lanes r[4];
    for (int l = 0; l < 4; ++l) r[l] = load<Lanes>(motion + 4 * at[l]);
    const Lanes t0 = __builtin_shuffle(r[0], r[1], Index{0, 4, 2, 6});  // ax0 ax1 vx0 vx1
    const Lanes t1 = __builtin_shuffle(r[0], r[1], Index{1, 5, 3, 7});  // ay0 ay1 vy0 vy1
    const Lanes t2 = __builtin_shuffle(r[2], r[3], Index{0, 4, 2, 6});
    const Lanes t3 = __builtin_shuffle(r[2], r[3], Index{1, 5, 3, 7});
    m[0] = __builtin_shuffle(t0, t2, Index{0, 1, 4, 5});
    m[1] = __builtin_shuffle(t1, t3, Index{0, 1, 4, 5});
    m[2] = __builtin_shuffle(t0, t2, Index{2, 3, 6, 7});
    m[3] = __builtin_shuffle(t1, t3, Index{2, 3, 6, 7});
  } else if constexpr (W == 2) {
    // A node's acceleration, then its velocity, each one load.
    const double* n0 = motion + 4 * at[0];
    const double* n1 = motion + 4 * at[1];
    const Lanes a0 = load<Lanes>(n0), a1 = load<Lanes>(n1), v0 = load<Lanes>(n0 + 2), v1 = load<Lanes>(n1 + 2);
    m[0] = __builtin_shuffle(a0, a1, Index{0, 2});
    m[1] = __builtin_shuffle(a0, a1, Index{1, 3});
    m[2] = __builtin_shuffle(v0, v1, Index{0, 2});
    m[3] = __builtin_shuffle(v0, v1, Index{1, 3});
  } else {
    for (int c = 0; c < 4; ++c) {
      double value[W];
      for (int l = 0; l < W; ++l) value[l] = motion[4 * at[l] + c];
      m[c] = load<Lanes>(value);
    }
  }
}

struct GatherKernel {
  using Grid = GatherLaneGrid;
  using In = GatherLaneBatch;
  using Out = GatherLaneSums;

  template <int W>
  MPMVV_LANE_INLINE static void body(const Grid& g, const In& in, Out& out, int l0) {
    using Lanes = typename Width<W>::Lanes;
    const Lanes zero = {};
    Sums<Lanes> sum = {zero, zero, zero, zero, zero, zero, zero, zero};
    bool corners = false, blocks = false;
    for (int l = 0; l < W; ++l) {
      const bool by_corners = in.first_node[l0 + l] == kByCorners;
      corners |= by_corners;
      blocks |= !by_corners;
    }
    if (in.block == 2) {
      block_sums<W, 2, false>(g, in, l0, sum);
    } else if (!corners) {
      block_sums<W, 3, false>(g, in, l0, sum);
    } else {
      // The block lanes by rows (the corner lanes at node 0, their sums then
      // replaced), each corner lane by itself, into an array: a vector's lane
      // written by a variable index keeps every sum in memory.
      using Mask = typename Width<W>::Mask;
      if (blocks) block_sums<W, 3, true>(g, in, l0, sum);
      alignas(64) double own[8][W] = {};
      Mask by_corners;
      for (int l = 0; l < W; ++l) {
        by_corners[l] = in.first_node[l0 + l] == kByCorners ? -1 : 0;
        if (by_corners[l]) corner_sums(g, in, l0 + l, l, own);
      }
      Lanes* const sums[8] = {&sum.ax, &sum.ay, &sum.vx, &sum.vy, &sum.L00, &sum.L10, &sum.L01, &sum.L11};
      for (int k = 0; k < 8; ++k) *sums[k] = by_corners ? load<Lanes>(own[k]) : *sums[k];
    }
    update<W>(g, out, l0, sum);
  }

  // The sums over the lanes' stencils, in the update's order.
  template <class Lanes>
  struct Sums {
    Lanes ax, ay, vx, vy, L00, L10, L01, L11;
  };

  // A block of N x N nodes; with `others`, a lane that is no block reads
  // node 0 (its sums are not kept).
  template <int W, int N, bool others>
  MPMVV_LANE_INLINE static void block_sums(const Grid& g, const In& in, int l0, Sums<typename Width<W>::Lanes>& sum) {
    using Lanes = typename Width<W>::Lanes;
    long long first[W];
    for (int l = 0; l < W; ++l) first[l] = others && in.first_node[l0 + l] < 0 ? 0 : in.first_node[l0 + l];
    for (int b = 0; b < N; ++b)
      for (int a = 0; a < N; ++a) {
        const int s = a + 3 * b;
        long long at[W];
        for (int l = 0; l < W; ++l) at[l] = first[l] + a + b * g.row;
        Lanes m[4];
        node_motion<W>(g.motion, at, m);
        const Lanes w = load<Lanes>(in.weight[s] + l0);
        const Lanes gx = load<Lanes>(in.gradient_x[s] + l0), gy = load<Lanes>(in.gradient_y[s] + l0);
        sum.ax = sum.ax + w * m[0];  // acceleration += w a_g
        sum.ay = sum.ay + w * m[1];
        sum.vx = sum.vx + w * m[2];  // velocity += w v_g
        sum.vy = sum.vy + w * m[3];
        sum.L00 = sum.L00 + m[2] * gx;  // L += v_g G^T
        sum.L01 = sum.L01 + m[2] * gy;
        sum.L10 = sum.L10 + m[3] * gx;
        sum.L11 = sum.L11 + m[3] * gy;
      }
  }

  // Lane `lane` at kByCorners, its sums into own[k][l]: its sixteen entries
  // in their order, corner by corner, one node's four values at once (a_x,
  // a_y, v_x, v_y, as `motion` holds them) and L's four entries at once (xx,
  // yx, xy, yy); each of the eight sums takes the products the scalar update
  // takes, in its order. Across the lanes (sixteen slots of transposed loads
  // for every lane) it cost as much as the update entry by entry: 329
  // instructions a particle-step against 317, and 212 this way (callgrind,
  // 256 cells, A = 0.5, t = 0.40-0.42 s).
  template <int W>
  MPMVV_LANE_INLINE static void corner_sums(const Grid& g, const In& in, int lane, int l, double (&own)[8][W]) {
    using Node = typename Width<4>::Lanes;
    using Index = typename Width<4>::Mask;
    Node motion_sum = {}, L = {};
    for (int c = 0; c < 4; ++c) {
      const long long first = in.corner_first[c][lane];
      for (int k = 0; k < 4; ++k) {
        const int s = 4 * c + k;
        const Node m = load<Node>(g.motion + 4 * (first + (k & 1) + (k >> 1) * g.row));
        const double w = in.corner_weight[s][lane], gx = in.corner_gradient_x[s][lane];
        const double gy = in.corner_gradient_y[s][lane];
        motion_sum = motion_sum + w * m;  // acceleration += w a_g, velocity += w v_g
        L = L + __builtin_shuffle(m, Index{2, 3, 2, 3}) * Node{gx, gx, gy, gy};  // L += v_g G^T
      }
    }
    for (int k = 0; k < 4; ++k) own[k][l] = motion_sum[k];  // a_x, a_y, v_x, v_y
    for (int k = 0; k < 4; ++k) own[4 + k][l] = L[k];       // L's xx, yx, xy, yy
  }

  template <int W>
  MPMVV_LANE_INLINE static void update(const Grid& g, Out& out, int l0, const Sums<typename Width<W>::Lanes>& sum) {
    using Lanes = typename Width<W>::Lanes;
    const Lanes ax = sum.ax, ay = sum.ay, vx = sum.vx, vy = sum.vy;
    const Lanes L00 = sum.L00, L10 = sum.L10, L01 = sum.L01, L11 = sum.L11;
    const GatherLaneTargets& to = g.targets;
    const bool in_place = to.position || to.velocity || to.deformation_gradient || to.volume;
    if (!in_place) {
      store(out.acceleration[0] + l0, ax);
      store(out.acceleration[1] + l0, ay);
      store(out.velocity[0] + l0, vx);
      store(out.velocity[1] + l0, vy);
      store(out.velocity_gradient[0] + l0, L00);
      store(out.velocity_gradient[1] + l0, L10);
      store(out.velocity_gradient[2] + l0, L01);
      store(out.velocity_gradient[3] + l0, L11);
    }
    if (g.particles == nullptr) return;
    const GatherLaneParticles& P = *g.particles;
    // (I + dt L) F, each entry the two-term sum of Eigen's product, with
    // I + dt L formed as Eigen adds the identity (its zeros included).
    Lanes F[4];
    load_interleaved(P.deformation_gradient + 4 * l0, F);
    const Lanes a00 = 1.0 + g.dt * L00, a01 = 0.0 + g.dt * L01;
    const Lanes a10 = 0.0 + g.dt * L10, a11 = 1.0 + g.dt * L11;
    const Lanes n00 = a00 * F[0] + a01 * F[1], n01 = a00 * F[2] + a01 * F[3];
    const Lanes n10 = a10 * F[0] + a11 * F[1], n11 = a10 * F[2] + a11 * F[3];
    const Lanes volume = (n00 * n11 - n01 * n10) * load<Lanes>(P.reference_volume + l0);  // det F V_p0
    Lanes v[2], x[2];
    load_interleaved(P.velocity + 2 * l0, v);
    load_interleaved(P.position + 2 * l0, x);
    const Lanes new_v[2] = {v[0] + g.kick * ax, v[1] + g.kick * ay};
    const Lanes new_x[2] = {x[0] + g.dt * vx, x[1] + g.dt * vy};
    if (!in_place) {
      store(out.new_deformation_gradient[0] + l0, n00);
      store(out.new_deformation_gradient[1] + l0, n10);
      store(out.new_deformation_gradient[2] + l0, n01);
      store(out.new_deformation_gradient[3] + l0, n11);
      store(out.new_volume + l0, volume);
      store(out.new_velocity[0] + l0, new_v[0]);
      store(out.new_velocity[1] + l0, new_v[1]);
      store(out.new_position[0] + l0, new_x[0]);
      store(out.new_position[1] + l0, new_x[1]);
      return;
    }
    // Straight into the particles' arrays, once every lane's values are read.
    const Lanes new_F[4] = {n00, n10, n01, n11};
    if (to.deformation_gradient) store_interleaved(to.deformation_gradient + 4 * l0, new_F);
    if (to.volume) store(to.volume + l0, volume);
    if (to.velocity) store_interleaved(to.velocity + 2 * l0, new_v);
    if (to.position) store_interleaved(to.position + 2 * l0, new_x);
  }
};

}  // namespace

namespace lanes::MPMVV_LANE_BUILD_NS {
void gather_lanes(const GatherLaneGrid& grid, const GatherLaneBatch& batch, GatherLaneSums& out) {
  run<GatherKernel>(grid, batch, out);
}
}  // namespace lanes::MPMVV_LANE_BUILD_NS

#if defined(MPMVV_LANE_DISPATCH)
MPMVV_LANE_DISPATCH_OF(gather_lanes, (const GatherLaneGrid& grid, const GatherLaneBatch& batch, GatherLaneSums& out),
                       (grid, batch, out))
#endif

}  // namespace mpmvv
