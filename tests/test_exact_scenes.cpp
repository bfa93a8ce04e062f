// The classical exact-solution scenes built on the boundary conditions: the
// uniaxial bar, simple shear and the neo-Hookean bar settle to their exact
// static states, the vibrating and layered bars' periods converge at second
// order, Hertz on a coarse mesh; contact with a floor and between two blocks;
// B-splines kept clear of the walls.
#include <gtest/gtest.h>

#include "boundary_models.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/QR>

#ifdef MPMVV_HAVE_FFTW
#include "analytic/fft.hpp"
#endif
#include "solver/boundary.hpp"
#include "solver/explicit_stepper.hpp"
#include "solver/rest_points.hpp"
#include "solver/shape/bspline.hpp"
#include "tools/app/scene/scene.hpp"

using namespace mpmvv::testing::boundary_models;  // the block and the names it uses

namespace {

struct SceneRun {
  mpmvv::app::ErrorTable errors;
  std::vector<std::pair<std::string, double>> measurements;
  bool completed;
};

SceneRun run_scene(const std::string& scene, const std::vector<std::string>& overrides) {
  mpmvv::app::Config config(scene, mpmvv::app::find_scene_type(scene)->keys());
  for (const std::string& o : overrides) config.set_from_text(o);
  auto s = mpmvv::app::find_scene_type(scene)->build(config);
  const mpmvv::RunOutcome outcome = s->run({});
  return {s->errors(), s->measurements(), outcome.completed};
}

// Errors on cells halved level by level fall at orders within [1.8, 2.2].
void expect_halving_orders_near_two(const std::vector<double>& error) {
  for (std::size_t k = 0; k + 1 < error.size(); ++k) {
    const double order = std::log2(error[k] / error[k + 1]);
    EXPECT_GT(order, 1.8) << error[k] << " " << error[k + 1];
    EXPECT_LT(order, 2.2) << error[k] << " " << error[k + 1];
  }
}

double measurement(const SceneRun& r, const std::string& name) {
  for (const auto& [n, v] : r.measurements)
    if (n == name) return v;
  ADD_FAILURE() << "no measurement " << name;
  return NAN;
}

}  // namespace

// The seed's steel bar pulled and pushed 0.8566 um (22 cells, the defaults):
// measured axial stress and lateral strain errors 7.6e-7 and 4.0e-7 (tension,
// CPDI), 1.4e-5 (linear MPM), 3.3e-5 (compression); the seed reached 13 % on
// Poisson's ratio. Bound: 1e-4 on both, and on the implied Poisson's ratio.
TEST(ExactScenes, UniaxialBarMatchesHookesLaw) {
  for (const char* scene : {"uniaxial-tension", "uniaxial-compression"})
    for (const char* method : {"linear", "cpdi"}) {
      const SceneRun r = run_scene(scene, {std::string("method=") + method});
      ASSERT_TRUE(r.completed) << scene << " " << method;
      EXPECT_LT(r.errors.column("error_axial_stress").back(), 1e-4) << scene << " " << method;
      EXPECT_LT(r.errors.column("error_lateral_strain").back(), 1e-4) << scene << " " << method;
      EXPECT_LT(r.errors.column("error_grip_stress").back(), 1e-4) << scene << " " << method;
      EXPECT_NEAR(measurement(r, "poisson_ratio"), 0.3, 3e-5) << scene << " " << method;
    }
}

// Simple shear of the seed's block (8 cells across): measured error of the
// middle's shear stress 6e-8 (the seed: 1.9 %); bound 1e-5. The normal
// stresses there vanish to the same measure.
TEST(ExactScenes, ShearMatchesGGamma) {
  const SceneRun r = run_scene("shear", {});
  ASSERT_TRUE(r.completed);
  EXPECT_LT(r.errors.column("error_shear_stress").back(), 1e-5);
  EXPECT_LT(r.errors.column("error_normal_stress").back(), 1e-5);
  EXPECT_NEAR(measurement(r, "shear_stress") / 15.5992e6, 1.0, 1e-5);
}

