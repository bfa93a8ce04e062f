// The stencils of the lane kernels (solver/lanes.hpp: CPDI, uGIMP and linear) against
// the scalar evaluate of their shapes, bit for bit, for every build of the
// kernels this CPU can run: the explicit step takes its stencils from the
// kernels, and its results are meant to be those of the scalar code to the
// last bit.
#include <gtest/gtest.h>

#include "support.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <vector>

#include "solver/shape/cpdi.hpp"
#include "solver/shape/cpdi_lanes.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/linear.hpp"
#include "solver/stages.hpp"  // list_lane

namespace {

using mpmvv::CpdiShape;
using mpmvv::CpdiShapeT;
using mpmvv::CpdiForm;
using mpmvv::Geometry;
using mpmvv::GimpShape;
using mpmvv::GridGeometry;
using mpmvv::LaneBuild;
using mpmvv::Mat2;
using mpmvv::Particles;
using mpmvv::Stencil;
using mpmvv::Vec2;

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// Particles spread over a 20 x 20-cell grid with random deformation
// gradients: small strains, shears that stretch a domain past a cell (the
// kernel lists those unmerged, as evaluate does), and one folded domain (det F < 0).
Particles random_particles(const GridGeometry& grid, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> where(6.0, 14.0), strain(-0.3, 0.3), shear(-3.0, 3.0);
  Particles P;
  P.resize(n);
  P.half_size.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    P.position[p] = grid.origin + grid.h * Vec2(where(rng), where(rng));
    P.half_size[p] = Vec2(0.25 * grid.h, 0.25 * grid.h);
    Mat2 F;
    F << 1.0 + strain(rng), strain(rng), strain(rng), 1.0 + strain(rng);
    if (p % 5 == 0) F(0, 1) = shear(rng);  // a domain several cells long
    if (p == 7) F(0, 0) = -1.0;            // turned over
    // The domain out of the grid; the centre beyond the wall, in the ghost layer.
    if (p % 13 == 4) P.position[p] = grid.origin + grid.h * Vec2(0.02, where(rng));
    if (p % 13 == 5) P.position[p] = grid.origin + grid.h * Vec2(where(rng), 0.7);
    P.deformation_gradient[p] = F;
    P.volume[p] = P.reference_volume[p] = 0.25 * grid.h * grid.h;
  }
  return P;
}

