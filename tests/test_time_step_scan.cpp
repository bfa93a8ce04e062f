// The time-step scan's shortcuts (solver/stages/time_step_scan.hpp): the
// bound on sum_g |G_gp| that lets the scan skip a particle's stencil holds for
// random domains, the early test leaves the largest speed as it is, and the
// lane screen rules out what the scalar test does.
#include <gtest/gtest.h>

#include "run_scene.hpp"
#include "solver_models.hpp"
#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "solver/explicit_stepper.hpp"
#include "solver/io/hdf5.hpp"
#include "solver/parallel.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/total_lagrangian.hpp"
#include "solver/stages.hpp"

namespace {

using mpmvv::CpdiShape;
using mpmvv::GridGeometry;
using mpmvv::testing::monitor;
using mpmvv::testing::rotation;
using mpmvv::testing::simple_shear;
using namespace mpmvv::testing::solver_models;  // the report's solid (kSolid, kDensity) and the solver's names

}  // namespace

// The scan evaluates a particle's stencil only where the bound
// CpdiShape::gradient_sum_bound says it could set a new largest speed; the
// maximum is then exact only if the bound holds: sum_g |G_gp| never exceeds
// it, for random domains (sheared, stretched, rotated; across cell lines) in
// plane strain and in r-z.
TEST(StableStep, GradientSumBoundHoldsForRandomDomains) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> where(4.0, 12.0);
  Model model;
  model.grid = GridGeometry::walled(Vec2::Zero(), 1.0, 16, 16);
  Particles& P = model.particles;
  P.resize(2000);
  P.half_size.assign(P.size(), Vec2(0.25, 0.25));
  for (std::size_t p = 0; p < P.size(); ++p) {
    P.position[p] = Vec2(where(rng), where(rng));
    P.deformation_gradient[p] =
        rotation(where(rng)) * simple_shear(0.5 * where(rng) - 2.0) * mpmvv::testing::random_deformation(rng, 0.6, 0.2);
  }
  const CpdiShape plane = CpdiShape::bind(model.grid, P);
  const auto axisymmetric = mpmvv::CpdiShapeT<mpmvv::Geometry::axisymmetric>::bind(model.grid, P);
  for (std::size_t p = 0; p < P.size(); ++p) {
    const double bound = plane.gradient_sum_bound(p);
    EXPECT_TRUE(std::isfinite(bound)) << "particle " << p;
    EXPECT_LE(mpmvv::gradient_sum(plane, p), bound * (1.0 + 1e-12)) << "particle " << p;
    EXPECT_LE(mpmvv::gradient_sum(axisymmetric, p), axisymmetric.gradient_sum_bound(p) * (1.0 + 1e-12));
  }
}

namespace {

// The neo-Hookean solid without its wave_modulus_bound: the scan then forms
// every particle's speed in full.
struct WithoutBound {
  NeoHookean solid;
  double wave_modulus(const Mat2& F, double F33, const Mat2& sigma) const { return solid.wave_modulus(F, F33, sigma); }
  double p_wave_modulus() const { return solid.p_wave_modulus(); }
};

// A "bound" that is not one: the scan would leave out the particles that set
// the largest speed, which the comparison below must see.
struct BelowTheWaveModulus : WithoutBound {
  double wave_modulus_bound(const Mat2& F, double F33, const Mat2& sigma) const {
    return 0.25 * solid.wave_modulus(F, F33, sigma);
  }
};

// n particles spread over a 16 x 16-cell grid with sheared, stretched and
// compressed CPDI domains, a fifth of them fast (twice the small-strain wave
// speed), the rest slow, each stressed as its F says.
Model scanned_particles(const NeoHookean& solid, std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> where(4.0, 12.0), unit(-1.0, 1.0);
  Model model;
  model.grid = GridGeometry::walled(Vec2::Zero(), 1.0, 16, 16);
  Particles& P = model.particles;
  P.resize(n);
  P.half_size.assign(P.size(), Vec2(0.25, 0.25));
  const double c0 = std::sqrt(solid.p_wave_modulus() / kDensity);
  for (std::size_t p = 0; p < P.size(); ++p) {
    P.position[p] = Vec2(where(rng), where(rng));
    const double shear = p % 3 == 0 ? 0.0 : 0.4 * where(rng) - 1.6;
    P.deformation_gradient[p] =
        rotation(where(rng)) * simple_shear(shear) * mpmvv::testing::random_deformation(rng, 0.3, 0.4);
    P.velocity[p] = (p % 5 == 0 ? 2.0 : 0.1) * c0 * Vec2(unit(rng), unit(rng));
    P.reference_volume[p] = 0.25;
    P.volume[p] = mpmvv::determinant(P.deformation_gradient[p]) * P.reference_volume[p];
    P.mass[p] = kDensity * P.reference_volume[p];
    P.stress[p] = solid.cauchy_stress(P.deformation_gradient[p]);
  }
  return model;
}

}  // namespace

