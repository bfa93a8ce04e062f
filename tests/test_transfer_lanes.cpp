// The transfers by rows of nodes (solver/scatter_lanes.hpp, gather_lanes.hpp)
// against the transfers entry by entry, bit for bit: particle-to-grid's node
// sums and the time-step scan's verdict (by rows for uGIMP and linear; CPDI's lanes
// there add entry by entry, against its scalar stencils), and grid-to-particle's x_p, v_p,
// F_p, V_p and APIC's C_p, over CPDI domains merged and stretched past a
// cell (by their corners' blocks), uGIMP at the grid's edge, a batch of fewer than eight, and particles
// the scan leaves out; each build of the kernels this CPU can run; and a
// map into buffers that earlier maps used.
#include <gtest/gtest.h>

#include "support.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "solver/gather_lanes.hpp"
#include "solver/material/neo_hookean.hpp"
#include "solver/scatter_lanes.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/linear.hpp"
#include "solver/stages.hpp"

namespace {

using mpmvv::CpdiShape;
using mpmvv::GimpShape;
using mpmvv::GridFields;
using mpmvv::GridGeometry;
using mpmvv::LaneBuild;
using mpmvv::Mat2;
using mpmvv::NeoHookean;
using mpmvv::Particles;
using mpmvv::Vec2;

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// The same shape taken entry by entry: its scalar evaluate, no lanes.
template <class Shape>
struct EntryByEntry : Shape {
  static constexpr bool lanes = false;
  explicit EntryByEntry(const Shape& s) : Shape(s) {}
};

const NeoHookean kSolid{2.0e4, 1.0e4};

// n particles of random state on a 20 x 20-cell grid: small strains, one in
// five sheared several cells long; with `strays`, some whose domain leaves
// the grid and one with a NaN velocity (the scan leaves them out).
Particles random_particles(const GridGeometry& grid, std::size_t n, unsigned seed, bool strays) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> where(3.0, 17.0), strain(-0.3, 0.3), shear(-3.0, 3.0), unit(-1.0, 1.0);
  Particles P;
  P.resize(n);
  P.half_size.resize(n);
  P.body_force.resize(n);
  P.affine_velocity.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    P.position[p] = grid.origin + grid.h * Vec2(where(rng), where(rng));
    P.half_size[p] = Vec2(0.25 * grid.h, 0.25 * grid.h);
    Mat2 F;
    F << 1.0 + strain(rng), strain(rng), strain(rng), 1.0 + strain(rng);
    if (p % 5 == 0) F(0, 1) = shear(rng), F(1, 0) = 0.0;  // det F > 0 still
    P.deformation_gradient[p] = F;
    P.reference_volume[p] = 0.25 * grid.h * grid.h;
    P.volume[p] = mpmvv::determinant(F) * P.reference_volume[p];
    P.mass[p] = 1000.0 * P.reference_volume[p] * (1.0 + 0.5 * unit(rng));
    P.velocity[p] = Vec2(unit(rng), unit(rng));
    P.body_force[p] = Vec2(10.0 * unit(rng), 10.0 * unit(rng));
    P.stress[p] = kSolid.cauchy_stress(F);
    if (strays && p % 37 == 4) P.position[p] = grid.origin + grid.h * Vec2(0.02, where(rng));
    if (strays && p == 300) P.velocity[p].x() = std::nan("");
  }
  return P;
}

