// CPDI domains under the explicit step: they follow F (eq. 1.97), split in
// halves that tile them when stretched, and turn to stay open under shear
// (corner domains: test_cpdi_corners.cpp).
#include <gtest/gtest.h>

#include "solver_models.hpp"
#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "solver/explicit_stepper.hpp"
#include "solver/io/state_archive.hpp"
#include "solver/parallel.hpp"
#include "solver/domain_angle.hpp"
#include "solver/domain_corners.hpp"
#include <map>
#include "solver/shape/cpdi.hpp"
#include "solver/split.hpp"
#include "solver/time_loop.hpp"

namespace {

using namespace mpmvv::testing::solver_models;  // the models and the solver's names they use

// ---------------------------------------------------------------- CPDI domains

// After steps that shear and stretch the body, each CPDI domain is still
// s_p = F_p diag(l_p) (eq. 1.97) and its corner polygon has the particle's
// volume V_p = det(F_p) V_p0 (eq. 1.75).
TEST(CpdiDomain, FollowsTheDeformationGradientAfterSteps) {
  Model model = disk_model(Method::cpdi);
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = Vec2(0.3 * x.y() + 0.1 * x.x(), -0.05 * x.y());
  }
  const double dt = stable_step(model);
  auto stepper = mpmvv::make_stepper(std::move(model), SolverOptions{Method::cpdi, Scheme::usl},
                                     MaterialModel{kSolid}, nullptr);
  advance(*stepper, 10, dt);
  const Particles& P = stepper->model().particles;
  const mpmvv::CpdiShape shape = mpmvv::CpdiShape::bind(stepper->model().grid, P);
  double largest_shear = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Mat2& F = P.deformation_gradient[p];
    largest_shear = std::max(largest_shear, std::abs(F(0, 1)));
    const Mat2 expected = F * P.half_size[p].asDiagonal();
    const Mat2 s = shape.domain(p);
    EXPECT_LT((s - expected).norm(), 1e-15 * expected.norm());
    double twice_area = 0.0;
    for (int c = 0; c < 4; ++c) {
      const Vec2 a = shape.corner(p, s, c), b = shape.corner(p, s, (c + 1) % 4);
      EXPECT_LT((a - (P.position[p] + mpmvv::CpdiShape::corner_xi[c] * s.col(0) +
                      mpmvv::CpdiShape::corner_eta[c] * s.col(1))).norm(), 1e-15);
      twice_area += a.x() * b.y() - b.x() * a.y();
    }
    // Coordinates of order 1 m give areas of order 4e-3 m^2: 1e-10 relative
    // covers the cancellation of the shoelace sum.
    EXPECT_NEAR(0.5 * twice_area, P.volume[p], 1e-10 * P.volume[p]);
  }
  // The steps really sheared the domains (measured max |F_xy| about 0.1).
  EXPECT_GT(largest_shear, 1e-2);
}

// ---------------------------------------------------------------- splitting stretched domains