// The scan leaves out a particle whose bound cannot beat the largest speed so
// far (stages.hpp: signal_speed); the largest speed is then the one that
// forming every particle's speed gives, bit for bit, from the particle's
// state alone (scan_particles) and with the map's stencils (ScanInMap), over
// sheared, stretched and compressed CPDI domains, some at rest and some fast.
TEST(StableStep, TheScansEarlyTestLeavesTheLargestSpeedAsItIs) {
  std::mt19937 rng(17);
  for (const NeoHookean& solid : {kSolid, NeoHookean{576923.0769230769, 384615.3846153846}}) {
    Model model = scanned_particles(solid, 3000, rng);
    Particles& P = model.particles;
    const double c0 = std::sqrt(solid.p_wave_modulus() / kDensity);
    const CpdiShape shape = CpdiShape::bind(model.grid, P);
    const mpmvv::ParticleScan bounded = mpmvv::scan_particles(shape, solid, P, model.grid.h);
    const mpmvv::ParticleScan full = mpmvv::scan_particles(shape, WithoutBound{solid}, P, model.grid.h);
    ASSERT_EQ(bounded.first_unhealthy, P.size());
    EXPECT_EQ(bounded.max_signal_speed, full.max_signal_speed);
    EXPECT_GT(full.max_signal_speed, c0);

    mpmvv::ScatterBuffers buffers;
    buffers.resize(mpmvv::max_threads(), model.grid.node_count());
    mpmvv::GridFields g;
    g.resize(model.grid.node_count());
    mpmvv::ScanInMap<CpdiShape, NeoHookean> in_map{shape, solid, P, model.grid.h};
    mpmvv::particles_to_grid<mpmvv::kMass>(shape, P, buffers, g, {}, nullptr, &in_map);
    const WithoutBound unbounded{solid};
    mpmvv::ScanInMap<CpdiShape, WithoutBound> in_map_full{shape, unbounded, P, model.grid.h};
    mpmvv::particles_to_grid<mpmvv::kMass>(shape, P, buffers, g, {}, nullptr, &in_map_full);
    EXPECT_EQ(in_map.result.max_signal_speed, in_map_full.result.max_signal_speed);
    EXPECT_EQ(in_map.result.max_signal_speed, full.max_signal_speed);

    // uGIMP has no stiffening: the material's wave speed alone sets the
    // largest, and a bound below it would change it.
    const mpmvv::GimpShape gimp = mpmvv::GimpShape::bind(model.grid, P);
    const double gimp_full = mpmvv::scan_particles(gimp, unbounded, P, model.grid.h).max_signal_speed;
    EXPECT_EQ(mpmvv::scan_particles(gimp, solid, P, model.grid.h).max_signal_speed, gimp_full);
    EXPECT_LT(mpmvv::scan_particles(gimp, BelowTheWaveModulus{unbounded}, P, model.grid.h).max_signal_speed,
              gimp_full);
  }
}

