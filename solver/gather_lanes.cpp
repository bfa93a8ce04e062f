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
    if (in.block == 2) sums<W, 2>(g, in, out, l0);
    else sums<W, 3>(g, in, out, l0);
  }

  // A block of N x N nodes.
  template <int W, int N>
  MPMVV_LANE_INLINE static void sums(const Grid& g, const In& in, Out& out, int l0) {
    using Lanes = typename Width<W>::Lanes;
    const Lanes zero = {};
    Lanes ax = zero, ay = zero, vx = zero, vy = zero;
    Lanes L00 = zero, L10 = zero, L01 = zero, L11 = zero;
    for (int b = 0; b < N; ++b)
      for (int a = 0; a < N; ++a) {
        const int s = a + 3 * b;
        long long at[W];
        for (int l = 0; l < W; ++l) at[l] = in.first_node[l0 + l] + a + b * g.row;
        Lanes m[4];
        node_motion<W>(g.motion, at, m);
        const Lanes w = load<Lanes>(in.weight[s] + l0);
        const Lanes gx = load<Lanes>(in.gradient_x[s] + l0), gy = load<Lanes>(in.gradient_y[s] + l0);
        ax = ax + w * m[0];  // acceleration += w a_g
        ay = ay + w * m[1];
        vx = vx + w * m[2];  // velocity += w v_g
        vy = vy + w * m[3];
        L00 = L00 + m[2] * gx;  // L += v_g G^T
        L01 = L01 + m[2] * gy;
        L10 = L10 + m[3] * gx;
        L11 = L11 + m[3] * gy;
      }
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