#ifdef MPMVV_HAVE_SUNDIALS
// The neo-Hookean bar at 50 % stretch under its exact dead load, CPDI, 32
// cells: measured errors of the lateral stretch and the axial stress 1.6e-4
// and 2.2e-4 (16 cells: 6.9e-4, 8.5e-4; 64 cells: 3.3e-5, 5.7e-5). Bound 5e-4.
TEST(ExactScenes, NeoHookeanBarReachesItsStretch) {
  const SceneRun r = run_scene("neo-hookean-bar", {"cells=32"});
  ASSERT_TRUE(r.completed);
  EXPECT_LT(r.errors.column("error_lateral_stretch").back(), 5e-4);
  EXPECT_LT(r.errors.column("error_axial_stress").back(), 5e-4);
  EXPECT_NEAR(measurement(r, "axial_stretch"), 1.5, 5e-4);
}
#endif

#ifdef MPMVV_HAVE_FFTW
// The fixed-free bar in its first mode, CPDI: the period error falls at second
// order with h (measured 1.28e-3, 3.15e-4, 7.83e-5 on 16, 32, 64 cells).
TEST(ExactScenes, VibratingBarPeriodConvergesAtSecondOrder) {
  std::vector<double> error;
  for (int cells : {16, 32, 64}) {
    const SceneRun r = run_scene("vibrating-bar", {"cells=" + std::to_string(cells)});
    ASSERT_TRUE(r.completed);
    error.push_back(r.errors.column("error_period").back());
  }
  expect_halving_orders_near_two(error);
}
#endif

#if defined(MPMVV_HAVE_FFTW) && defined(MPMVV_HAVE_SUNDIALS)
// Soft against stiff: the bar of a steel layer and one a hundred times softer,
// the interface on a cell line, CPDI: the period error falls at second order
// (measured over five periods 5.33e-3, 1.30e-3, 3.17e-4 on 16, 32, 64 cells;
// here over two). With the second layer as stiff as the first it is the
// one-layer bar's period, 4 L / c.
TEST(ExactScenes, LayeredBarPeriodConvergesAtSecondOrder) {
  std::vector<double> error;
  for (int cells : {16, 32, 64}) {
    const SceneRun r = run_scene("layered-bar", {"cells=" + std::to_string(cells), "end_time=0.0068",
                                                 "output_times=[0.0034, 0.0068]"});
    ASSERT_TRUE(r.completed);
    error.push_back(r.errors.column("error_period").back());
  }
  expect_halving_orders_near_two(error);
  const SceneRun equal = run_scene("layered-bar", {"stiffness_ratio=1", "end_time=0.0014", "output_times=[0.0014]"});
  EXPECT_NEAR(measurement(equal, "period_exact") / (4.0 / std::sqrt((119.42e9 + 2 * 79.615e9) / 7850.0)), 1.0, 1e-12);
}
#endif

// Frictionless contact with a rigid master (solver/contact.hpp): a block
// falling at 1 m/s and sliding at 0.5 m/s onto a fixed floor stops falling at
// the floor without crossing it (no domain more than 1e-6 h below it), keeps
// its sliding momentum (no friction), and the floor's force is upward.
TEST(Contact, BlockLandsOnAFloorWithoutCrossingOrFriction) {
  for (Method method : {Method::linear, Method::gimp, Method::cpdi}) {
    Model m = block(method);
    for (Vec2& v : m.particles.velocity) v = Vec2(0.5, -1.0);
    SceneStages stages;
    mpmvv::RigidBody floor;
    floor.kind = mpmvv::RigidBody::Kind::half_plane;
    floor.point = Vec2(0.0, 4.0 - 0.02);  // just below the block's bottom at y = 4
    floor.outward = Vec2(0.0, 1.0);
    floor.displacement = [](double) { return Vec2::Zero(); };
    stages.contact = floor;
    auto stepper = mpmvv::make_stepper(std::move(m), SolverOptions{method, Scheme::usl}, kSolid, stages);
    const double dt = 2e-3;  // cfl 0.13 at c = 63 m/s, h = 1
    double lowest = 1.0, upward = 0.0;
    for (int k = 0; k < 200; ++k) {
      stepper->step(k * dt, dt, dt);
      const Particles& P = stepper->model().particles;
      for (std::size_t p = 0; p < P.size(); ++p) {
        const double half = method == Method::linear ? 0.0 : 0.25 * P.deformation_gradient[p](1, 1);
        lowest = std::min(lowest, P.position[p].y() - half - floor.point.y());
      }
      upward += stepper->contact_forces().total.y() * dt;
      EXPECT_EQ(stepper->contact_forces().total.x(), 0.0);
    }
    const Particles& P = stepper->model().particles;
    Vec2 momentum = Vec2::Zero();
    double mass = 0.0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      momentum += P.mass[p] * P.velocity[p];
      mass += P.mass[p];
    }
    EXPECT_GT(lowest, -1e-6) << mpmvv::to_string(method);
    EXPECT_NEAR(momentum.x() / mass, 0.5, 1e-12) << mpmvv::to_string(method);
    EXPECT_GT(upward, 0.9 * mass) << mpmvv::to_string(method);  // at least stopped the fall
  }
}