// `block_share`: the share of all-block batches the map is told the last one
// found, which decides CPDI's layout (scatter_by_rows: 1 by rows, 0 node by
// node); uGIMP goes by rows whatever it is.
template <class Shape>
void expect_map_by_rows_as_entry_by_entry(const GridGeometry& grid, const Particles& P, double block_share) {
  using mpmvv::kBodyForce, mpmvv::kInternalForce, mpmvv::kMass, mpmvv::kMomentum;
  const Shape shape = Shape::bind(grid, P);
  const EntryByEntry<Shape> scalar(shape);
  mpmvv::ScatterBuffers buffers;
  buffers.resize(mpmvv::max_threads(), grid.node_count());
  buffers.block_batch_share = block_share;
  const bool expected_rows = block_share == 1.0 || !std::is_same_v<Shape, CpdiShape>;  // uGIMP, linear: always
  EXPECT_EQ(mpmvv::scatter_by_rows<Shape>(buffers), expected_rows);
  GridFields rows, entries;
  rows.resize(grid.node_count());
  entries.resize(grid.node_count());
  mpmvv::ScanInMap<Shape, NeoHookean> scan_rows{shape, kSolid, P, grid.h};
  mpmvv::ScanInMap<EntryByEntry<Shape>, NeoHookean> scan_entries{scalar, kSolid, P, grid.h};
  mpmvv::particles_to_grid<kMass | kMomentum | kInternalForce | kBodyForce>(shape, P, buffers, rows, {}, nullptr,
                                                                            &scan_rows);
  // The map counts its batches that were all blocks, for the next: most of
  // these particles' domains are within a cell.
  EXPECT_GT(buffers.block_batch_share, 0.2) << buffers.block_batch_share;
  ::testing::Test::RecordProperty("block_batch_share", std::to_string(buffers.block_batch_share));
  EXPECT_LE(buffers.block_batch_share, 1.0);
  mpmvv::particles_to_grid<kMass | kMomentum | kInternalForce | kBodyForce>(scalar, P, buffers, entries, {},
                                                                            nullptr, &scan_entries);
  EXPECT_EQ(scan_rows.result.first_unhealthy, scan_entries.result.first_unhealthy);
  EXPECT_EQ(bits(scan_rows.result.max_signal_speed), bits(scan_entries.result.max_signal_speed));
  std::size_t reached = 0;
  for (std::size_t i = 0; i < grid.node_count(); ++i) {
    ASSERT_EQ(bits(rows.mass[i]), bits(entries.mass[i])) << "node " << i;
    for (int c = 0; c < 2; ++c) {
      ASSERT_EQ(bits(rows.momentum[i][c]), bits(entries.momentum[i][c])) << "node " << i;
      ASSERT_EQ(bits(rows.force[i][c]), bits(entries.force[i][c])) << "node " << i;
    }
    reached += rows.mass[i] > 0.0;
  }
  EXPECT_GT(reached, grid.node_count() / 4);
}

template <class Shape>
void expect_update_by_rows_as_entry_by_entry(const GridGeometry& grid, const Particles& start, unsigned seed) {
  using mpmvv::kAffine, mpmvv::kDeformation, mpmvv::kPosition, mpmvv::kVelocity;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  GridFields g;
  g.resize(grid.node_count());
  for (std::size_t i = 0; i < grid.node_count(); ++i) {
    g.velocity[i] = Vec2(unit(rng), unit(rng));
    g.acceleration[i] = Vec2(100.0 * unit(rng), 100.0 * unit(rng));
  }
  const double dt = 1e-3, kick = 1.1e-3;
  auto expect_same = [&](const Particles& a, const Particles& b, bool affine) {
    for (std::size_t p = 0; p < a.size(); ++p) {
      for (int c = 0; c < 2; ++c) {
        ASSERT_EQ(bits(a.position[p][c]), bits(b.position[p][c])) << "particle " << p;
        ASSERT_EQ(bits(a.velocity[p][c]), bits(b.velocity[p][c])) << "particle " << p;
      }
      for (int c = 0; c < 4; ++c) {
        ASSERT_EQ(bits(a.deformation_gradient[p](c)), bits(b.deformation_gradient[p](c))) << "particle " << p;
        if (affine) {
          ASSERT_EQ(bits(a.affine_velocity[p](c)), bits(b.affine_velocity[p](c))) << "particle " << p;
        }
      }
      ASSERT_EQ(bits(a.volume[p]), bits(b.volume[p])) << "particle " << p;
    }
  };
  {
    Particles rows = start, entries = start;
    std::vector<double> motion;
    mpmvv::grid_to_particles<kVelocity | kPosition | kDeformation>(Shape::bind(grid, rows), g, rows, dt, kick,
                                                                   nullptr, {}, &motion);
    mpmvv::grid_to_particles<kVelocity | kPosition | kDeformation>(EntryByEntry<Shape>(Shape::bind(grid, entries)),
                                                                   g, entries, dt, kick);
    expect_same(rows, entries, false);
    EXPECT_NE(bits(rows.position[0].x()), bits(start.position[0].x()));
  }
  {  // APIC: the sums by rows, the update entry by entry
    Particles rows = start, entries = start;
    mpmvv::grid_to_particles<kVelocity | kAffine | kPosition>(Shape::bind(grid, rows), g, rows, dt, kick);
    mpmvv::grid_to_particles<kVelocity | kAffine | kPosition>(EntryByEntry<Shape>(Shape::bind(grid, entries)), g,
                                                              entries, dt, kick);
    expect_same(rows, entries, true);
  }
}

