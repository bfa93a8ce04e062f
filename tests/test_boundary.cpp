// Boundary conditions (solver/boundary.hpp, solver/rest_points.hpp):
// prescribed node motion follows u(t) exactly and its reaction balances the
// grid force; rest points hold the field; a traction puts its total force into
// the body's momentum; damping takes energy out; the crossing period of a sine.
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

// apply_constraints sets the prescribed component to (u(t + dt) - u(t)) / dt,
// leaves the other component alone, and returns sum (m a - f) over its nodes.
TEST(Boundary, ConstraintSetsVelocityAndReturnsReaction) {
  GridFields g;
  g.resize(3);
  for (int i = 0; i < 3; ++i) {
    g.mass[i] = 2.0;
    g.momentum[i] = Vec2(2.0, 4.0);  // velocity (1, 2) before the kick
    g.force[i] = Vec2(6.0, 8.0);
    g.velocity[i] = Vec2(7.0, 9.0);
    g.acceleration[i] = Vec2(3.0, 4.0);
  }
  const std::vector<NodeConstraint> c = {{{0, 2}, 0, [](double t) { return 0.5 * t * t; }}};
  const double t = 1.0, dt = 0.1, kick = 0.1;
  const std::vector<double> reactions = mpmvv::apply_constraints(c, t, dt, kick, g);
  const double v = (0.5 * 1.1 * 1.1 - 0.5) / dt;  // 1.05
  for (int i : {0, 2}) {
    EXPECT_DOUBLE_EQ(g.velocity[i].x(), v);
    EXPECT_DOUBLE_EQ(g.acceleration[i].x(), (v - 1.0) / kick);
    EXPECT_EQ(g.velocity[i].y(), 9.0);
  }
  EXPECT_EQ(g.velocity[1].x(), 7.0);
  ASSERT_EQ(reactions.size(), 1u);
  EXPECT_NEAR(reactions[0], 2.0 * (2.0 * (v - 1.0) / kick - 6.0), 1e-12);
}

// Rest points (rest_points.hpp): after the projection the grid field, read
// with the quadratic B-splines, is zero at every point; the correction is the
// nearest in kinetic energy (M dv lies in the span of the rows, C^T lambda);
// the acceleration changes with the velocity; nodes a constraint prescribes
// keep their value; and a field already at rest there is left as it is.
TEST(Boundary, RestPointsHoldTheFieldAtRestNearestInKineticEnergy) {
  const GridGeometry grid = GridGeometry::walled(Vec2(0.0, 0.0), 0.1, 12, 12);
  std::vector<Vec2> points;
  for (int k = 0; k < 9; ++k) {
    const double a = 0.7 * k;
    points.push_back(Vec2(0.6 + 0.3 * std::cos(a), 0.6 + 0.3 * std::sin(a)));
  }
  const auto rows = mpmvv::basis_rows<mpmvv::BsplineShape>(grid, points);
  ASSERT_EQ(rows.size(), points.size());
  GridFields g;
  g.resize(grid.node_count());
  std::uint64_t state = 12345;
  auto next = [&state] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) * 0x1.0p-53;
  };
  for (std::size_t i = 0; i < grid.node_count(); ++i) {
    g.mass[i] = 0.5 + next();
    g.velocity[i] = Vec2(next() - 0.5, next() - 0.5);
    g.acceleration[i] = Vec2(next(), next());
  }
  // One node the first point weighs is prescribed.
  std::vector<unsigned char> prescribed(2 * grid.node_count(), 0);
  const int fixed = rows[0][0].first;
  prescribed[2 * std::size_t(fixed) + 1] = 1;
  const GridFields before = g;
  mpmvv::RestPoints rest(rows, prescribed);
  const double kick = 0.01;
  rest.apply(g, kick);

  auto field_at = [&](std::size_t b, int axis) {
    double v = 0.0;
    for (const auto& [node, w] : rows[b]) v += w * g.velocity[std::size_t(node)][axis];
    return v;
  };
  for (std::size_t b = 0; b < points.size(); ++b)
    for (int axis : {0, 1}) EXPECT_NEAR(field_at(b, axis), 0.0, 1e-13) << "point " << b << " axis " << axis;
  EXPECT_EQ(g.velocity[std::size_t(fixed)], before.velocity[std::size_t(fixed)]);

  // M dv = C^T lambda for some lambda: least squares leaves no residual.
  std::vector<int> nodes;
  for (const auto& row : rows)
    for (const auto& [node, w] : row)
      if (node != fixed) nodes.push_back(node);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  Eigen::MatrixXd Ct = Eigen::MatrixXd::Zero(Eigen::Index(nodes.size()), Eigen::Index(rows.size()));
  for (std::size_t b = 0; b < rows.size(); ++b)
    for (const auto& [node, w] : rows[b]) {
      const auto at = std::lower_bound(nodes.begin(), nodes.end(), node);
      if (at != nodes.end() && *at == node) Ct(at - nodes.begin(), Eigen::Index(b)) = w;
    }
  for (int axis : {0, 1}) {
    Eigen::VectorXd momentum(Eigen::Index(nodes.size()));
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const std::size_t i = std::size_t(nodes[k]);
      const double dv = g.velocity[i][axis] - before.velocity[i][axis];
      momentum[Eigen::Index(k)] = g.mass[i] * dv;
      EXPECT_NEAR(g.acceleration[i][axis] - before.acceleration[i][axis], dv / kick, 1e-10);
    }
    const Eigen::VectorXd lambda = Ct.colPivHouseholderQr().solve(momentum);
    EXPECT_GT(momentum.norm(), 1e-3);
    EXPECT_LT((Ct * lambda - momentum).norm(), 1e-12 * momentum.norm());
  }
  // Nodes no point weighs keep their motion.
  for (std::size_t i = 0; i < grid.node_count(); ++i) {
    if (!std::binary_search(nodes.begin(), nodes.end(), int(i))) {
      EXPECT_EQ(g.velocity[i], before.velocity[i]);
    }
  }

  const GridFields held = g;
  rest.apply(g, kick);
  for (std::size_t i = 0; i < grid.node_count(); ++i)
    EXPECT_NEAR((g.velocity[i] - held.velocity[i]).norm(), 0.0, 1e-14);
}