// Hertz contact on the coarsest mesh of the hertz-cylinder suite (25 cells,
// a / h = 2): measured half-width 12.7 % short of Hertz at the measured load
// and peak pressure 0.25 % off (50 cells: 0.94 % and 0.99 %; 100 cells:
// see the suite). Band: the load within the range of the finer meshes
// (22.5 to 24.6 MN/m), half-width error under 15 %, peak pressure under 2 %.
TEST(ExactScenes, HertzCylinderOnACoarseMesh) {
  const SceneRun r = run_scene("hertz-cylinder", {"cells=25"});
  ASSERT_TRUE(r.completed);
  EXPECT_GT(measurement(r, "load"), 22.0e6);
  EXPECT_LT(measurement(r, "load"), 25.0e6);
  EXPECT_LT(r.errors.column("error_half_width").back(), 0.15);
  EXPECT_LT(r.errors.column("error_peak_pressure").back(), 0.02);
}

// The Hertz sphere in r-z on the coarsest mesh of its study in the hertz
// suite (25 cells, a / h = 2.3): the load within 10 % of the finer meshes'
// (1.40 MN at 50 cells, 1.35 MN at 100; 1.52 MN measured here), the contact
// radius 13.6 % short of Hertz at the measured load (3.3 % at 50 cells, 1.5 %
// at 100): band under 15 %; the largest shear on the axis Hertz's 0.310 p0 at
// 0.481 a for nu = 0.3, and the measured one within 10 % of it (0.317 p0).
TEST(ExactScenes, HertzSphereOnACoarseMesh) {
  const SceneRun r = run_scene("hertz-sphere", {"cells=25"});
  ASSERT_TRUE(r.completed);
  EXPECT_GT(measurement(r, "load"), 1.25e6);
  EXPECT_LT(measurement(r, "load"), 1.6e6);
  EXPECT_LT(r.errors.column("error_half_width").back(), 0.15);
  EXPECT_NEAR(measurement(r, "largest_shear_over_p0_exact"), 0.310, 0.001);
  EXPECT_NEAR(measurement(r, "largest_shear_depth_over_a_exact"), 0.481, 0.001);
  EXPECT_NEAR(measurement(r, "largest_shear_over_p0") / 0.310, 1.0, 0.1);
}

