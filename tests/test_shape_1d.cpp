// uGIMP's weight in one dimension (the hat averaged over the particle, its
// partition of unity, derivative and breakpoints) and the B-splines (closed
// forms, the hats' gradients against the splines').
#include <gtest/gtest.h>

#include "shape_models.hpp"
#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include "solver/particles.hpp"
#include "solver/shape/bspline.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/cpdi_exact.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/linear.hpp"

namespace {

using namespace mpmvv::testing::shape_models;  // the grid, the particles and the names they use

// ---------------------------------------------------------------- GIMP in one dimension

// The uGIMP weight is the hat averaged over the particle, (1/2l) int_{d-l}^{d+l}
// hat(y) dy (eqs. 1.85, 1.86, 1.90). The hat's antiderivative gives that
// average in closed form independently of the five cases of eq. 1.91.
double hat_antiderivative(double y, double h) {
  if (y <= -h) return 0.0;
  if (y <= 0.0) return (y + h) * (y + h) / (2.0 * h);
  if (y <= h) return h - (h - y) * (h - y) / (2.0 * h);
  return h;
}

double averaged_hat(double d, double h, double l) {
  return (hat_antiderivative(d + l, h) - hat_antiderivative(d - l, h)) / (2.0 * l);
}

// eq. 1.91 equals the hat averaged over the particle for random d and l <= h/2.
TEST(GimpWeight1D, MatchesTheHatAveragedOverTheParticle) {
  const double h = 0.5;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> distance(-1.6 * h, 1.6 * h), half(0.01 * h, 0.5 * h);
  for (int k = 0; k < 2000; ++k) {
    const double d = distance(rng), l = half(rng);
    // Both are sums of a few terms of order one; the antiderivative difference
    // divided by 2l loses up to h/l ~ 100 times the round-off.
    EXPECT_NEAR(mpmvv::gimp_weight_1d(d, h, l).weight, averaged_hat(d, h, l), 1e-13)
        << "d = " << d << ", l = " << l;
  }
}

// The 1D weights of all nodes sum to one at random positions and sizes.
TEST(GimpWeight1D, PartitionOfUnity) {
  const double h = 0.5;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> position(2.0, 8.0), half(0.01 * h, 0.5 * h);
  for (int k = 0; k < 2000; ++k) {
    const double xp = position(rng) * h, l = half(rng);
    double sum = 0.0, derivative_sum = 0.0;
    for (int node = 0; node <= 10; ++node) {
      const mpmvv::GimpWeight1D w = mpmvv::gimp_weight_1d(xp - node * h, h, l);
      EXPECT_GE(w.weight, 0.0);
      sum += w.weight;
      derivative_sum += w.derivative;
    }
    EXPECT_NEAR(sum, 1.0, kRoundOff) << "x_p = " << xp << ", l = " << l;
    EXPECT_NEAR(derivative_sum, 0.0, kRoundOff / h) << "x_p = " << xp << ", l = " << l;
  }
}

// The derivative (eq. 1.92) equals a centred difference of the weight (eq. 1.91).
TEST(GimpWeight1D, DerivativeMatchesCentredDifference) {
  const double h = 0.5, step = 1e-7;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> distance(-1.6 * h, 1.6 * h), half(0.01 * h, 0.5 * h);
  double worst = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const double d = distance(rng), l = half(rng);
    const double difference = (mpmvv::gimp_weight_1d(d + step, h, l).weight -
                               mpmvv::gimp_weight_1d(d - step, h, l).weight) / (2.0 * step);
    const double error = std::abs(mpmvv::gimp_weight_1d(d, h, l).derivative - difference);
    worst = std::max(worst, error);
    // The weight is piecewise quadratic with a continuous derivative, so the
    // centred difference is exact up to round-off 1e-16 / step = 1e-9, or
    // off by at most step * max|w''| / 2 = step / (2 h l) when a breakpoint
    // falls within `step` of d: 5e-7 * h / h at l = 0.01 h. 1e-6 / h covers both.
    EXPECT_LT(error, 1e-6 / h) << "d = " << d << ", l = " << l;
  }
  // Measured worst case 4.2e-10 / h (no sample fell next to a breakpoint):
  // the difference really resolves the derivative.
  EXPECT_LT(worst, 1e-8 / h);
}

// The 1D weight is continuous at each breakpoint of eq. 1.91 and vanishes
// outside |d| < h + l.
TEST(GimpWeight1D, ContinuousAtBreakpointsAndCompactlySupported) {
  const double h = 0.5, l = 0.125;
  for (double b : {-h - l, -h + l, -l, l, h - l, h + l}) {
    const double below = mpmvv::gimp_weight_1d(b - 1e-12, h, l).weight;
    const double above = mpmvv::gimp_weight_1d(b + 1e-12, h, l).weight;
    // |w'| <= 1/h, so a jump over 2e-12 is at most 4e-12 when continuous.
    EXPECT_NEAR(below, above, 1e-11) << "breakpoint d = " << b;
  }
  for (double d : {-h - l, -h - l - 1e-3, h + l, h + l + 1e-3, 3.0 * h}) {
    EXPECT_EQ(mpmvv::gimp_weight_1d(d, h, l).weight, 0.0) << "d = " << d;
    EXPECT_EQ(mpmvv::gimp_weight_1d(d, h, l).derivative, 0.0) << "d = " << d;
  }
}

// ---------------------------------------------------------------- B-splines

