// CPDI and exact CPDI in r-z: the factors against quadrature over the
// parallelogram, exact CPDI's properties for deformed domains, its averages of
// the grid basis, and a domain over the axis keeping its part at r > 0.
#include <gtest/gtest.h>

#include "rz_models.hpp"
#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>
#include "solver/explicit_stepper.hpp"
#include "solver/particles.hpp"
#include "solver/shape/cpdi.hpp"
#include "solver/shape/cpdi_exact.hpp"
#include "solver/shape/gimp.hpp"
#include "solver/shape/linear.hpp"
#include "solver/stages.hpp"

namespace {

using mpmvv::testing::scientific;
using namespace mpmvv::testing::rz_models;  // the r-z models and the names they use

// ---------------------------------------------------------------- CPDI against quadrature

// S_g(x): the bilinear hat of node g.
double hat2(const GridGeometry& grid, int node, const Vec2& x) {
  const Vec2 d = (x - node_position(grid, node)) / grid.h;
  return std::max(0.0, 1.0 - std::abs(d.x())) * std::max(0.0, 1.0 - std::abs(d.y()));
}

// The CPDI weight, gradient and hoop factor of every node, by numerical
// quadrature over the parallelogram x = x_p + xi r1 + eta r2 (xi, eta in
// [-1, 1]) of the corner interpolation of the grid basis,
//   S~_g(xi, eta) = sum_c N_c(xi, eta) S_g(x_c),  N_c = (1 + xi xi_c)(1 + eta eta_c) / 4,
// weighted by r = x(xi, eta).x: w_g = int S~ r / int r, G_g = int grad S~ r / int r
// (grad S~ = s^-T (dS~/dxi, dS~/deta)), hoop_g = int S~ / int r. Composite
// three-point Gauss-Legendre on 8 x 8 sub-squares (576 points): exact for the
// integrands, which are of degree two in each of xi and eta.
struct NodeFactors {
  double weight = 0.0;
  Vec2 gradient = Vec2::Zero();
  double hoop = 0.0;
};

std::map<int, NodeFactors> cpdi_by_quadrature(const GridGeometry& grid, const Vec2& x_p, const Mat2& s) {
  const double xi_c[4] = {-1.0, 1.0, 1.0, -1.0}, eta_c[4] = {-1.0, -1.0, 1.0, 1.0};
  const double gauss_x[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, gauss_w[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  const Mat2 s_inverse_transpose = mpmvv::inverse(s).transpose();
  std::vector<double> abscissa, weight;
  const int pieces = 8;
  for (int i = 0; i < pieces; ++i)
    for (int q = 0; q < 3; ++q) {
      const double half = 1.0 / pieces;
      abscissa.push_back(-1.0 + (2 * i + 1) * half + gauss_x[q] * half);
      weight.push_back(gauss_w[q] * half);
    }
  std::map<int, NodeFactors> out;
  double integral_of_r = 0.0;
  for (std::size_t a = 0; a < abscissa.size(); ++a)
    for (std::size_t b = 0; b < abscissa.size(); ++b)
      integral_of_r += weight[a] * weight[b] * (x_p + abscissa[a] * s.col(0) + abscissa[b] * s.col(1)).x();
  for (int node = 0; node < int(grid.node_count()); ++node) {
    double corner_value[4];
    bool touches = false;
    for (int c = 0; c < 4; ++c) {
      corner_value[c] = hat2(grid, node, x_p + xi_c[c] * s.col(0) + eta_c[c] * s.col(1));
      touches = touches || corner_value[c] > 0.0;
    }
    if (!touches) continue;
    NodeFactors f;
    for (std::size_t a = 0; a < abscissa.size(); ++a)
      for (std::size_t b = 0; b < abscissa.size(); ++b) {
        const double xi = abscissa[a], eta = abscissa[b], w = weight[a] * weight[b];
        const double r = (x_p + xi * s.col(0) + eta * s.col(1)).x();
        double value = 0.0, d_xi = 0.0, d_eta = 0.0;
        for (int c = 0; c < 4; ++c) {
          value += 0.25 * (1.0 + xi * xi_c[c]) * (1.0 + eta * eta_c[c]) * corner_value[c];
          d_xi += 0.25 * xi_c[c] * (1.0 + eta * eta_c[c]) * corner_value[c];
          d_eta += 0.25 * (1.0 + xi * xi_c[c]) * eta_c[c] * corner_value[c];
        }
        f.weight += w * value * r;
        f.gradient += w * r * (s_inverse_transpose * Vec2(d_xi, d_eta));
        f.hoop += w * value;
      }
    f.weight /= integral_of_r;
    f.gradient /= integral_of_r;
    f.hoop /= integral_of_r;
    out[node] = f;
  }
  return out;
}

// A shape's weight, gradient and hoop factor for particle p, summed per node.
template <class Shape>
std::map<int, NodeFactors> factors_by_node(const Shape& shape, std::size_t p) {
  Stencil<Shape::stencil_size> st;
  shape.evaluate(p, st);
  std::map<int, NodeFactors> out;
  for (int k = 0; k < st.count; ++k) {
    NodeFactors& f = out[st.node[k]];
    f.weight += st.weight[k];
    f.gradient += st.gradient[k];
    f.hoop += st.hoop[k];
  }
  return out;
}

// CPDI's r-weighted weights, gradients and hoop factors (the closed forms in
// solver/shape/cpdi.hpp) equal the quadrature of their definitions, node by
// node, for sheared and stretched domains, interior and next to the axis.
// Measured worst 7.3e-15 (gradients scaled by h); tolerance 1e-12.
TEST(AxisymmetricShape, CpdiMatchesQuadratureOverTheParallelogram) {
  const GridGeometry grid = rz_grid();
  const std::vector<Vec2> positions = {{0.9, 1.1}, {0.31, 0.62}, {0.1, 0.4}, {0.07, 0.03}, {1.6, 1.9}};
  double worst = 0.0;
  for (const Mat2& F : cpdi_deformations()) {
    const Particles P = particles_at(positions, F);
    const CpdiShapeT<kRz> shape = CpdiShapeT<kRz>::bind(grid, P);
    for (std::size_t p = 0; p < P.size(); ++p) {
      ASSERT_TRUE(shape.inside(p));
      const std::map<int, NodeFactors> closed = factors_by_node(shape, p);
      const std::map<int, NodeFactors> quadrature = cpdi_by_quadrature(grid, P.position[p], shape.domain(p));
      // Every node the quadrature reaches is in the stencil, and every stencil
      // node the quadrature does not reach carries nothing.
      for (const auto& [node, q] : quadrature) {
        const NodeFactors c = closed.count(node) ? closed.at(node) : NodeFactors{};
        const double errors[] = {std::abs(c.weight - q.weight), (c.gradient - q.gradient).norm() * grid.h,
                                 std::abs(c.hoop - q.hoop) * P.position[p].x()};
        for (double e : errors) {
          worst = std::max(worst, e);
          EXPECT_LE(e, 1e-12) << "node " << node << " x_p = " << P.position[p].transpose() << "\nF =\n" << F;
        }
      }
      for (const auto& [node, c] : closed)
        if (!quadrature.count(node)) {
          EXPECT_EQ(c.weight, 0.0);
          EXPECT_EQ(c.hoop, 0.0);
        }
    }
  }
  RecordProperty("worst", scientific(worst));
}

// ---------------------------------------------------------------- exact CPDI in r-z

// The positions of test_positions() whose deformed domain stays at r >= 0.
std::vector<Vec2> off_axis_positions(const Mat2& F) {
  std::vector<Vec2> out;
  const double reach = kHalfSize * (std::abs(F(0, 0)) + std::abs(F(0, 1)));
  for (const Vec2& x : test_positions())
    if (x.x() - reach >= 0.0) out.push_back(x);
  return out;
}

// Exact CPDI in r-z: (a)-(e), and (f) the r-weighted centroid of the
// parallelogram, which the exact r-weighted average of the bilinear basis
// reproduces exactly (linear completeness under any weight).
TEST(AxisymmetricShape, CpdiExactPropertiesHoldForDeformedDomains) {
  const GridGeometry grid = rz_grid();
  double worst = 0.0;
  for (const Mat2& F : cpdi_deformations()) {
    const Particles P = particles_at(off_axis_positions(F), F);
    ASSERT_GT(P.size(), 40u);
    expect_rz_properties<CpdiExactShapeT<kRz>>(grid, P, cpdi_centroid, "cpdi-exact", worst);
  }
  RecordProperty("worst", scientific(worst));
}

// Its weights, gradients and hoop factors are the r-weighted averages of the
// grid basis itself (not of its corner interpolation) over the domain. The
// reference is a midpoint rule on n x n points of the parallelogram, whose
// error falls as 1 / n where a cell line crosses the domain (the gradient
// jumps there): at n = 1600 it agrees node by node within 5e-5, four times
// closer than at n = 400, so the rule converges on exactly these values.
struct RzFactors {
  std::map<int, NodeFactors> node;
};

RzFactors rz_midpoint(const GridGeometry& grid, const Vec2& x_p, const Mat2& s, int n) {
  RzFactors out;
  double integral_of_r = 0.0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      const Vec2 x = x_p + s * Vec2(-1.0 + (2.0 * a + 1.0) / n, -1.0 + (2.0 * b + 1.0) / n);
      const double r = x.x();
      integral_of_r += r;
      const Vec2 xi = (x - grid.origin) / grid.h;
      const int i = int(std::floor(xi.x())), j = int(std::floor(xi.y()));
      const double fx = xi.x() - i, fy = xi.y() - j;
      const double value[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
      const Vec2 gradient[4] = {Vec2(-(1 - fy), -(1 - fx)) / grid.h, Vec2(1 - fy, -fx) / grid.h,
                                Vec2(-fy, 1 - fx) / grid.h, Vec2(fy, fx) / grid.h};
      const int node[4] = {grid.node(i, j), grid.node(i + 1, j), grid.node(i, j + 1), grid.node(i + 1, j + 1)};
      for (int k = 0; k < 4; ++k) {
        NodeFactors& f = out.node[node[k]];
        f.weight += r * value[k];
        f.gradient += r * gradient[k];
        f.hoop += value[k];
      }
    }
  for (auto& [node, f] : out.node) {
    f.weight /= integral_of_r;
    f.gradient /= integral_of_r;
    f.hoop /= integral_of_r;
  }
  return out;
}

// The largest difference, node by node, scaled as in the test above.
double largest_difference(const std::map<int, NodeFactors>& exact, const RzFactors& reference, const GridGeometry& grid,
                          double r_p) {
  double worst = 0.0;
  for (const auto& [node, f] : reference.node) {
    const NodeFactors e = exact.count(node) ? exact.at(node) : NodeFactors{};
    worst = std::max({worst, std::abs(e.weight - f.weight), (e.gradient - f.gradient).norm() * grid.h,
                      std::abs(e.hoop - f.hoop) * r_p});
  }
  return worst;
}

TEST(AxisymmetricShape, CpdiExactMatchesTheAveragesOfTheGridBasis) {
  const GridGeometry grid = rz_grid();
  const std::vector<Vec2> positions = {{0.9, 1.1}, {0.31, 0.62}, {0.13, 0.4}, {1.6, 1.9}};
  double worst = 0.0;
  for (const Mat2& F : cpdi_deformations()) {
    const Particles P = particles_at(positions, F);
    const CpdiExactShapeT<kRz> shape = CpdiExactShapeT<kRz>::bind(grid, P);
    for (std::size_t p = 0; p < P.size(); ++p) {
      ASSERT_TRUE(shape.inside(p));
      const std::map<int, NodeFactors> exact = factors_by_node(shape, p);
      const double coarse = largest_difference(exact, rz_midpoint(grid, P.position[p], shape.domain(p), 400), grid,
                                               P.position[p].x());
      const double fine = largest_difference(exact, rz_midpoint(grid, P.position[p], shape.domain(p), 1600), grid,
                                             P.position[p].x());
      worst = std::max(worst, fine);
      EXPECT_LE(fine, 5e-5) << "x_p = " << P.position[p].transpose() << "\nF =\n" << F;
      EXPECT_LE(fine, 0.35 * coarse + 1e-9) << "x_p = " << P.position[p].transpose() << "\nF =\n" << F;
    }
  }
  RecordProperty("worst", scientific(worst));
}

// A domain reaching over the axis keeps its part at r >= 0: weights stay
// non-negative and (a)-(c) hold for that part.
TEST(AxisymmetricShape, CpdiExactDomainOverTheAxisKeepsItsPartAtPositiveRadius) {
  const GridGeometry grid = rz_grid();
  const Particles P = particles_at({{0.04, 1.0}, {0.0625, 0.5}, {0.05, 0.05}}, mpmvv::testing::simple_shear(0.6));
  const CpdiExactShapeT<kRz> shape = CpdiExactShapeT<kRz>::bind(grid, P);
  for (std::size_t p = 0; p < P.size(); ++p) {
    ASSERT_TRUE(shape.inside(p));
    Stencil<CpdiExactShapeT<kRz>::stencil_size> st;
    shape.evaluate(p, st);
    const Sums sums = stencil_sums(grid, shape, p);
    for (int k = 0; k < st.count; ++k) EXPECT_GE(st.weight[k], 0.0);
    EXPECT_NEAR(sums.weight, 1.0, kRoundOff);
    EXPECT_LE(sums.gradient.norm() * grid.h, kRoundOff);
    EXPECT_LE((sums.completeness - Mat2::Identity()).cwiseAbs().maxCoeff(), kRoundOff);
  }
}


}  // namespace