TEST(TransferLanes, TheMapByRowsAddsWhatTheMapEntryByEntryAdds) {
  const GridGeometry grid = GridGeometry::walled(Vec2(-0.3, 0.1), 0.05, 18, 18);
  const Particles P = random_particles(grid, 1003, 5, true);  // 125 batches of 8 and 3 over
  for (const double share : {1.0, 0.0}) {
    SCOPED_TRACE(share == 1.0 ? "CPDI by rows" : "CPDI node by node");
    expect_map_by_rows_as_entry_by_entry<CpdiShape>(grid, P, share);
  }
  {
    SCOPED_TRACE("uGIMP");
    expect_map_by_rows_as_entry_by_entry<GimpShape>(grid, P, 0.0);
  }
  {
    SCOPED_TRACE("linear");
    expect_map_by_rows_as_entry_by_entry<mpmvv::LinearShape>(grid, P, 0.0);
  }
}

TEST(TransferLanes, TheUpdateByRowsGivesWhatTheUpdateEntryByEntryGives) {
  const GridGeometry grid = GridGeometry::walled(Vec2(-0.3, 0.1), 0.05, 18, 18);
  const Particles P = random_particles(grid, 1003, 7, false);
  {
    SCOPED_TRACE("CPDI");
    expect_update_by_rows_as_entry_by_entry<CpdiShape>(grid, P, 3);
  }
  {
    SCOPED_TRACE("uGIMP");
    expect_update_by_rows_as_entry_by_entry<GimpShape>(grid, P, 4);
  }
  {
    SCOPED_TRACE("linear");
    expect_update_by_rows_as_entry_by_entry<mpmvv::LinearShape>(grid, P, 5);
  }
}