// Splitting (solver/split.hpp) replaces a particle by halves that tile it:
// mass, reference volume, momentum and the first moment of mass (sum m x and
// sum m X) are unchanged, every domain ends no longer than the limit, and
// each half's domain corners lie on its parent's domain.
TEST(CpdiSplit, HalvesTileTheParentAndConserveMassAndMomentum) {
  Particles P;
  P.resize(2);
  P.half_size = {Vec2(0.05, 0.05), Vec2(0.05, 0.05)};
  Mat2 shear;
  shear << 1.0, 4.5, 0.0, 1.0;  // r_2 = (4.5, 1) l: 0.46 m long
  Mat2 stretch;
  stretch << 2.5, 0.3, -0.4, 0.6;
  P.deformation_gradient = {shear, stretch};
  P.position = {Vec2(0.2, -0.1), Vec2(-0.5, 0.7)};
  P.reference_position = {Vec2(0.1, -0.2), Vec2(-0.4, 0.6)};
  P.velocity = {Vec2(1.0, -2.0), Vec2(0.3, 0.25)};
  for (std::size_t p = 0; p < 2; ++p) {
    P.stress[p] = Mat2::Identity() * double(p + 1);
    P.reference_volume[p] = 4.0 * 0.05 * 0.05;
    P.volume[p] = mpmvv::determinant(P.deformation_gradient[p]) * P.reference_volume[p];
    P.mass[p] = 1000.0 * P.reference_volume[p];
  }
  auto totals = [](const Particles& Q) {
    struct {
      double mass = 0.0, volume = 0.0;
      Vec2 momentum = Vec2::Zero(), moment = Vec2::Zero(), reference_moment = Vec2::Zero();
    } t;
    for (std::size_t p = 0; p < Q.size(); ++p) {
      t.mass += Q.mass[p];
      t.volume += Q.volume[p];
      t.momentum += Q.mass[p] * Q.velocity[p];
      t.moment += Q.mass[p] * Q.position[p];
      t.reference_moment += Q.mass[p] * Q.reference_position[p];
    }
    return t;
  };
  const auto before = totals(P);
  const Particles parent = P;
  const double limit = 0.12;
  const std::size_t splits = mpmvv::split_long_domains(P, limit);
  EXPECT_EQ(splits, P.size() - 2);
  EXPECT_GE(splits, 4u);  // the 0.46 m shear domain alone needs two halvings
  const auto after = totals(P);
  EXPECT_NEAR(after.mass, before.mass, 1e-14 * before.mass);
  EXPECT_NEAR(after.volume, before.volume, 1e-14 * before.volume);
  EXPECT_LT((after.momentum - before.momentum).norm(), 1e-14 * before.momentum.norm());
  EXPECT_LT((after.moment - before.moment).norm(), 1e-14);
  EXPECT_LT((after.reference_moment - before.reference_moment).norm(), 1e-14);
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Mat2 s = P.deformation_gradient[p] * P.half_size[p].asDiagonal();
    EXPECT_LE(2.0 * s.col(0).norm(), limit);
    EXPECT_LE(2.0 * s.col(1).norm(), limit);
    // Which parent: the one whose F it carries; the half's centre and its
    // reference centre are on the parent's affine map, x - x_q = F (X - X_q).
    const std::size_t q = P.deformation_gradient[p] == shear ? 0 : 1;
    EXPECT_LT((P.position[p] - parent.position[q] -
               parent.deformation_gradient[q] * (P.reference_position[p] - parent.reference_position[q]))
                  .norm(),
              1e-14);
    EXPECT_EQ(P.velocity[p], parent.velocity[q]);
    EXPECT_EQ(P.stress[p], parent.stress[q]);
  }
}

// A run that splits keeps going over its growing particle set: the sheared
// disk of the domain tests, with domains limited to half a cell, completes,
// ends with more particles, and keeps its mass and momentum.
TEST(CpdiSplit, RunWithSplittingCompletesAndConserves) {
  Model model = disk_model(Method::cpdi);
  for (std::size_t p = 0; p < model.particles.size(); ++p) {
    const Vec2 x = model.particles.position[p];
    model.particles.velocity[p] = Vec2(0.3 * x.y() + 0.1 * x.x(), -0.05 * x.y());
  }
  const std::size_t n0 = model.particles.size();
  const Vec2 momentum = total_momentum(model.particles);
  double mass = 0.0;
  for (double m : model.particles.mass) mass += m;
  SolverOptions options{Method::cpdi, Scheme::usl};
  options.split_domains_beyond = 0.5;  // the seeded domains are exactly half a cell
  auto stepper = mpmvv::make_stepper(std::move(model), options, MaterialModel{kSolid}, nullptr);
  NullObserver observer;
  const mpmvv::RunOutcome o = mpmvv::run_time_loop(*stepper, short_run(0.5), observer);
  EXPECT_TRUE(o.completed) << o.failure_reason << " " << o.failure_detail;
  const Particles& P = stepper->model().particles;
  EXPECT_GT(P.size(), n0);
  double mass_after = 0.0;
  for (double m : P.mass) mass_after += m;
  EXPECT_NEAR(mass_after, mass, 1e-12 * mass);
  EXPECT_LT((total_momentum(P) - momentum).norm(), 1e-10 * total_momentum_magnitude(P));
  EXPECT_GT(o.particle_steps, static_cast<long long>(o.steps * n0));
}