// Two rest points whose only node with mass is the same node ask for the same
// thing: their system C M^-1 C^T is singular (rank 1) but consistent, and the
// projection still holds both, setting that node to rest, where a plain
// factorization would give no finite multiplier and end the run.
TEST(Boundary, RedundantRestPointsStillHoldTheField) {
  GridFields g;
  g.resize(8);
  g.mass[5] = 2.0;
  g.velocity[5] = Vec2(1.0, -2.0);
  g.velocity[6] = Vec2(0.5, 0.25);  // no mass: not corrected
  const std::vector<std::vector<std::pair<int, double>>> rows = {{{5, 0.6}, {6, 0.4}}, {{5, 0.3}, {7, 0.7}}};
  mpmvv::RestPoints rest(rows, std::vector<unsigned char>(16, 0));
  ASSERT_NO_THROW(rest.apply(g, 0.01));
  EXPECT_NEAR(g.velocity[5].norm(), 0.0, 1e-10);
  EXPECT_NEAR(g.acceleration[5].x(), -1.0 / 0.01, 1e-6);
  EXPECT_EQ(g.velocity[6], Vec2(0.5, 0.25));
}

// A rest point where the grid basis would leave the grid is refused by name.
TEST(Boundary, RestPointBeyondTheGridIsRefused) {
  const GridGeometry grid = GridGeometry::walled(Vec2(0.0, 0.0), 0.1, 12, 12);
  try {
    (void)mpmvv::basis_rows<mpmvv::BsplineShape>(grid, {Vec2(0.5, 0.5), Vec2(1.4, 0.5)});
    FAIL() << "a point outside the walls was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rest point (1.4, 0.5)"), std::string::npos) << e.what();
  }
}

// A block whose bottom row of nodes is driven along u_y(t) = 1e-3 sin(t):
// after any number of steps of any size the particles that sit on those nodes'
// row have moved by exactly u_y (linear shape functions interpolate the row).
TEST(Boundary, ConstrainedNodesFollowTheirDisplacement) {
  Model m = block(Method::linear);
  std::vector<std::size_t> row;
  for (int i = 0; i < m.grid.nodes_x(); ++i)
    for (int j : {5, 6, 7, 8, 9, 10, 11, 12, 13})
      row.push_back(std::size_t(m.grid.node(i, j)));
  SceneStages stages;
  auto u = [](double t) { return 1e-3 * std::sin(t); };
  stages.constraints.push_back({row, 1, u});
  auto stepper = mpmvv::make_stepper(std::move(m), SolverOptions{Method::linear, Scheme::usl}, kSolid, stages);
  double t = 0.0;
  for (double dt : {1e-3, 3e-3, 2e-3, 5e-4}) {
    stepper->step(t, dt, dt);
    t += dt;
  }
  const Particles& P = stepper->model().particles;
  for (std::size_t p = 0; p < P.size(); ++p)
    EXPECT_NEAR(P.position[p].y() - P.reference_position[p].y(), u(t), 1e-15) << p;
}