// Two bodies in frictionless contact through their own grid fields
// (multi-velocity contact): two blocks of 8 x rows particles meeting head-on at
// 1 m/s each while sliding past each other at 0.3 m/s conserve the total
// momentum, do not pass through each other, and bounce (each block's normal
// momentum changes sign). Frictionless but for the corners, where the normal
// from the mass gradients tilts: the tangential momentum a block keeps was
// measured 0.867 with 8 rows, 0.933 with 16, 0.966 with 32 (the loss halves
// as the edge doubles). Band: above 0.85 with 8 rows, and the loss with 16
// rows between 0.4 and 0.6 of that with 8.
namespace {

double collide_blocks(int rows) {
  Model m;
  m.grid = GridGeometry::walled(Vec2::Zero(), 1.0, 20, 8 + rows);
  Particles& P = m.particles;
  for (int b = 0; b < 2; ++b)
    for (int j = 0; j < rows; ++j)
      for (int i = 0; i < 8; ++i) P.reference_position.push_back(Vec2(4.25 + 0.5 * i + 4.5 * b, 4.25 + 0.5 * j));
  const std::vector<Vec2> X = P.reference_position;
  const std::size_t n = X.size(), half = n / 2;
  P.resize(n);
  P.reference_position = X;
  P.position = X;
  for (std::size_t p = 0; p < n; ++p) {
    P.reference_volume[p] = P.volume[p] = 0.25;
    P.mass[p] = 250.0;
    P.velocity[p] = p < half ? Vec2(1.0, 0.3) : Vec2(-1.0, -0.3);
  }
  P.half_size.assign(n, Vec2(0.25, 0.25));
  SceneStages stages;
  stages.second_body = half;
  auto stepper = mpmvv::make_stepper(std::move(m), SolverOptions{Method::cpdi, Scheme::usl}, kSolid, stages);
  auto momentum = [&](std::size_t first, std::size_t last) {
    const Particles& Q = stepper->model().particles;
    Vec2 sum = Vec2::Zero();
    for (std::size_t p = first; p < last; ++p) sum += Q.mass[p] * Q.velocity[p];
    return sum;
  };
  const Vec2 start_a = momentum(0, half);
  const double dt = 2e-3;
  double closest = 1.0, contact_impulse = 0.0;
  for (int k = 0; k < 1200; ++k) {
    stepper->step(k * dt, dt, dt);
    const Particles& Q = stepper->model().particles;
    double right_of_a = -1e9, left_of_b = 1e9;
    for (std::size_t p = 0; p < half; ++p) right_of_a = std::max(right_of_a, Q.position[p].x());
    for (std::size_t p = half; p < n; ++p) left_of_b = std::min(left_of_b, Q.position[p].x());
    closest = std::min(closest, left_of_b - right_of_a);
    contact_impulse += std::abs(stepper->contact_forces().total.x()) * dt;
    const Vec2 total = momentum(0, n);
    EXPECT_NEAR(total.x(), 0.0, 1e-9 * start_a.norm());
    EXPECT_NEAR(total.y(), 0.0, 1e-9 * start_a.norm());
  }
  EXPECT_GT(closest, 0.0) << rows;
  EXPECT_GT(contact_impulse, start_a.x()) << rows;
  const Vec2 end_a = momentum(0, half);
  EXPECT_LT(end_a.x(), 0.0) << rows;  // bounced
  return end_a.y() / start_a.y();
}

}  // namespace

TEST(Contact, TwoBlocksCollideWithoutFrictionOrInterpenetration) {
  const double kept8 = collide_blocks(8), kept16 = collide_blocks(16);
  EXPECT_GT(kept8, 0.85);
  EXPECT_LE(kept8, 1.0);
  EXPECT_GT((1.0 - kept16) / (1.0 - kept8), 0.4);
  EXPECT_LT((1.0 - kept16) / (1.0 - kept8), 0.6);
}

// The B-spline support reaches a node past a wall when a particle comes
// within half a cell (quadratic) or a cell (cubic) of it, where the mirror
// walls would drop the particle's share on the ghost node
// (shape/bspline.hpp). A body that far clear of the walls runs; one closer is
// refused by name before the run starts.
TEST(Walls, BsplinesKeepTheirParticlesClearOfTheWalls) {
  for (const auto& [method, clearance] : {std::pair{Method::bspline, 0.5}, std::pair{Method::bspline_cubic, 1.0}}) {
    SCOPED_TRACE(mpmvv::to_string(method));
    const mpmvv::SolverOptions options{method, Scheme::usl};
    EXPECT_NO_THROW(mpmvv::make_stepper(block(method), options, kSolid, nullptr));
    Model near = block(method);
    near.particles.position[0] = near.grid.wall_lower() + Vec2(clearance - 0.1, 4.25) * near.grid.h;
    try {
      mpmvv::make_stepper(near, options, kSolid, nullptr);
      ADD_FAILURE() << "a particle " << clearance - 0.1 << " cells from a wall was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("of a wall, where its support would reach the mirrored ghost nodes"),
                std::string::npos)
          << e.what();
    }
    near.particles.position[0] = near.grid.wall_lower() + Vec2(clearance, 4.25) * near.grid.h;
    EXPECT_NO_THROW(mpmvv::make_stepper(near, options, kSolid, nullptr));
  }
}