// Returns how many stencils of sixteen entries reached past 4 x 4 nodes. `every_kind`:
// the particles hold every kind of CPDI stencil (random_particles' F_p).
template <class Shape>
std::size_t expect_lanes_equal_evaluate(const Shape& shape, std::size_t n, LaneBuild build, bool every_kind = true) {
  constexpr bool cpdi = Shape::gradients_beyond_grid_basis;
  constexpr int N = Shape::stencil_size;
  std::size_t compared = 0, wide = 0, wide_bounded = 0, beyond = 0, outside = 0, by_corners = 0;
  for (std::size_t first = 0; first < n; first += mpmvv::kLanes) {
    const int count = int(std::min<std::size_t>(mpmvv::kLanes, n - first));
    typename Shape::LaneBatch batch;
    shape.compute_lanes(first, count, batch, true, &build);
    for (int l = 0; l < count; ++l) {
      const std::size_t p = first + std::size_t(l);
      // The scan's test of the domain, from the kernel's values.
      EXPECT_EQ(shape.lane_inside(batch, l), shape.inside(p)) << "particle " << p;
      Stencil<N> lane;
      mpmvv::list_lane(shape, batch, l, lane);
      const double* bounds = shape.lane_gradient_bounds(batch);
      const double bound = bounds ? bounds[l] : -1.0;
      if (!shape.inside(p)) {  // its stencil may leave the grid: never listed in a run
        ++outside;
        continue;
      }
      Stencil<N> scalar;
      shape.evaluate(p, scalar);
      EXPECT_EQ(lane.count, scalar.count) << "particle " << p << ", build " << mpmvv::name(build);
      if (lane.count != scalar.count) continue;
      if (scalar.count == N) ++wide;
      for (int k = 0; k < scalar.count; ++k) {
        EXPECT_EQ(lane.node[k], scalar.node[k]) << "particle " << p << " entry " << k;
        EXPECT_EQ(bits(lane.weight[k]), bits(scalar.weight[k])) << "particle " << p << " entry " << k;
        EXPECT_EQ(bits(lane.gradient[k].x()), bits(scalar.gradient[k].x())) << "particle " << p << " entry " << k;
        EXPECT_EQ(bits(lane.gradient[k].y()), bits(scalar.gradient[k].y())) << "particle " << p << " entry " << k;
      }
      // The block the transfers by rows take (lane_block_first): every
      // entry's node in it; CPDI's sixteen entries by corners, entry 4 c + k
      // the k-th node of corner c's cell from corner_first; none only for a
      // node held at the grid's edge (listed twice).
      const std::ptrdiff_t block = shape.lane_block_first(batch, l);
      const int side = N == 4 ? 2 : 3, row = shape.grid->nodes_x();
      if (block >= 0) {
        for (int k = 0; k < scalar.count; ++k) {
          const std::ptrdiff_t d = scalar.node[k] - block;
          EXPECT_TRUE(d >= 0 && d % row < side && d / row < side) << "particle " << p << " entry " << k;
        }
      } else if (block == mpmvv::kByCorners) {
        EXPECT_TRUE(cpdi && scalar.count == N) << "particle " << p;
        if constexpr (cpdi) {
          ++by_corners;
          for (int k = 0; k < scalar.count; ++k)
            EXPECT_EQ(scalar.node[k], batch.out.corner_first[k / 4][l] + (k % 2) + (k % 4 / 2) * row)
                << "particle " << p << " entry " << k;
        }
      } else {
        EXPECT_EQ(block, mpmvv::kNoBlock) << "particle " << p;
        bool repeated = false;
        for (int k = 0; k < scalar.count; ++k)
          for (int m = 0; m < k; ++m) repeated |= scalar.node[k] == scalar.node[m];
        EXPECT_TRUE(repeated || (cpdi && scalar.count == N)) << "particle " << p;
      }
      if constexpr (cpdi) {
        if (scalar.count < N) {
          // The time-step scan's bound of sum |G| over the entries: the one
          // stencil.hpp forms, and above the sum of the lengths.
          EXPECT_EQ(bits(bound), bits(mpmvv::entry_gradient_sum_bound(scalar))) << "particle " << p;
          double lengths = 0.0;
          for (int k = 0; k < scalar.count; ++k) lengths += scalar.gradient[k].norm();
          EXPECT_GE(bound, lengths) << "particle " << p;
          EXPECT_LE(bound, 1.09 * lengths) << "particle " << p;
        } else {
          // Sixteen entries: within 4 x 4 nodes, the bound of the scan's own
          // sum over nodes, each node's gradients merged (stages.hpp:
          // gradient_sum); past them, the bound over the entries as listed,
          // the one stencil.hpp forms.
          int low_i = 1 << 30, high_i = -1, low_j = 1 << 30, high_j = -1;
          for (int k = 0; k < N; ++k) {
            const int i = scalar.node[k] % shape.grid->nodes_x(), j = scalar.node[k] / shape.grid->nodes_x();
            low_i = std::min(low_i, i), high_i = std::max(high_i, i);
            low_j = std::min(low_j, j), high_j = std::max(high_j, j);
          }
          const double lengths = mpmvv::gradient_sum(scalar);
          EXPECT_GE(bound, lengths) << "particle " << p;
          if (high_i - low_i > 3 || high_j - low_j > 3) {
            EXPECT_EQ(bits(bound), bits(mpmvv::entry_gradient_sum_bound(scalar))) << "particle " << p;
            ++beyond;
          } else {
            EXPECT_LE(bound, 1.09 * lengths) << "particle " << p;
            EXPECT_LE(bound, mpmvv::entry_gradient_sum_bound(scalar) * (1.0 + 1e-15)) << "particle " << p;
            ++wide_bounded;
          }
        }
      }
      ++compared;
    }
  }
  EXPECT_GT(compared, n / 2);
  if (cpdi && every_kind) {  // both kinds of stencil, merged and full, and domains out of the grid
    EXPECT_GT(outside, 0u);
    EXPECT_GT(wide_bounded, 0u);
    EXPECT_GT(compared - wide, n / 4);
    EXPECT_EQ(by_corners, wide);  // every wide stencil inside the grid goes by its corners
  }
  return beyond;
}