// The threads' scatter buffers are kept from map to map (ScatterBuffers):
// after maps of particles elsewhere (the first thread's at the top of the
// grid, the second's at the bottom, then everywhere), a map gives what
// fresh buffers give, to the bit, in each layout of the sums and with 1, 2
// and 3 threads; no sum of an earlier map is left in a node.
template <class Shape>
void expect_reused_buffers_as_fresh(const GridGeometry& grid, double block_share, int threads) {
  using mpmvv::kBodyForce, mpmvv::kInternalForce, mpmvv::kMass, mpmvv::kMomentum;
  constexpr unsigned kAll = kMass | kMomentum | kInternalForce | kBodyForce;
  const std::size_t n = 403;
  Particles apart = random_particles(grid, n, 21, false);
  for (std::size_t p = 0; p < n; ++p) {
    // y from cells 3-17 to 11-17 (the first half) or 3-9 (the second).
    const double y = (apart.position[p].y() - grid.origin.y()) / grid.h;
    apart.position[p].y() = grid.origin.y() + grid.h * ((p < n / 2 ? 11.0 : 3.0) + (y - 3.0) * 6.0 / 14.0);
  }
  const Particles spread = random_particles(grid, n, 22, false);
  auto map = [&](const Particles& P, mpmvv::ScatterBuffers& buffers, GridFields& g) {
    buffers.block_batch_share = block_share;
    mpmvv::particles_to_grid<kAll>(Shape::bind(grid, P), P, buffers, g);
  };
  auto expect_same = [&](const GridFields& a, const GridFields& b) {
    for (std::size_t i = 0; i < grid.node_count(); ++i) {
      ASSERT_EQ(bits(a.mass[i]), bits(b.mass[i])) << "node " << i;
      for (int c = 0; c < 2; ++c) {
        ASSERT_EQ(bits(a.momentum[i][c]), bits(b.momentum[i][c])) << "node " << i;
        ASSERT_EQ(bits(a.force[i][c]), bits(b.force[i][c])) << "node " << i;
      }
    }
  };
  mpmvv::ScatterBuffers reused;
  reused.resize(threads, grid.node_count());
  for (const Particles* P : std::initializer_list<const Particles*>{&apart, &spread, &apart}) {
    GridFields again, fresh;
    again.resize(grid.node_count());
    fresh.resize(grid.node_count());
    map(*P, reused, again);
    mpmvv::ScatterBuffers new_buffers;
    new_buffers.resize(threads, grid.node_count());
    map(*P, new_buffers, fresh);
    expect_same(again, fresh);
    // Stale sums of the earlier map were left out, not merely small.
    double mass = 0.0;
    for (std::size_t i = 0; i < grid.node_count(); ++i) mass += again.mass[i];
    double particles_mass = 0.0;
    for (std::size_t p = 0; p < n; ++p) particles_mass += P->mass[p];
    EXPECT_NEAR(mass, particles_mass, 1e-12 * particles_mass);
  }
}

TEST(TransferLanes, AMapAfterOthersSumsWhatFreshBuffersSum) {
  const GridGeometry grid = GridGeometry::walled(Vec2(-0.3, 0.1), 0.05, 18, 18);
  for (const int threads : {1, 2, 3}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    for (const double share : {1.0, 0.0}) {
      SCOPED_TRACE(share == 1.0 ? "CPDI by rows" : "CPDI node by node");
      expect_reused_buffers_as_fresh<CpdiShape>(grid, share, threads);
    }
    {
      SCOPED_TRACE("uGIMP");
      expect_reused_buffers_as_fresh<GimpShape>(grid, 0.0, threads);
    }
    {
      SCOPED_TRACE("linear");
      expect_reused_buffers_as_fresh<mpmvv::LinearShape>(grid, 0.0, threads);
    }
  }
}

