// Shape functions by their properties (002_c3305cb8b1bc1490.txt section 1.6):
// partition of unity, gradients that sum to zero, linear completeness and
// non-negative weights, for every family and at the places where a weight
// changes formula: cell edges, nodes, the GIMP breakpoints d = +-l, +-(h - l),
// +-(h + l), and the last positions `inside` still accepts next to a wall.
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

// The distance, in cells, a particle centre must keep from a wall for
// `inside` to accept it with F = I and l = h/4: linear MPM needs its cell,
// uGIMP the node on each side of its nearest node, CPDI its corners, the
// B-splines the node beyond the wall (half a cell quadratic, one cubic).
template <class Shape>
double wall_margin_in_cells();
template <>
double wall_margin_in_cells<LinearShape>() { return 0.0; }
template <>
double wall_margin_in_cells<GimpShape>() { return 0.25; }  // the half-size h/4: the domain may touch a wall
template <>
double wall_margin_in_cells<CpdiShape>() { return 0.25; }
template <>
double wall_margin_in_cells<CpdiExactShape>() { return 0.25; }
template <>
double wall_margin_in_cells<BsplineShape>() { return 0.5; }  // the node beyond the wall would weigh it
template <>
double wall_margin_in_cells<CubicBsplineShape>() { return 1.0; }

// Positions on and a hair either side of every place where a weight changes
// formula, around node (3, 4) and the cell beyond it, plus the last accepted
// positions next to each of the four walls.
template <class Shape>
std::vector<Vec2> critical_positions(const GridGeometry& grid) {
  std::vector<Vec2> xi;
  const double offsets[] = {0.0, 0.25, 0.5, 0.75, -0.25, -0.5, -0.75, 1.0, 1.25};
  const double hairs[] = {0.0, 1e-12, -1e-12, 1e-9, -1e-9};
  for (double ox : offsets)
    for (double hx : hairs) {
      xi.emplace_back(3.0 + ox + hx, 4.0 + 0.37);
      xi.emplace_back(3.0 + 0.61, 4.0 + ox + hx);
      xi.emplace_back(3.0 + ox + hx, 4.0 + ox - hx);
    }
  const double m = wall_margin_in_cells<Shape>();
  const double lo = m, hi_x = grid.cells_x - m, hi_y = grid.cells_y - m;
  for (double along : {m, 0.5 * grid.cells_x, 2.3, double(grid.cells_y) - m}) {
    xi.emplace_back(lo, along);
    xi.emplace_back(lo + 1e-12, along);
    xi.emplace_back(hi_x, along);
    xi.emplace_back(along, lo);
    xi.emplace_back(along, hi_y);
  }
  std::vector<Vec2> x;
  for (const Vec2& v : xi) x.push_back(grid.origin + grid.h * v);
  return x;
}


// The sums the properties are stated in.
struct StencilSums {
  double weight = 0.0;
  Vec2 gradient = Vec2::Zero();
  Vec2 weighted_position = Vec2::Zero();  // sum_k w_k x_k
  Mat2 position_gradient = Mat2::Zero();  // sum_k x_k (outer) G_k
  double smallest_weight = 0.0;
  bool nodes_exist = true;
};

template <int N>
StencilSums sums_of(const GridGeometry& grid, const Stencil<N>& s) {
  StencilSums out;
  out.smallest_weight = s.weight[0];
  for (int k = 0; k < s.count; ++k) {
    if (s.node[k] < 0 || std::size_t(s.node[k]) >= grid.node_count()) {
      out.nodes_exist = false;
      continue;
    }
    const Vec2 x = node_position(grid, s.node[k]);
    out.weight += s.weight[k];
    out.gradient += s.gradient[k];
    out.weighted_position += s.weight[k] * x;
    out.position_gradient += x * s.gradient[k].transpose();
    out.smallest_weight = std::min(out.smallest_weight, s.weight[k]);
  }
  return out;
}