// Splitting is for CPDI in plane strain with one body.
TEST(CpdiSplit, MakeStepperRefusesSplittingElsewhere) {
  SolverOptions gimp{Method::gimp, Scheme::usl};
  gimp.split_domains_beyond = 1.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::gimp), gimp, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  SolverOptions negative{Method::cpdi, Scheme::usl};
  negative.split_domains_beyond = -1.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), negative, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
}

// ---------------------------------------------------------------- domain angle

namespace {

// The cosine of the angle between the columns of s.
double side_cosine(const Mat2& s) { return s.col(0).dot(s.col(1)) / (s.col(0).norm() * s.col(1).norm()); }

// Second moment of area of the domain x_p + s xi, xi in [-1, 1]^2, about o.
Mat2 second_moment(const Mat2& s, const Vec2& centre, const Vec2& o) {
  const double area = 4.0 * std::abs(mpmvv::determinant(s));
  return area / 3.0 * s * s.transpose() + area * (centre - o) * (centre - o).transpose();
}

// Four domains: sheared to 18 degrees (gamma = 3), stretched and skewed to
// 73 degrees, barely sheared (79 degrees) and unsheared.
Particles domains_to_turn() {
  Particles P;
  P.resize(4);
  P.half_size.assign(4, Vec2(0.05, 0.04));
  Mat2 shear, skew, mild;
  shear << 1.0, 3.0, 0.0, 1.0;
  skew << 2.5, 0.3, -0.4, 0.6;
  mild << 1.0, 0.2, 0.0, 1.0;
  P.deformation_gradient = {shear, skew, mild, Mat2::Identity()};
  for (std::size_t p = 0; p < 4; ++p) {
    P.position[p] = Vec2(0.3 * double(p), -0.2);
    P.reference_position[p] = Vec2(0.25 * double(p), -0.1);
    P.reference_volume[p] = 4.0 * 0.05 * 0.04;
    P.volume[p] = mpmvv::determinant(P.deformation_gradient[p]) * P.reference_volume[p];
    P.mass[p] = 1000.0 * P.reference_volume[p];
  }
  return P;
}

}  // namespace

// A domain whose sides meet below the set angle is turned within the
// parallelograms of its centroid, area and second moment of area (in both
// configurations) until they meet at that angle, by the smallest turn; the
// others are left as they are; a second pass finds nothing left to turn.
TEST(CpdiDomainAngle, TurnKeepsTheMomentsAndOpensTheSidesToTheSetAngle) {
  Particles P = domains_to_turn();
  mpmvv::start_domain_axes(P);
  const Particles before = P;
  const double max_cos = std::cos(30.0 * std::numbers::pi / 180.0);
  EXPECT_EQ(mpmvv::open_sheared_domains(P, max_cos), 1u);  // only the 18-degree one is below 30 degrees
  const double wide = std::cos(75.0 * std::numbers::pi / 180.0);
  Particles P75 = before;
  EXPECT_EQ(mpmvv::open_sheared_domains(P75, wide), 2u);  // and the 73-degree one below 75
  for (const auto& [after, limit] : {std::pair<const Particles*, double>{&P, max_cos}, {&P75, wide}}) {
    for (std::size_t p = 0; p < 4; ++p) {
      SCOPED_TRACE("particle " + std::to_string(p) + ", limit " + std::to_string(limit));
      const Mat2 A0 = before.domain_axes[p], A = after->domain_axes[p];
      const Mat2 s0 = before.deformation_gradient[p] * A0, s = after->deformation_gradient[p] * A;
      const Vec2 x = after->position[p];
      EXPECT_LT((second_moment(s, x, x) - second_moment(s0, x, x)).norm(), 1e-14 * second_moment(s0, x, x).norm());
      EXPECT_LT((A * A.transpose() - A0 * A0.transpose()).norm(), 1e-14 * (A0 * A0.transpose()).norm());
      EXPECT_NEAR(mpmvv::determinant(A), mpmvv::determinant(A0), 1e-15);
      if (std::abs(side_cosine(s0)) > limit) {
        EXPECT_NEAR(std::abs(side_cosine(s)), limit, 1e-12);
        // The smallest turn: nine tenths of it leave the sides closer than the limit.
        const Mat2 W = mpmvv::inverse(A0) * A;
        const double t = 0.9 * std::atan2(W(1, 0), W(0, 0));
        Mat2 part;
        part << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
        EXPECT_GT(std::abs(side_cosine(s0 * part)), limit);
      } else {
        EXPECT_EQ(A, A0);
      }
    }
  }
  const Particles turned = P;
  mpmvv::open_sheared_domains(P, max_cos);
  for (std::size_t p = 0; p < 4; ++p)
    EXPECT_LT((P.domain_axes[p] - turned.domain_axes[p]).norm(), 1e-14) << "particle " << p;
}