// Each build's kernels against the build the transfers run, batch by batch:
// the scatter into sums from zero, the gather's sums and update.
TEST(TransferLanes, EveryBuildGivesTheSameSumsBitForBit) {
  const GridGeometry grid = GridGeometry::walled(Vec2(-0.3, 0.1), 0.05, 18, 18);
  const Particles P = random_particles(grid, 203, 9, false);
  const CpdiShape shape = CpdiShape::bind(grid, P);
  const std::ptrdiff_t row = grid.nodes_x();
  const std::size_t stride = mpmvv::ScatterSums<true>::stride_of(grid.node_count(), row);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<double> motion(4 * stride, 0.0);
  for (std::size_t k = 0; k < 4 * grid.node_count(); ++k) motion[k] = unit(rng);
  const mpmvv::ScatterParticles particles{P.mass.data(), mpmvv::values_of(P.velocity.data()), P.volume.data(),
                                          mpmvv::values_of(P.stress.data()), mpmvv::values_of(P.body_force.data())};
  const mpmvv::ScatterFields fields{true, true, true, true};
  std::size_t by_rows = 0, by_corners = 0;
  for (std::size_t first = 0; first + mpmvv::kLanes <= P.size(); first += mpmvv::kLanes) {
    CpdiShape::LaneBatch batch;
    shape.compute_lanes(first, mpmvv::kLanes, batch, false);
    mpmvv::ScatterLaneBatch scatter;
    mpmvv::GatherLaneBatch gather;
    mpmvv::take_slots(batch, scatter);
    mpmvv::take_slots(batch, gather);
    scatter.first = first;
    for (int l = 0; l < mpmvv::kLanes; ++l) {
      const std::ptrdiff_t block = shape.lane_block_first(batch, l);
      gather.first_node[l] = block == mpmvv::kNoBlock ? 0 : block;
      scatter.first_node[l] = block;
      if (block != mpmvv::kNoBlock) scatter.pending |= 1u << l, ++by_rows;
      by_corners += block == mpmvv::kByCorners;
    }
    const mpmvv::GatherLaneParticles in{mpmvv::values_of(P.position.data() + first),
                                        mpmvv::values_of(P.velocity.data() + first),
                                        mpmvv::values_of(P.deformation_gradient.data() + first),
                                        P.reference_volume.data() + first};
    const mpmvv::GatherLaneGrid lanes{motion.data(), row, &in, 1e-3, 1.1e-3};
    mpmvv::GatherLaneSums expected;
    mpmvv::gather_lanes(lanes, gather, expected);
    std::vector<double> expected_sums(5 * stride, 0.0);
    mpmvv::ScatterLaneBatch pending = scatter;
    auto rows_of = [&](std::vector<double>& sums) {
      double* s = sums.data();
      return mpmvv::ScatterRows{s, s + stride, s + 2 * stride, s + 3 * stride, s + 4 * stride, row};
    };
    mpmvv::scatter_lanes(fields, particles, pending, rows_of(expected_sums));
    EXPECT_EQ(pending.pending, 0u);
    for (LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
      SCOPED_TRACE(mpmvv::name(build));
      mpmvv::GatherLaneSums sums;
      mpmvv::gather_lanes(build, lanes, gather, sums);
      const double* a = &expected.acceleration[0][0];
      const double* b = &sums.acceleration[0][0];
      for (std::size_t k = 0; k < sizeof(sums) / sizeof(double); ++k)
        ASSERT_EQ(bits(a[k]), bits(b[k])) << "batch " << first << ", value " << k;
      // In place (grid_to_particles' whole batch): the update written over
      // the very arrays it reads, in the particles' layout, is new_*.
      std::vector<double> x(in.position, in.position + 2 * mpmvv::kLanes);
      std::vector<double> v(in.velocity, in.velocity + 2 * mpmvv::kLanes);
      std::vector<double> F(in.deformation_gradient, in.deformation_gradient + 4 * mpmvv::kLanes);
      const mpmvv::GatherLaneParticles own{x.data(), v.data(), F.data(), in.reference_volume};
      std::vector<double> V(mpmvv::kLanes, 0.0);
      mpmvv::GatherLaneGrid in_place{motion.data(), row, &own, 1e-3, 1.1e-3};
      in_place.targets = {x.data(), v.data(), F.data(), V.data()};
      mpmvv::GatherLaneSums unused;
      mpmvv::gather_lanes(build, in_place, gather, unused);
      for (int l = 0; l < mpmvv::kLanes; ++l) {
        for (int c = 0; c < 2; ++c) {
          ASSERT_EQ(bits(x[2 * l + c]), bits(expected.new_position[c][l])) << "batch " << first << ", lane " << l;
          ASSERT_EQ(bits(v[2 * l + c]), bits(expected.new_velocity[c][l])) << "batch " << first << ", lane " << l;
        }
        for (int c = 0; c < 4; ++c)
          ASSERT_EQ(bits(F[4 * l + c]), bits(expected.new_deformation_gradient[c][l]))
              << "batch " << first << ", lane " << l;
        ASSERT_EQ(bits(V[l]), bits(expected.new_volume[l])) << "batch " << first << ", lane " << l;
      }
      std::vector<double> scattered(5 * stride, 0.0);
      pending = scatter;
      mpmvv::scatter_lanes(build, fields, particles, pending, rows_of(scattered));
      for (std::size_t k = 0; k < scattered.size(); ++k)
        ASSERT_EQ(bits(scattered[k]), bits(expected_sums[k])) << "batch " << first << ", sum " << k;
    }
  }
  EXPECT_GT(by_rows, P.size() / 2);
  EXPECT_GT(by_corners, 0u);  // domains stretched past a cell among them
}

}  // namespace