// Checks (a)-(d) at every particle of `P`, all of which must be inside.
template <class Shape>
void expect_shape_properties(const GridGeometry& grid, const Particles& P) {
  const Shape shape = Shape::bind(grid, P);
  Stencil<Shape::stencil_size> s;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Vec2 x = P.position[p];
    SCOPED_TRACE("particle at xi = (" + std::to_string((x.x() - grid.origin.x()) / grid.h) + ", " +
                 std::to_string((x.y() - grid.origin.y()) / grid.h) + ")");
    ASSERT_TRUE(shape.inside(p));
    shape.evaluate(p, s);
    const StencilSums sum = sums_of(grid, s);
    ASSERT_TRUE(sum.nodes_exist);
    EXPECT_NEAR(sum.weight, 1.0, kRoundOff);
    EXPECT_LT(sum.gradient.norm(), kRoundOff / grid.h);
    // Node coordinates are of order 2 m, so the completeness sums carry that scale.
    EXPECT_LT((sum.weighted_position - x).norm(), kRoundOff);
    EXPECT_LT((sum.position_gradient - Mat2::Identity()).norm(), kRoundOff);
    EXPECT_GE(sum.smallest_weight, 0.0);
  }
}

template <class Shape>
class ShapeFunctionTest : public ::testing::Test {};

using ShapeFamilies =
    ::testing::Types<LinearShape, GimpShape, CpdiShape, CpdiExactShape, BsplineShape, CubicBsplineShape>;
TYPED_TEST_SUITE(ShapeFunctionTest, ShapeFamilies);

// (a)-(d) at random interior positions.
TYPED_TEST(ShapeFunctionTest, PropertiesHoldAtInteriorPositions) {
  const GridGeometry grid = small_grid();
  expect_shape_properties<TypeParam>(grid, particles_at(grid, random_interior_positions(grid, 200, 7)));
}

// (a)-(d) on cell edges and nodes, a hair either side of them, at the GIMP
// breakpoints and CPDI corners on edges, and next to every wall.
TYPED_TEST(ShapeFunctionTest, PropertiesHoldOnEdgesBreakpointsAndNearWalls) {
  const GridGeometry grid = small_grid();
  expect_shape_properties<TypeParam>(grid, particles_at(grid, critical_positions<TypeParam>(grid)));
}

// A particle whose support leaves the grid is not inside; one well inside is,
// and so is one whose support just touches a wall (a body may fill the grid
// up to its walls).
TYPED_TEST(ShapeFunctionTest, InsideRejectsSupportBeyondTheGrid) {
  const GridGeometry grid = small_grid();
  const double m = wall_margin_in_cells<TypeParam>();
  const std::vector<Vec2> inside = {
      {4.1, 3.7},                          // well inside
      {4.0, double(grid.cells_y) - m},     // support touching the top wall
      {m, 4.0},                            // support touching the left wall
  };
  const std::vector<Vec2> outside = {
      {-0.3, 4.0},                              // centre beyond the left wall
      {4.0, double(grid.cells_y) + 0.2},        // beyond the top wall
      {double(grid.cells_x) - m + 0.05, 4.0},   // support crosses the right wall
      {m - 0.05, 4.0},                          // support crosses the left wall
  };
  std::vector<Vec2> x;
  for (const Vec2& v : inside) x.push_back(grid.origin + grid.h * v);
  for (const Vec2& v : outside) x.push_back(grid.origin + grid.h * v);
  const Particles P = particles_at(grid, x);
  const TypeParam shape = TypeParam::bind(grid, P);
  for (std::size_t p = 0; p < inside.size(); ++p) EXPECT_TRUE(shape.inside(p)) << "particle " << p;
  for (std::size_t p = inside.size(); p < P.size(); ++p) EXPECT_FALSE(shape.inside(p)) << "particle " << p;
}

// A NaN position is never inside, so a broken particle cannot index the grid.
TYPED_TEST(ShapeFunctionTest, NanPositionIsNotInside) {
  const GridGeometry grid = small_grid();
  const Particles P = particles_at(grid, {Vec2(std::nan(""), 0.0), Vec2(0.0, std::nan(""))});
  const TypeParam shape = TypeParam::bind(grid, P);
  EXPECT_FALSE(shape.inside(0));
  EXPECT_FALSE(shape.inside(1));
}

// ---------------------------------------------------------------- CPDI with deformed domains

using mpmvv::testing::rotation;
using mpmvv::testing::simple_shear;

Mat2 rotated_stretch() {
  Mat2 stretch;
  stretch << 1.4, 0.3, 0.3, 0.7;  // symmetric positive definite
  return rotation(0.7) * stretch;
}

