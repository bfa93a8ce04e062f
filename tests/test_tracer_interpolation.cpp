// Tracers placed from an external program's particles (tools/app/scene/
// tracer_interpolation.hpp): a quadratic displacement is reproduced to
// round-off on scattered particles, at the body's edge as inside; a smooth
// one to the third order in the particle spacing; a tracer the particles do
// not surround, and particles that cannot carry a quadratic fit, are named.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "tools/app/scene/tracer_interpolation.hpp"

namespace {

using mpmvv::Vec2;
using mpmvv::app::interpolated_tracers;
using mpmvv::app::TracerInterpolationError;

struct Cloud {
  std::vector<Vec2> X, x;
  std::vector<double> V0;
};

// n x n particles in the unit square, each moved off its cell centre by up
// to a quarter spacing (a program's particles need not sit on a lattice),
// then displaced by u.
template <class Motion>
Cloud cloud(int n, Motion u) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  Cloud c;
  const double s = 1.0 / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vec2 X((i + 0.5 + jitter(random)) * s, (j + 0.5 + jitter(random)) * s);
      c.X.push_back(X);
      c.x.push_back(X + u(X));
      c.V0.push_back(s * s);
    }
  return c;
}

// Inside, near an edge and at a corner of the particles' square.
const std::vector<Vec2> kTracers = {{0.5, 0.5}, {0.31, 0.77}, {0.02, 0.4}, {0.6, 0.99}, {0.01, 0.01}};

TEST(TracerInterpolation, ReproducesAQuadraticDisplacement) {
  const auto u = [](const Vec2& X) {
    return Vec2(0.01 + 0.2 * X.x() - 0.1 * X.y() + 0.3 * X.x() * X.x() - 0.2 * X.x() * X.y(),
                -0.02 + 0.05 * X.x() + 0.4 * X.y() * X.y() + 0.1 * X.x() * X.y());
  };
  const Cloud c = cloud(20, u);
  const std::vector<Vec2> x = interpolated_tracers(c.X, c.x, c.V0, kTracers);
  ASSERT_EQ(x.size(), kTracers.size());
  for (std::size_t t = 0; t < x.size(); ++t)
    EXPECT_LT((x[t] - (kTracers[t] + u(kTracers[t]))).norm(), 1e-14) << "tracer " << t;
}

TEST(TracerInterpolation, ASmoothDisplacementToTheThirdOrder) {
  const double pi = std::numbers::pi;
  const auto u = [pi](const Vec2& X) {
    return Vec2(0.05 * std::sin(pi * X.x()) * std::sin(2.0 * pi * X.y()), 0.03 * std::cos(1.5 * pi * X.x() * X.y()));
  };
  std::vector<double> worst;
  for (int n : {16, 32, 64}) {
    const Cloud c = cloud(n, u);
    const std::vector<Vec2> x = interpolated_tracers(c.X, c.x, c.V0, kTracers);
    double e = 0.0;
    for (std::size_t t = 0; t < x.size(); ++t) e = std::max(e, (x[t] - (kTracers[t] + u(kTracers[t]))).norm());
    worst.push_back(e);
    std::printf("spacing 1/%d: largest tracer error %.3g m\n", n, e);
  }
  // Quadratic fits leave the cubic terms: the error falls as s^3 (8x per halving).
  for (std::size_t k = 0; k + 1 < worst.size(); ++k) {
    const double order = std::log2(worst[k] / worst[k + 1]);
    EXPECT_GT(order, 2.5) << "spacings 1/" << (16 << k) << " and 1/" << (32 << k) << ": " << worst[k] << ", "
                          << worst[k + 1];
  }
  EXPECT_LT(worst.back(), 1e-5);  // 0.05 m of motion, spacing 1/64
}

std::string refusal(const Cloud& c, const std::vector<Vec2>& tracers) {
  try {
    interpolated_tracers(c.X, c.x, c.V0, tracers);
  } catch (const TracerInterpolationError& e) {
    return e.what();
  }
  return "(placed)";
}

TEST(TracerInterpolation, WhatCannotBePlacedIsNamed) {
  const Cloud c = cloud(12, [](const Vec2&) { return Vec2(0.0, 0.0); });
  const std::string far = refusal(c, {{0.5, 0.5}, {3.0, 0.5}});
  EXPECT_NE(far.find("tracer 1 at X = (3, 0.5)"), std::string::npos) << far;
  EXPECT_NE(far.find("the particles do not cover the body there"), std::string::npos) << far;
  // Particles on one line carry no quadratic in two variables.
  Cloud line;
  for (int i = 0; i < 200; ++i) {  // close along the line, each as large as a 1/20 square
    line.X.emplace_back(i / 200.0, 0.5);
    line.x.push_back(line.X.back());
    line.V0.push_back(1.0 / 400.0);
  }
  const std::string flat = refusal(line, {{0.5, 0.5}});
  EXPECT_NE(flat.find("lie on a line or a conic"), std::string::npos) << flat;
  Cloud few = c;
  few.X.resize(10), few.x.resize(10), few.V0.resize(10);
  EXPECT_NE(refusal(few, {{0.1, 0.1}}).find("10 particles with a positive reference volume"), std::string::npos);
}

}  // namespace