TEST(CpdiLanes, EveryBuildGivesTheScalarStencilsBitForBit) {
  const GridGeometry grid = GridGeometry::walled(Vec2(-0.3, 0.1), 0.05, 18, 18);
  const Particles P = random_particles(grid, 203, 5);  // 25 lanes of 8 and 3 over
  ASSERT_FALSE(mpmvv::testing::lane_builds_of_this_cpu().empty());
  for (LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
    SCOPED_TRACE(mpmvv::name(build));
    // Corners past 4 x 4 nodes too, with the bound over their entries.
    EXPECT_GT(expect_lanes_equal_evaluate(CpdiShape::bind(grid, P), P.size(), build), 0u);
    // The deliberate faults' factors (faults.hpp) go through the kernel too.
    CpdiShape faulty = CpdiShape::bind(grid, P, nullptr, 1.5);
    faulty.weight_skew = 0.2;
    expect_lanes_equal_evaluate(faulty, P.size(), build);
    // A shape without F_p: the undeformed domains diag(l_p), which the lanes
    // read from a copy rather than in place.
    CpdiShape undeformed = CpdiShape::bind(grid, P);
    undeformed.deformation_gradient = nullptr;
    expect_lanes_equal_evaluate(undeformed, P.size(), build, false);
  }
}

TEST(CpdiLanes, TurnedDomainsTooBitForBit) {
  const GridGeometry grid = GridGeometry::walled(Vec2(0.0, 0.0), 0.1, 18, 18);
  Particles P = random_particles(grid, 64, 9);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> turn(-0.8, 0.8);
  P.domain_axes.resize(P.size());
  for (std::size_t p = 0; p < P.size(); ++p) {
    const double c = std::cos(turn(rng)), s = std::sin(turn(rng));
    P.domain_axes[p] << 0.25 * grid.h * c, -0.2 * grid.h * s, 0.25 * grid.h * s, 0.2 * grid.h * c;
  }
  using Turned = CpdiShapeT<Geometry::plane_strain, CpdiForm::turned>;
  for (LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
    SCOPED_TRACE(mpmvv::name(build));
    expect_lanes_equal_evaluate(Turned::bind(grid, P), P.size(), build);
  }
}

TEST(GimpLanes, EveryBuildGivesTheScalarStencilsBitForBit) {
  // Centres anywhere a particle of half-size h/4 is inside the grid, up to a
  // quarter cell from its edge, where nodes beyond it carry no weight; one
  // particle in three half as large.
  const GridGeometry grid = GridGeometry::walled(Vec2(-0.3, 0.1), 0.05, 12, 10);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> along_x(0.25, grid.cells_x - 0.25), along_y(0.25, grid.cells_y - 0.25);
  const std::size_t n = 301;
  Particles P;
  P.resize(n);
  P.half_size.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    P.position[p] = grid.origin + grid.h * Vec2(along_x(rng), along_y(rng));
    const double l = p % 3 == 0 ? 0.125 : 0.25;
    P.half_size[p] = Vec2(l * grid.h, l * grid.h);
  }
  P.position[0] = grid.origin + grid.h * Vec2(0.25, 0.25);  // on the edges' limit
  P.position[1] = grid.origin + grid.h * Vec2(grid.cells_x - 0.25, 3.5);  // half-way between nodes
  // Centres whose distance x - x_g to a node is, in floating point, exactly
  // an end of a piece of the weight (l = h/4), where the pieces on either
  // side round differently: the first test that holds must pick the piece.
  // d = l and -l from node 6, h - l and -h + l from node 4.
  const double ends[4] = {0.012500000000000056, -0.012499999999999945, -0.06249999999999997, -0.13749999999999998};
  const std::size_t end_particles[4] = {2, 4, 5, 7};  // half-size h/4
  for (int k = 0; k < 4; ++k) P.position[end_particles[k]] = Vec2(ends[k], grid.origin.y() + 5.5 * grid.h);
  // One particle per cell and direction (l = h/2, where h - l = l): d = l
  // from node 6, -l from node 7, -h - l from node 3 (the support's end,
  // outside) and a centre on node 6.
  const double half_ends[4] = {-0.024999999999999932, -0.024999999999999946, -0.27499999999999997,
                               grid.origin.x() + 6.0 * grid.h};
  for (int k = 0; k < 4; ++k) {
    const std::size_t p = 10 + std::size_t(k);
    P.half_size[p] = Vec2(0.5 * grid.h, 0.5 * grid.h);
    P.position[p] = Vec2(half_ends[k], grid.origin.y() + (k == 3 ? 6.0 : 5.5) * grid.h);
  }
  ASSERT_FALSE(mpmvv::testing::lane_builds_of_this_cpu().empty());
  for (LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
    SCOPED_TRACE(mpmvv::name(build));
    expect_lanes_equal_evaluate(GimpShape::bind(grid, P), n, build);
  }
}