// Random F with det F >= 0.2 and entries of order one.
Mat2 random_deformation(std::mt19937& rng) { return mpmvv::testing::random_deformation(rng, 0.8, 0.2); }

// (a)-(c) for CPDI domains under simple shear and under a rotated stretch, at
// interior positions and on edges. Weights stay non-negative (they are
// bilinear hat values at the corners).
TEST(CpdiShape, PropertiesHoldForDeformedDomains) {
  const GridGeometry grid = small_grid();
  for (const Mat2& F : {simple_shear(1.5), rotated_stretch()}) {
    SCOPED_TRACE("F = [" + std::to_string(F(0, 0)) + " " + std::to_string(F(0, 1)) + "; " +
                 std::to_string(F(1, 0)) + " " + std::to_string(F(1, 1)) + "]");
    std::vector<Vec2> x = random_interior_positions(grid, 100, 11);
    for (double ox : {0.0, 0.25, 0.5, 1e-12, -1e-12})
      x.push_back(grid.origin + grid.h * Vec2(4.0 + ox, 4.0 - ox));
    expect_shape_properties<CpdiShape>(grid, particles_at(grid, x, std::vector<Mat2>(x.size(), F)));
  }
}

// The same for the exactly integrated domains; their weights are integrals
// of non-negative hats, so non-negative too.
TEST(CpdiExactShape, PropertiesHoldForDeformedDomains) {
  const GridGeometry grid = small_grid();
  for (const Mat2& F : {simple_shear(1.5), rotated_stretch()}) {
    std::vector<Vec2> x = random_interior_positions(grid, 100, 11);
    for (double ox : {0.0, 0.25, 0.5, 1e-12, -1e-12})
      x.push_back(grid.origin + grid.h * Vec2(4.0 + ox, 4.0 - ox));
    expect_shape_properties<CpdiExactShape>(grid, particles_at(grid, x, std::vector<Mat2>(x.size(), F)));
  }
}

// Shear alone moves the corners of a particle 1/2 cell from the wall across
// it: inside follows the deformed domain, not the centre.
TEST(CpdiShape, InsideFollowsTheDeformedCorners) {
  const GridGeometry grid = small_grid();
  const Vec2 x = grid.origin + grid.h * Vec2(0.5, 4.0);
  const Particles P = particles_at(grid, {x, x}, {Mat2::Identity(), simple_shear(1.5)});
  const CpdiShape shape = CpdiShape::bind(grid, P);
  EXPECT_TRUE(shape.inside(0));
  EXPECT_FALSE(shape.inside(1));  // corner at xi = 0.5 - (1 + 1.5)/4 = -0.125
}

// The domain is s_p = F diag(l) (eq. 1.97) for random F with det F > 0; its
// corners are x_p -+ r_1 -+ r_2, counter-clockwise from (-,-), so the corner
// polygon has area 4 det(s_p) = det(F) V_p0 (eq. 1.75).
TEST(CpdiShape, DomainVectorsFollowTheDeformationGradient) {
  const GridGeometry grid = small_grid();
  std::mt19937 rng(2024);
  std::vector<Mat2> F;
  for (int k = 0; k < 50; ++k) F.push_back(random_deformation(rng));
  const std::vector<Vec2> x = random_interior_positions(grid, F.size(), 5);
  Particles P = particles_at(grid, x, F);
  std::uniform_real_distribution<double> size(0.05, 0.25);
  for (Vec2& l : P.half_size) l = grid.h * Vec2(size(rng), size(rng));
  const CpdiShape shape = CpdiShape::bind(grid, P);
  for (std::size_t p = 0; p < P.size(); ++p) {
    const Vec2 l = P.half_size[p];
    const Mat2 expected = F[p] * l.asDiagonal();
    const Mat2 s = shape.domain(p);
    // Each entry is one product F_ij l_j: exact up to one rounding.
    EXPECT_LT((s - expected).norm(), 1e-15 * expected.norm());
    const Vec2 r1 = expected.col(0), r2 = expected.col(1);
    const Vec2 corners[4] = {x[p] - r1 - r2, x[p] + r1 - r2, x[p] + r1 + r2, x[p] - r1 + r2};
    double twice_area = 0.0;
    for (int c = 0; c < 4; ++c) {
      const Vec2 got = shape.corner(p, s, c);
      EXPECT_LT((got - corners[c]).norm(), 1e-15 * (x[p].norm() + 2.0 * expected.norm()));
      const Vec2 next = shape.corner(p, s, (c + 1) % 4);
      twice_area += got.x() * next.y() - next.x() * got.y();
    }
    const double area = 0.5 * twice_area;
    // The shoelace sum cancels coordinates of order 2 m down to areas of
    // order 1e-3 m^2: a relative 1e-10 covers that cancellation.
    EXPECT_NEAR(area, mpmvv::determinant(F[p]) * 4.0 * l.x() * l.y(), 1e-10 * area);
  }
}