// With no other force a traction changes the body's momentum at its total
// force: after the first step (a kick of dt), sum m v = F dt along its direction.
TEST(Boundary, TractionDeliversItsTotalForce) {
  for (Method method : {Method::linear, Method::gimp, Method::cpdi}) {
    Model m = block(method);
    std::vector<std::size_t> loaded;
    std::vector<double> area;
    for (std::size_t p = 0; p < m.particles.size(); ++p)
      if (m.particles.reference_position[p].x() > 7.5) {
        loaded.push_back(p);
        area.push_back(0.5);
      }
    SceneStages stages;
    auto traction = std::make_shared<mpmvv::SurfaceTraction>(loaded, area, Vec2(0.6, 0.8),
                                                             [](double) { return 100.0; });
    stages.body_force = traction;
    auto stepper = mpmvv::make_stepper(std::move(m), SolverOptions{method, Scheme::usl}, kSolid, stages);
    const double dt = 1e-4;
    stepper->step(0.0, dt, dt);
    Vec2 momentum = Vec2::Zero();
    const Particles& P = stepper->model().particles;
    for (std::size_t p = 0; p < P.size(); ++p) momentum += P.mass[p] * P.velocity[p];
    const double F = traction->total_force(0.0);
    EXPECT_DOUBLE_EQ(F, 100.0 * 0.5 * 8);
    EXPECT_NEAR(momentum.x(), 0.6 * F * dt, 1e-12 * F * dt) << mpmvv::to_string(method);
    EXPECT_NEAR(momentum.y(), 0.8 * F * dt, 1e-12 * F * dt) << mpmvv::to_string(method);
  }
}

// Damping takes energy out: a free block started in a shearing motion (about
// three periods of its lowest mode over the run) still swings with much of its
// kinetic energy undamped and keeps almost none of it critically damped (the
// largest kinetic energy over the last hundred steps, against the start).
TEST(Boundary, DampingRemovesEnergy) {
  double remaining[2];
  for (int damped : {0, 1}) {
    Model m = block(Method::cpdi);
    for (std::size_t p = 0; p < m.particles.size(); ++p)
      m.particles.velocity[p] = Vec2(0.01 * (m.particles.reference_position[p].y() - 6.0), 0.0);
    const double start = kinetic_energy(m.particles);
    SceneStages stages;
    // c_s = sqrt(mu / rho) = 31.6 m/s over 4 m: omega about 25 /s.
    stages.damping = damped ? 50.0 : 0.0;
    auto stepper = mpmvv::make_stepper(std::move(m), SolverOptions{Method::cpdi, Scheme::usl}, kSolid, stages);
    const double dt = 0.2 * 0.5 / 55.0;
    double late = 0.0;
    for (int k = 0; k < 400; ++k) {
      stepper->step(k * dt, dt, dt);
      if (k >= 300) late = std::max(late, kinetic_energy(stepper->model().particles));
    }
    remaining[damped] = late / start;
  }
  EXPECT_LT(remaining[1], 1e-3) << remaining[1];
  EXPECT_GT(remaining[0], 0.2) << remaining[0];
}

#ifdef MPMVV_HAVE_FFTW
// The period of a sampled sine from its zero crossings, located by the
// spectrum: exact to far below the sample spacing.
TEST(Boundary, CrossingPeriodOfASine) {
  std::vector<double> t, u;
  const double period = 0.37;
  for (int i = 0; i <= 2000; ++i) {
    t.push_back(2.0 * i / 2000.0);
    u.push_back(std::sin(2.0 * M_PI * t.back() / period + 0.3));
  }
  const double estimate = 1.0 / mpmvv::analytic::dominant_frequency(t, u);
  EXPECT_NEAR(estimate / period, 1.0, 2e-2);
  EXPECT_NEAR(mpmvv::analytic::crossing_period(t, u, estimate) / period, 1.0, 1e-7);
}
#endif