TEST(LinearLanes, EveryBuildGivesTheScalarStencilsBitForBit) {
  // Centres anywhere between the walls, on them (the upper ones belong to
  // the last cells), on a node and on a cell's edge; and outside: in the
  // ghost layer and NaN.
  const GridGeometry grid = GridGeometry::walled(Vec2(-0.3, 0.1), 0.05, 12, 10);
  const Vec2 lo = grid.wall_lower(), hi = grid.wall_upper();
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> along_x(lo.x(), hi.x()), along_y(lo.y(), hi.y());
  const std::size_t n = 203;  // 25 lanes of 8 and 3 over
  Particles P;
  P.resize(n);
  for (std::size_t p = 0; p < n; ++p) P.position[p] = Vec2(along_x(rng), along_y(rng));
  P.position[0] = hi;
  P.position[1] = lo;
  P.position[2] = grid.node_position(5, 4);
  P.position[3] = Vec2(grid.node_position(7, 3).x(), along_y(rng));
  P.position[4] = Vec2(lo.x() - 0.5 * grid.h, along_y(rng));
  P.position[201] = Vec2(std::nan(""), along_y(rng));
  const mpmvv::LinearShape shape = mpmvv::LinearShape::bind(grid, P);
  ASSERT_FALSE(mpmvv::testing::lane_builds_of_this_cpu().empty());
  for (LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
    SCOPED_TRACE(mpmvv::name(build));
    expect_lanes_equal_evaluate(shape, n, build);
  }
  EXPECT_FALSE(shape.inside(4));
  EXPECT_FALSE(shape.inside(201));
}

}  // namespace

// MPMVV_LANE_BUILD names the build a benchmark runs, where the CPU has it;
// any other value leaves the widest.
TEST(LaneBuilds, TheEnvironmentNamesABuildTheCpuHas) {
  ::unsetenv("MPMVV_LANE_BUILD");
  const LaneBuild widest = mpmvv::widest_lane_build();
  EXPECT_TRUE(mpmvv::cpu_has(widest));
  ::setenv("MPMVV_LANE_BUILD", "baseline", 1);
  EXPECT_EQ(mpmvv::widest_lane_build(), LaneBuild::baseline);
  for (LaneBuild b : mpmvv::testing::lane_builds_of_this_cpu()) {
    ::setenv("MPMVV_LANE_BUILD", mpmvv::name(b), 1);
    EXPECT_EQ(mpmvv::widest_lane_build(), b) << mpmvv::name(b);
  }
  ::setenv("MPMVV_LANE_BUILD", "sse5", 1);
  EXPECT_EQ(mpmvv::widest_lane_build(), widest);
  ::unsetenv("MPMVV_LANE_BUILD");
}