// The lanes' screen of the scan (material/neo_hookean_lanes.hpp), from every
// build the CPU has: a particle is sound exactly where its state is finite
// with J > 0, and ruled out exactly where the scalar test rules it out
// (signal_speed returns 0) with the same largest speed (a domain whose
// corners reach past 4 x 4 nodes has no bound and is left to the scalar
// test); over sheared and
// stretched CPDI domains, fast and slow particles, and states with NaN, an
// infinite stress or a turned-over F, at three largest speeds.
TEST(StableStep, TheLanesScreenRulesOutWhatTheScalarTestDoes) {
  std::mt19937 rng(23);
  const NeoHookean solid{576923.0769230769, 384615.3846153846};
  Model model = scanned_particles(solid, 4000, rng);
  Particles& P = model.particles;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (p % 97 == 1) P.velocity[p].x() = std::nan("");
    if (p % 89 == 2) P.stress[p](1, 0) = std::numeric_limits<double>::infinity();
    if (p % 83 == 3) P.deformation_gradient[p].col(0) *= -1.0;
  }
  const CpdiShape shape = CpdiShape::bind(model.grid, P);
  const double largest_speed = mpmvv::scan_particles(shape, WithoutBound{solid}, P, model.grid.h).max_signal_speed;
  for (const mpmvv::LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
    SCOPED_TRACE(mpmvv::name(build));
    std::size_t ruled_out = 0, formed = 0, unsound = 0;
    for (const double fraction : {0.3, 0.7, 1.0}) {
      const double largest = fraction * largest_speed;
      // The last batch holds fewer than eight particles (its input a copy).
      const std::size_t n = P.size() - 3;
      for (std::size_t first = 0; first < n; first += mpmvv::kLanes) {
        const int count = int(std::min<std::size_t>(mpmvv::kLanes, n - first));
        CpdiShape::LaneBatch batch;
        shape.compute_lanes(first, count, batch, true, &build);
        mpmvv::NeoHookeanScanLaneCopy copy;
        const mpmvv::NeoHookeanScanLaneInput in =
            mpmvv::scan_lane_input(P, first, count, shape.lane_gradient_bounds(batch), copy);
        const mpmvv::NeoHookeanScanLaneParams params{solid.lambda, solid.mu, solid.p_wave_modulus(), largest,
                                                     model.grid.h, 1.0 / mpmvv::kGridBasisGradientBound, true};
        mpmvv::NeoHookeanScanLaneVerdict verdict;
        mpmvv::neo_hookean_scan_lanes(build, params, in, verdict);
        for (int l = 0; l < count; ++l) {
          const std::size_t p = first + std::size_t(l);
          const bool finite = P.position[p].allFinite() && P.velocity[p].allFinite() &&
                              P.deformation_gradient[p].allFinite() && P.stress[p].allFinite();
          const bool sound = finite && mpmvv::determinant(P.deformation_gradient[p]) > 0.0;
          ASSERT_EQ(verdict.sound[l] != 0, sound) << "particle " << p;
          if (!sound) {
            EXPECT_NE(verdict.may_set_speed[l], 0) << "particle " << p;
            unsound += fraction == 1.0;
            continue;
          }
          mpmvv::Stencil<CpdiShape::stencil_size> st;
          shape.evaluate(p, st);
          auto stencil_of = [&]() -> const mpmvv::Stencil<CpdiShape::stencil_size>& { return st; };
          const double speed =
              mpmvv::signal_speed(shape, solid, P, model.grid.h, p, largest, stencil_of, in.gradient_bound[l]);
          // A lane with no stencil bound (corners past 3 x 3 cells) is left to the scalar test.
          if (in.gradient_bound[l] >= 0.0)
            EXPECT_EQ(verdict.may_set_speed[l] == 0, speed == 0.0) << "particle " << p << ", largest " << largest;
          else
            EXPECT_NE(verdict.may_set_speed[l], 0) << "particle " << p;
          (verdict.may_set_speed[l] == 0 ? ruled_out : formed) += 1;
        }
      }
    }
    // Both verdicts occur, and every kind of unsound state.
    EXPECT_GT(ruled_out, P.size());
    EXPECT_GT(formed, 100u);
    EXPECT_GT(unsound, 100u);
  }
}