// The closed forms of the uniform quadratic and cubic B-splines centred on a
// node, r the distance from it in cells (written from the recursion's
// pieces, independently of shape/bspline.hpp).
double closed_form_bspline(int degree, double r) {
  r = std::abs(r);
  if (degree == 2) return r < 0.5 ? 0.75 - r * r : r < 1.5 ? 0.5 * (1.5 - r) * (1.5 - r) : 0.0;
  return r < 1.0 ? (3.0 * r * r * r - 6.0 * r * r + 4.0) / 6.0 : r < 2.0 ? (2.0 - r) * (2.0 - r) * (2.0 - r) / 6.0 : 0.0;
}

// The node weights and gradients of a point, keyed by node.
template <class Shape>
std::map<int, std::pair<double, Vec2>> stencil_at(const GridGeometry& grid, const Vec2& x) {
  const Particles P = particles_at(grid, {x});
  const Shape shape = Shape::bind(grid, P);
  Stencil<Shape::stencil_size> s;
  shape.evaluate(0, s);
  std::map<int, std::pair<double, Vec2>> out;
  for (int k = 0; k < s.count; ++k) out[s.node[k]] = {s.weight[k], s.gradient[k]};
  return out;
}

template <class Shape>
class BsplineTest : public ::testing::Test {};
using Bsplines = ::testing::Types<BsplineShape, CubicBsplineShape>;
TYPED_TEST_SUITE(BsplineTest, Bsplines);

// Each listed weight is the tensor product of the closed-form B-spline at the
// node, its gradient the centred difference of that weight, and every node
// whose B-spline reaches the point is listed.
TYPED_TEST(BsplineTest, WeightsAreTheClosedFormAndGradientsItsDerivative) {
  const int degree = TypeParam::width - 1;
  auto N = [degree](double r) { return closed_form_bspline(degree, r); };
  const GridGeometry grid = small_grid();
  const double step = 1e-6;  // in cells
  double worst_gradient = 0.0;
  for (const Vec2& x : random_interior_positions(grid, 200, 11)) {
    const auto st = stencil_at<TypeParam>(grid, x);
    int reached = 0;
    for (int node = 0; node < int(grid.node_count()); ++node) {
      const Vec2 r = (x - node_position(grid, node)) / grid.h;
      const double w = N(r.x()) * N(r.y());
      if (w > 0.0) ++reached;
      const auto it = st.find(node);
      if (it == st.end()) {
        EXPECT_EQ(w, 0.0) << "node " << node << " is missing from the stencil";
        continue;
      }
      EXPECT_NEAR(it->second.first, w, kRoundOff);
      const Vec2 difference((N(r.x() + step) - N(r.x() - step)) * N(r.y()),
                            N(r.x()) * (N(r.y() + step) - N(r.y() - step)));
      worst_gradient = std::max(worst_gradient, (it->second.second * grid.h - difference / (2.0 * step)).norm());
    }
    EXPECT_LE(reached, TypeParam::stencil_size);
  }
  // Piecewise polynomials with continuous derivatives: the centred difference
  // is exact up to round-off 1e-16 / 1e-6 and a curvature term of 1e-6.
  EXPECT_LT(worst_gradient, 1e-5);
}

// The basis is C1 at least: where the set of covering nodes changes and
// across a cell line, the weights and the gradients of every node are the
// same on both sides, so a particle crossing a cell line sees no jump in its
// gradients. The bilinear hats' gradients jump there by 1 / h.
TYPED_TEST(BsplineTest, WeightsAndGradientsAreContinuousWhereTheStencilChanges) {
  const GridGeometry grid = small_grid();
  for (const Vec2& xi : {Vec2(3.5, 4.37), Vec2(3.61, 4.5), Vec2(3.5, 4.5), Vec2(3.0, 4.37), Vec2(3.0, 4.0)}) {
    const Vec2 x = grid.origin + grid.h * xi;
    const Vec2 hair = Vec2(1e-10, 1e-10) * grid.h;
    auto below = stencil_at<TypeParam>(grid, x - hair), above = stencil_at<TypeParam>(grid, x + hair);
    for (const auto& [node, wg] : below) {
      const auto it = above.find(node);
      const double w_above = it == above.end() ? 0.0 : it->second.first;
      const Vec2 g_above = it == above.end() ? Vec2::Zero() : it->second.second;
      EXPECT_NEAR(wg.first, w_above, 1e-9) << "node " << node;
      EXPECT_LT((wg.second - g_above).norm() * grid.h, 1e-9) << "node " << node;
    }
    for (const auto& [node, wg] : above) {
      if (!below.count(node)) {
        EXPECT_NEAR(wg.first, 0.0, 1e-9) << "node " << node;
      }
    }
  }
}

// The same comparison on the bilinear hats finds their jump on a cell line:
// the check above can fail.
TEST(BsplineShape, HatGradientsJumpWhereTheSplinesDoNot) {
  const GridGeometry grid = small_grid();
  const Vec2 x = grid.origin + grid.h * Vec2(3.0, 4.37), hair = Vec2(1e-10 * grid.h, 0.0);
  Particles P = particles_at(grid, {x - hair, x + hair});
  const LinearShape hats = LinearShape::bind(grid, P);
  Stencil<LinearShape::stencil_size> a, b;
  hats.evaluate(0, a);
  hats.evaluate(1, b);
  double jump = 0.0;
  for (int k = 0; k < 4; ++k)
    for (int m = 0; m < 4; ++m)
      if (a.node[k] == b.node[m]) jump = std::max(jump, (a.gradient[k] - b.gradient[m]).norm() * grid.h);
  EXPECT_GT(jump, 0.5);
}

}  // namespace