// A turned domain splits along its own half-vectors: the halves' centres lie
// on the parent's affine map, x - x_p = F (X - X_p), and together they carry
// the parent's mass and second moment of area about its centroid.
TEST(CpdiDomainAngle, TurnedDomainSplitsIntoHalvesThatTileIt) {
  Particles P = domains_to_turn();
  mpmvv::start_domain_axes(P);
  mpmvv::open_sheared_domains(P, std::cos(60.0 * std::numbers::pi / 180.0));
  const Particles parent = P;
  const double limit = 0.15;
  const std::size_t splits = mpmvv::split_long_domains(P, limit);
  EXPECT_GE(splits, 2u);
  ASSERT_EQ(P.domain_axes.size(), P.size());
  for (std::size_t q = 0; q < parent.size(); ++q) {
    SCOPED_TRACE("parent " + std::to_string(q));
    const Vec2 xq = parent.position[q];
    const Mat2 sq = parent.deformation_gradient[q] * parent.domain_axes[q];
    Mat2 moment = Mat2::Zero();
    double mass = 0.0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      if (P.deformation_gradient[p] != parent.deformation_gradient[q]) continue;
      const Mat2 s = P.deformation_gradient[p] * P.domain_axes[p];
      EXPECT_LE(2.0 * s.col(0).norm(), limit * (1.0 + 1e-14));
      EXPECT_LE(2.0 * s.col(1).norm(), limit * (1.0 + 1e-14));
      EXPECT_LT((P.position[p] - xq - parent.deformation_gradient[q] *
                                         (P.reference_position[p] - parent.reference_position[q]))
                    .norm(),
                1e-14);
      moment += second_moment(s, P.position[p], xq);
      mass += P.mass[p];
    }
    EXPECT_NEAR(mass, parent.mass[q], 1e-14 * parent.mass[q]);
    EXPECT_LT((moment - second_moment(sq, xq, xq)).norm(), 1e-12 * second_moment(sq, xq, xq).norm());
  }
}

// The angle is for CPDI in plane strain under the updated formulation, from
// 0 (never) to below a right angle.
TEST(CpdiDomainAngle, MakeStepperRefusesTheAngleElsewhere) {
  SolverOptions gimp{Method::gimp, Scheme::usl};
  gimp.min_domain_angle = 30.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::gimp), gimp, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  for (double angle : {-1.0, 90.0}) {
    SolverOptions cpdi{Method::cpdi, Scheme::usl};
    cpdi.min_domain_angle = angle;
    EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), cpdi, MaterialModel{kSolid}, nullptr),
                 std::invalid_argument)
        << angle;
  }
  SolverOptions total{Method::cpdi, Scheme::usl};
  total.formulation = mpmvv::Formulation::total;
  total.min_domain_angle = 30.0;
  EXPECT_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), total, MaterialModel{kSolid}, nullptr),
               std::invalid_argument);
  SolverOptions fine{Method::cpdi, Scheme::usl};
  fine.min_domain_angle = 30.0;
  EXPECT_NO_THROW(mpmvv::make_stepper(disk_model(Method::cpdi), fine, MaterialModel{kSolid}, nullptr));
}

}  // namespace