// A domain within 2 x 2 cells lists each node it reaches once: 4 entries
// inside a cell, 6 across one grid line, 9 across two; a domain stretched
// further keeps four entries per corner. Either way each node carries the
// definition's S_gp = (1/4) sum_c N_g(x_c) and G_gp = (1/4) s^-T sum_c
// (xi_c, eta_c) N_g(x_c) (eq. 1.100 in 2D), with N_g the bilinear tent.
TEST(CpdiShape, ListsEachNodeOnceWithTheDefinitionsValues) {
  const GridGeometry grid = small_grid();
  const Mat2 stretch = (Mat2() << 5.0, 0.3, 0.0, 1.0).finished();
  struct Case {
    Vec2 xi;  // centre, in cells
    Mat2 F;
    int count;
  };
  const Case cases[] = {{{3.5, 4.5}, Mat2::Identity(), 4},
                        {{3.1, 4.5}, Mat2::Identity(), 6},
                        {{3.5, 3.9}, Mat2::Identity(), 6},
                        {{3.1, 4.1}, Mat2::Identity(), 9},
                        {{3.9, 4.1}, mpmvv::testing::simple_shear(0.6), 9},
                        {{4.0, 4.3}, stretch, 16}};
  for (const Case& c : cases) {
    const Particles P = particles_at(grid, {grid.origin + grid.h * c.xi}, {c.F});
    const CpdiShape shape = CpdiShape::bind(grid, P);
    ASSERT_TRUE(shape.inside(0));
    Stencil<CpdiShape::stencil_size> st;
    shape.evaluate(0, st);
    SCOPED_TRACE("centre at xi = (" + std::to_string(c.xi.x()) + ", " + std::to_string(c.xi.y()) + ")");
    EXPECT_EQ(st.count, c.count);
    struct Values {
      double weight = 0.0;
      Vec2 gradient = Vec2::Zero();
    };
    std::map<int, Values> got;
    for (int k = 0; k < st.count; ++k) {
      if (c.count < 16) {
        EXPECT_EQ(got.count(st.node[k]), 0u) << "node " << st.node[k] << " listed twice";
      }
      got[st.node[k]].weight += st.weight[k];
      got[st.node[k]].gradient += st.gradient[k];
    }
    // The definition, node by node.
    const Mat2 s = shape.domain(0);
    const Mat2 s_inv_t = mpmvv::inverse(s).transpose();
    std::map<int, Values> expected;
    const double corner_xi[4] = {-1, 1, 1, -1}, corner_eta[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; ++k) {
      const Vec2 x = (P.position[0] + corner_xi[k] * s.col(0) + corner_eta[k] * s.col(1) - grid.origin) / grid.h;
      for (int j = 0; j <= grid.cells_y; ++j)
        for (int i = 0; i <= grid.cells_x; ++i) {
          const double N = std::max(0.0, 1.0 - std::abs(x.x() - i)) * std::max(0.0, 1.0 - std::abs(x.y() - j));
          if (N == 0.0) continue;
          auto& e = expected[grid.node(i, j)];
          e.weight += 0.25 * N;
          e.gradient += 0.25 * N * (s_inv_t * Vec2(corner_xi[k], corner_eta[k]));
        }
    }
    for (const auto& [node, e] : expected) {
      ASSERT_EQ(got.count(node), 1u) << "node " << node << " missing";
      EXPECT_NEAR(got[node].weight, e.weight, 1e-15) << "node " << node;
      EXPECT_LT((got[node].gradient - e.gradient).norm() * grid.h, 1e-14) << "node " << node;
    }
    for (const auto& [node, g] : got) {
      if (!expected.count(node)) {
        EXPECT_LT(std::abs(g.weight) + g.gradient.norm() * grid.h, 1e-15) << "node " << node;
      }
    }
  }
}

}  // namespace
