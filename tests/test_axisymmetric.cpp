// The solver's axisymmetric (r-z) mode (solver/geometry.hpp): the r-weighted
// shape functions of linear MPM, uGIMP and CPDI (solver/shape/*.hpp, the
// averages of eq. 1.85 with r dA) by their properties and against numerical
// quadrature; the hoop rate of one step; the checks make_stepper makes; and
// the mirrored ghost walls (apply_walls, solver/stages.hpp).
#include <gtest/gtest.h>

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

using mpmvv::CpdiExactShapeT;
using mpmvv::CpdiShapeT;
using mpmvv::Geometry;
using mpmvv::GimpShapeT;
using mpmvv::GridFields;
using mpmvv::GridGeometry;
using mpmvv::LinearShapeT;
using mpmvv::Mat2;
using mpmvv::Method;
using mpmvv::Model;
using mpmvv::NeoHookean;
using mpmvv::Particles;
using mpmvv::Scheme;
using mpmvv::SolverOptions;
using mpmvv::Stencil;
using mpmvv::Vec2;

constexpr Geometry kRz = Geometry::axisymmetric;

// Walls at r = 0, z = 0 and r = z = 2 m, one ghost layer beyond each:
// nodes from -0.25 to 2.25 along both axes.
GridGeometry rz_grid() { return GridGeometry::walled(Vec2(0.0, 0.0), 0.25, 8, 8); }

// Two particles per cell per direction: half-size h/4.
constexpr double kHalfSize = 0.0625;

Particles particles_at(const std::vector<Vec2>& positions, const Mat2& F = Mat2::Identity()) {
  Particles P;
  P.resize(positions.size());
  P.half_size.assign(positions.size(), Vec2(kHalfSize, kHalfSize));
  P.hoop_stretch.assign(positions.size(), 1.0);
  P.hoop_stress.assign(positions.size(), 0.0);
  for (std::size_t p = 0; p < positions.size(); ++p) {
    P.position[p] = P.reference_position[p] = positions[p];
    P.deformation_gradient[p] = F;
  }
  return P;
}

// Random interior positions, positions whose support reaches the ghost layer
// beyond the axis (r_p <= l: the particle domain touches or crosses r = 0),
// beyond z = 0 and beyond the upper walls, and the corners of both.
std::vector<Vec2> test_positions() {
  std::vector<Vec2> x = {{0.0625, 1.0}, {0.04, 1.0},  {0.1, 0.03},   {0.9, 0.03},  {0.9, 1.98},
                         {1.98, 0.7},   {1.98, 1.98}, {0.05, 0.05},  {0.3, 0.125}, {0.125, 0.5},
                         {1.0, 1.0},    {0.25, 0.25}, {1.875, 1.99}, {0.0625, 0.0625}};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.3, 1.7);
  for (int k = 0; k < 40; ++k) x.emplace_back(u(rng), u(rng));
  return x;
}

// Sheared and stretched CPDI domains: simple shear, stretch with rotation, and
// a compressed one.
std::vector<Mat2> cpdi_deformations() {
  Mat2 stretch;
  stretch << 1.3, 0.0, 0.0, 0.8;
  Mat2 general;
  general << 1.2, 0.3, -0.2, 0.9;
  return {Mat2::Identity(), mpmvv::testing::simple_shear(0.6), mpmvv::testing::rotation(0.5) * stretch, general};
}

Vec2 node_position(const GridGeometry& grid, int node) {
  return grid.node_position(node % grid.nodes_x(), node / grid.nodes_x());
}

// The sums properties (a)-(f) are stated in.
struct Sums {
  double weight = 0.0;                      // sum_k w_k
  Vec2 gradient = Vec2::Zero();             // sum_k G_k
  Mat2 completeness = Mat2::Zero();         // sum_k x_k (outer) G_k
  double hoop = 0.0;                        // sum_k <S_k / r>
  double hoop_times_radius = 0.0;           // sum_k <S_k / r> r_k
  Vec2 centroid = Vec2::Zero();             // sum_k w_k x_k
};

template <class Shape>
Sums stencil_sums(const GridGeometry& grid, const Shape& shape, std::size_t p) {
  Stencil<Shape::stencil_size> s;
  shape.evaluate(p, s);
  Sums sums;
  for (int k = 0; k < s.count; ++k) {
    const Vec2 x = node_position(grid, s.node[k]);
    sums.weight += s.weight[k];
    sums.gradient += s.gradient[k];
    sums.completeness += x * s.gradient[k].transpose();
    sums.hoop += s.hoop[k];
    sums.hoop_times_radius += s.hoop[k] * x.x();
    sums.centroid += s.weight[k] * x;
  }
  return sums;
}

// The r-weighted centroid of particle p's domain, property (f).
Vec2 linear_centroid(const Particles& P, std::size_t p) { return P.position[p]; }
Vec2 gimp_centroid(const Particles& P, std::size_t p) {
  const double r = P.position[p].x(), l = P.half_size[p].x();
  return {r + l * l / (3.0 * r), P.position[p].y()};  // int r'^2 dr' / int r' dr' over [r - l, r + l]
}
Vec2 cpdi_centroid(const Particles& P, std::size_t p) {
  Mat2 s = P.deformation_gradient[p];
  s.col(0) *= P.half_size[p].x();
  s.col(1) *= P.half_size[p].y();
  const double r = P.position[p].x();
  // x = x_p + xi r1 + eta r2, weight r = r_p + a xi + b eta, xi, eta uniform on [-1, 1].
  return P.position[p] + (s(0, 0) * s.col(0) + s(0, 1) * s.col(1)) / (3.0 * r);
}

// Sums of at most 16 products of numbers of order one (weights), 1/h
// (gradients) or 1/r_p <= 25 (hoop): round-off is a few 1e-16 relative;
// measured worst 5.7e-15 (CPDI with deformed domains next to the axis).
// 1e-12 relative to the size of the sum leaves two orders of margin.
constexpr double kRoundOff = 1e-12;

template <class Shape>
void expect_rz_properties(const GridGeometry& grid, const Particles& P, Vec2 (*centroid)(const Particles&, std::size_t),
                          const std::string& label, double& worst) {
  const Shape shape = Shape::bind(grid, P);
  for (std::size_t p = 0; p < P.size(); ++p) {
    ASSERT_TRUE(shape.inside(p)) << label << " x = " << P.position[p].transpose();
    const Sums s = stencil_sums(grid, shape, p);
    const double r = P.position[p].x();
    const std::string where = label + " x = (" + std::to_string(P.position[p].x()) + ", " +
                              std::to_string(P.position[p].y()) + ")";
    const double errors[] = {
        std::abs(s.weight - 1.0),                                      // (a)
        s.gradient.norm() * grid.h,                                    // (b)
        (s.completeness - Mat2::Identity()).cwiseAbs().maxCoeff(),     // (c)
        std::abs(s.hoop_times_radius - 1.0),                           // (d)
        std::abs(s.hoop * r - 1.0),                                    // (e)
        (s.centroid - centroid(P, p)).norm() / grid.h,                 // (f)
    };
    const char* names[] = {"(a) sum w = 1", "(b) sum G = 0", "(c) sum x G^T = I", "(d) sum <S/r> r_g = 1",
                           "(e) sum <S/r> = 1 / r_p", "(f) sum w x_g = r-weighted centroid"};
    for (int k = 0; k < 6; ++k) {
      worst = std::max(worst, errors[k]);
      EXPECT_LE(errors[k], kRoundOff) << names[k] << " " << where;
    }
  }
}

// ---------------------------------------------------------------- shape-function properties

// Linear MPM in r-z, at interior positions and next to the walls:
// (a) sum w = 1, (b) sum G = 0, (c) sum x_g G^T = I, (d) sum <S/r> r_g = 1 (a
// radial velocity v_r = r has hoop rate 1), (e) sum <S/r> = 1 / r_p, (f)
// sum w x_g = x_p. Measured worst 8.9e-16.
TEST(AxisymmetricShape, LinearPropertiesHold) {
  const GridGeometry grid = rz_grid();
  const Particles P = particles_at(test_positions());
  double worst = 0.0;
  expect_rz_properties<LinearShapeT<kRz>>(grid, P, linear_centroid, "linear", worst);
  RecordProperty("worst", scientific(worst));
}

// uGIMP in r-z: (a)-(e) as above, and (f) the r-weighted centroid
// (r_p + l^2 / (3 r_p), z_p) of the particle's segment. Measured worst 2.7e-15.
TEST(AxisymmetricShape, GimpPropertiesHold) {
  const GridGeometry grid = rz_grid();
  const Particles P = particles_at(test_positions());
  double worst = 0.0;
  expect_rz_properties<GimpShapeT<kRz>>(grid, P, gimp_centroid, "gimp", worst);
  RecordProperty("worst", scientific(worst));
}

// CPDI in r-z with F = I, simple shear, a rotated stretch and a general F:
// (a)-(e) as above, and (f) x_p + (a r1 + b r2) / (3 r_p), the r-weighted
// centroid of the parallelogram (r1, r2 the columns of s = F diag(l), a = r1.x,
// b = r2.x). Measured worst 5.7e-15.
TEST(AxisymmetricShape, CpdiPropertiesHoldForDeformedDomains) {
  const GridGeometry grid = rz_grid();
  double worst = 0.0;
  for (const Mat2& F : cpdi_deformations()) {
    const Particles P = particles_at(test_positions(), F);
    expect_rz_properties<CpdiShapeT<kRz>>(grid, P, cpdi_centroid, "cpdi", worst);
  }
  RecordProperty("worst", scientific(worst));
}

// Property (f) is not vacuous: for uGIMP and CPDI (F = I) the r-weighted
// centroid lies l^2 / (3 r_p) = 5.2e-3 m = 2.1e-2 h beyond x_p at r_p = 0.25
// (more next to the axis), which sum w x_g = x_p would miss.
TEST(AxisymmetricShape, RWeightingMovesTheCentroidTowardsLargerRadius) {
  const GridGeometry grid = rz_grid();
  const Particles P = particles_at({{0.25, 1.0}});
  const GimpShapeT<kRz> gimp = GimpShapeT<kRz>::bind(grid, P);
  const CpdiShapeT<kRz> cpdi = CpdiShapeT<kRz>::bind(grid, P);
  const double shift = kHalfSize * kHalfSize / (3.0 * 0.25);
  EXPECT_NEAR(stencil_sums(grid, gimp, 0).centroid.x() - 0.25, shift, 1e-14);
  EXPECT_NEAR(stencil_sums(grid, cpdi, 0).centroid.x() - 0.25, shift, 1e-14);
  EXPECT_GT(shift, 0.02 * grid.h);
}

// ---------------------------------------------------------------- GIMP r-weighted factors

// int_a^b f by the composite two-point Gauss-Legendre rule on `n` intervals:
// exact for cubics, and it samples no end point (where S' jumps).
template <class F>
double gauss(F f, double a, double b, int n) {
  const double dx = (b - a) / n, offset = 0.5 * dx / std::sqrt(3.0);
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double middle = a + (i + 0.5) * dx;
    sum += f(middle - offset) + f(middle + offset);
  }
  return 0.5 * dx * sum;
}

// int over [r - l, r + l] of f, split where the hat of node x_g changes formula
// (x_g - h, x_g, x_g + h) so that each piece is smooth, 1000 intervals (2000
// points) each.
template <class F>
double over_particle(F f, double r, double l, double x_g, double h) {
  std::vector<double> cuts = {r - l, r + l};
  for (double c : {x_g - h, x_g, x_g + h})
    if (c > r - l && c < r + l) cuts.push_back(c);
  std::sort(cuts.begin(), cuts.end());
  double sum = 0.0;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) sum += gauss(f, cuts[k], cuts[k + 1], 1000);
  return sum;
}

// gimp_radial_1d against quadrature of its definitions, for random particles
// (l <= h/2, r_p >= l and also r_p < l next to the axis) and every node within
// reach:
//   weight     = int S(r' - x_g) r' dr' / (2 l r_p),
//   derivative = int S'(r' - x_g) r' dr' / (2 l r_p)  (the r-weighted mean of
//                dS/dr over the particle, not the derivative of the weight),
//   hoop       = int S(r' - x_g) dr' / (2 l r_p),
// and the weights sum to one over the nodes. On each smooth piece the
// integrands are polynomials of degree two at most, which the rule integrates
// exactly: the differences are round-off of the 2000-term sums,
// amplified by 1 / r_p next to the axis. Errors are scaled to the size of each
// factor (weight 1, derivative 1/h, hoop 1/r_p). Measured worst 1.3e-14;
// tolerance 1e-12.
TEST(GimpRadial1D, MatchesQuadratureOfItsDefinition) {
  const double h = 0.25;
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> size(0.05, 0.5), position(0.0, 2.0);
  double worst = 0.0;
  for (int k = 0; k < 200; ++k) {
    const double l = size(rng) * h;
    const double r = k < 20 ? 0.3 * l + 0.7 * l * (k / 20.0) : std::max(position(rng), l);
    double weight_sum = 0.0;
    for (int i = -2; i <= 12; ++i) {
      const double x_g = i * h;
      const mpmvv::GimpRadial1D g = mpmvv::gimp_radial_1d(r, x_g, h, l);
      auto S = [&](double y) { return std::max(0.0, 1.0 - std::abs(y - x_g) / h); };
      auto dS = [&](double y) { return std::abs(y - x_g) >= h ? 0.0 : (y < x_g ? 1.0 / h : -1.0 / h); };
      const double norm = 2.0 * l * r;
      const double weight = over_particle([&](double y) { return S(y) * y; }, r, l, x_g, h) / norm;
      const double derivative = over_particle([&](double y) { return dS(y) * y; }, r, l, x_g, h) / norm;
      const double hoop = over_particle(S, r, l, x_g, h) / norm;
      const double errors[] = {std::abs(g.weight - weight), std::abs(g.derivative - derivative) * h,
                               std::abs(g.hoop - hoop) * r};
      for (double e : errors) worst = std::max(worst, e);
      EXPECT_LE(errors[0], 1e-12) << "weight r = " << r << " l = " << l << " x_g = " << x_g;
      EXPECT_LE(errors[1], 1e-12) << "derivative r = " << r << " l = " << l << " x_g = " << x_g;
      EXPECT_LE(errors[2], 1e-12) << "hoop r = " << r << " l = " << l << " x_g = " << x_g;
      weight_sum += g.weight;
    }
    EXPECT_NEAR(weight_sum, 1.0, kRoundOff) << "r = " << r << " l = " << l;
  }
  RecordProperty("worst", scientific(worst));
}

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

// ---------------------------------------------------------------- one step of a cylinder

constexpr double kDensity = 1000.0;
const NeoHookean kSolid{577.0, 385.0};

// A hollow cylinder R in [0.3, 0.7], Z in [0, 1] on a walled grid whose left
// wall is the axis (cells of 1 / `cells` m over [0, 1]^2), two particles per
// cell per direction, F = I, unstressed, moving with velocity `velocity(x)`.
// Volumes and masses per radian: V_0 = R * area, m = rho_0 V_0.
template <class Velocity>
Model cylinder(Method method, Velocity velocity, int cells = 20) {
  Model model;
  const double h = 1.0 / cells;
  model.grid = GridGeometry::walled(Vec2(0.0, 0.0), h, cells, cells);
  const double spacing = 0.5 * h, area = spacing * spacing;
  std::vector<Vec2> X;
  for (int j = 0; j < 2 * cells; ++j)
    for (int i = 0; i < 2 * cells; ++i) {
      const Vec2 x = spacing * Vec2(i + 0.5, j + 0.5);
      if (x.x() >= 0.3 && x.x() <= 0.7) X.push_back(x);
    }
  Particles& P = model.particles;
  P.resize(X.size());
  P.hoop_stretch.assign(X.size(), 1.0);
  P.hoop_stress.assign(X.size(), 0.0);
  for (std::size_t p = 0; p < X.size(); ++p) {
    P.position[p] = P.reference_position[p] = X[p];
    P.velocity[p] = velocity(X[p]);
    P.reference_volume[p] = P.volume[p] = X[p].x() * area;
    P.mass[p] = kDensity * P.reference_volume[p];
  }
  if (method != Method::linear) P.half_size.assign(X.size(), Vec2(0.5 * spacing, 0.5 * spacing));
  return model;
}

const Method kMethods[] = {Method::linear, Method::gimp, Method::cpdi, Method::cpdi_exact};

// A uniform radial velocity v = (c, 0) has the hoop rate v_r / r = c / r_p: a
// uniform nodal velocity is reproduced exactly by any projection, and
// sum_k <S_k / r> = 1 / r_p (property (e)). After one USL step every particle
// has F_theta = 1 + dt c / r_p and F unchanged to round-off, for all three
// methods. Measured: F_theta exact, F within 4.4e-18 of I; tolerance 1e-14.
TEST(AxisymmetricStep, UniformRadialVelocityGivesHoopRateOverRadius) {
  const double c = 0.2, dt = 1e-3;
  for (Method method : kMethods) {
    auto stepper = mpmvv::make_stepper(cylinder(method, [c](const Vec2&) { return Vec2(c, 0.0); }),
                                       SolverOptions{method, Scheme::usl, Geometry::axisymmetric}, kSolid, nullptr);
    stepper->step(0.0, dt, dt);
    const Particles& P = stepper->model().particles;
    double worst_hoop = 0.0, worst_F = 0.0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      const double expected = 1.0 + dt * c / P.reference_position[p].x();
      worst_hoop = std::max(worst_hoop, std::abs(P.hoop_stretch[p] - expected));
      worst_F = std::max(worst_F, (P.deformation_gradient[p] - Mat2::Identity()).cwiseAbs().maxCoeff());
      EXPECT_NEAR(P.position[p].x(), P.reference_position[p].x() + dt * c, 1e-15) << to_string(method);
    }
    RecordProperty(std::string(to_string(method)) + "_hoop", scientific(worst_hoop));
    RecordProperty(std::string(to_string(method)) + "_F", scientific(worst_F));
    EXPECT_LE(worst_hoop, 1e-14) << to_string(method);
    EXPECT_LE(worst_F, 1e-14) << to_string(method);
  }
}

// A uniform radial expansion v = (c r, 0) has the hoop rate v_r / r = c. One
// USL step gives interior particles (two cells from the free surfaces)
// F_theta = 1 + dt c (1 + e) with e = k h^2 / r_p^2, not round-off: the nodal
// velocity is the lumped-mass projection sum_p S m_p v_p / sum_p S m_p, and
// with masses proportional to R the particles outside a node outweigh those
// inside, so v_g = c (r_g + k h^2 / r_g), k the second moment of the weights
// about the node over h^2: 1/6 for the r-weighted GIMP and CPDI averages (the
// hat's own), 3/16 for point particles at +-h/4, +-3h/4 (linear MPM).
// Measured e r_p^2 / h^2: linear 0.1876-0.1880, gimp and cpdi 0.1667-0.1671
// at h = 0.05 and 0.025 alike (so e falls as h^2). Band: within 2% of k.
TEST(AxisymmetricStep, UniformExpansionGivesHoopRateCToSecondOrder) {
  const double c = 0.2, dt = 1e-3;
  for (Method method : kMethods) {
    const double k = method == Method::linear ? 3.0 / 16.0 : 1.0 / 6.0;
    for (int cells : {20, 40}) {
      const double h = 1.0 / cells;
      auto stepper = mpmvv::make_stepper(
          cylinder(method, [c](const Vec2& x) { return Vec2(c * x.x(), 0.0); }, cells),
          SolverOptions{method, Scheme::usl, Geometry::axisymmetric}, kSolid, nullptr);
      stepper->step(0.0, dt, dt);
      const Particles& P = stepper->model().particles;
      double low = 1e300, high = 0.0;
      for (std::size_t p = 0; p < P.size(); ++p) {
        const Vec2& X = P.reference_position[p];
        if (!(X.x() > 0.3 + 2.0 * h && X.x() < 0.7 - 2.0 * h)) continue;
        const double e = (P.hoop_stretch[p] - 1.0) / (dt * c) - 1.0;
        low = std::min(low, e * X.x() * X.x() / (h * h));
        high = std::max(high, e * X.x() * X.x() / (h * h));
      }
      RecordProperty(std::string(to_string(method)) + "_cells" + std::to_string(cells) + "_coefficient",
                     scientific(low) + " " + scientific(high));
      EXPECT_GE(low, 0.98 * k) << to_string(method) << " cells " << cells;
      EXPECT_LE(high, 1.02 * k) << to_string(method) << " cells " << cells;
    }
  }
}

// make_stepper refuses an axisymmetric model whose particles lack the hoop
// arrays, one with a particle on or behind the axis, and a grid whose left
// wall is not the axis; the same model with its hoop arrays is accepted.
TEST(AxisymmetricStep, MakeStepperRejectsIncompleteModels) {
  const SolverOptions rz{Method::cpdi, Scheme::usl, Geometry::axisymmetric};
  auto still = [](const Vec2&) { return Vec2(0.0, 0.0); };
  EXPECT_NO_THROW(mpmvv::make_stepper(cylinder(Method::cpdi, still), rz, kSolid, nullptr));

  Model no_stretch = cylinder(Method::cpdi, still);
  no_stretch.particles.hoop_stretch.clear();
  EXPECT_THROW(mpmvv::make_stepper(no_stretch, rz, kSolid, nullptr), std::invalid_argument);

  Model no_stress = cylinder(Method::cpdi, still);
  no_stress.particles.hoop_stress.pop_back();
  EXPECT_THROW(mpmvv::make_stepper(no_stress, rz, kSolid, nullptr), std::invalid_argument);

  for (double r : {0.0, -0.01}) {
    Model on_axis = cylinder(Method::linear, still);
    on_axis.particles.position[7].x() = r;
    EXPECT_THROW(mpmvv::make_stepper(on_axis, SolverOptions{Method::linear, Scheme::usl, Geometry::axisymmetric},
                                     kSolid, nullptr),
                 std::invalid_argument)
        << "r = " << r;
  }

  Model shifted = cylinder(Method::cpdi, still);
  shifted.grid = GridGeometry::walled(Vec2(-1.0, 0.0), 0.05, 40, 20);
  EXPECT_THROW(mpmvv::make_stepper(shifted, rz, kSolid, nullptr), std::invalid_argument);

  // The B-spline basis reaches one node beyond the nearest: nodes at r < 0
  // next to the axis. Refused by name, not run with weights of no meaning.
  try {
    mpmvv::make_stepper(cylinder(Method::linear, still),
                        SolverOptions{Method::bspline, Scheme::usl, Geometry::axisymmetric}, kSolid, nullptr);
    ADD_FAILURE() << "method bspline was accepted in r-z";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("method bspline is plane strain only"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------- walls

// The index of the node inside (or on) the walls whose mirror image node i
// is, along one axis of n nodes with `ghost` layers, and whether it is mirrored.
struct Mirror {
  int index;
  bool mirrored;
};
Mirror mirror_of(int i, int n, int ghost) {
  const int low = ghost, high = n - 1 - ghost;
  if (i < low) return {2 * low - i, true};
  if (i > high) return {2 * high - i, true};
  return {i, false};
}

// After apply_walls on arbitrary node velocities and accelerations:
// nodes on a wall have no normal component; every node inside the walls keeps
// the rest of its values; every ghost node k cells beyond a wall is the mirror
// image of the node k cells inside (tangential equal, normal negated), the
// corner ghosts mirrored in both directions. One and two ghost layers.
TEST(Walls, WallNodesStopAndGhostNodesMirror) {
  for (int ghost : {1, 2}) {
    const GridGeometry grid = GridGeometry::walled(Vec2(0.0, 0.0), 0.25, 8, 6, ghost);
    const int nx = grid.nodes_x(), ny = grid.nodes_y();
    GridFields g;
    g.resize(grid.node_count());
    std::mt19937 rng(43);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (std::size_t k = 0; k < grid.node_count(); ++k) {
      g.velocity[k] = Vec2(u(rng), u(rng));
      g.acceleration[k] = Vec2(u(rng), u(rng));
    }
    const GridFields before = g;
    mpmvv::apply_walls(grid, g);

    // What a node inside or on the walls holds afterwards: its own values,
    // without the normal component on a wall.
    auto expected_inside = [&](const std::vector<Vec2>& field, int i, int j) {
      Vec2 v = field[std::size_t(grid.node(i, j))];
      if (i == ghost || i == nx - 1 - ghost) v.x() = 0.0;
      if (j == ghost || j == ny - 1 - ghost) v.y() = 0.0;
      return v;
    };
    int ghosts = 0, corners = 0;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const Mirror mi = mirror_of(i, nx, ghost), mj = mirror_of(j, ny, ghost);
        const Vec2 sign(mi.mirrored ? -1.0 : 1.0, mj.mirrored ? -1.0 : 1.0);
        const std::size_t k = std::size_t(grid.node(i, j));
        const Vec2 v = sign.cwiseProduct(expected_inside(before.velocity, mi.index, mj.index));
        const Vec2 a = sign.cwiseProduct(expected_inside(before.acceleration, mi.index, mj.index));
        EXPECT_EQ(g.velocity[k], v) << "ghost " << ghost << " node (" << i << ", " << j << ")";
        EXPECT_EQ(g.acceleration[k], a) << "ghost " << ghost << " node (" << i << ", " << j << ")";
        ghosts += mi.mirrored || mj.mirrored;
        corners += mi.mirrored && mj.mirrored;
      }
    EXPECT_EQ(corners, 4 * ghost * ghost);
    EXPECT_EQ(ghosts, nx * ny - (nx - 2 * ghost) * (ny - 2 * ghost));
    // The walls: nodes on them have no normal velocity or acceleration.
    for (int j = 0; j < ny; ++j)
      for (int i : {ghost, nx - 1 - ghost}) {
        EXPECT_EQ(g.velocity[std::size_t(grid.node(i, j))].x(), 0.0);
        EXPECT_EQ(g.acceleration[std::size_t(grid.node(i, j))].x(), 0.0);
      }
    for (int i = 0; i < nx; ++i)
      for (int j : {ghost, ny - 1 - ghost}) {
        EXPECT_EQ(g.velocity[std::size_t(grid.node(i, j))].y(), 0.0);
        EXPECT_EQ(g.acceleration[std::size_t(grid.node(i, j))].y(), 0.0);
      }
  }
}

// With mirrored ghosts, a particle whose support reaches past the axis reads
// the mirrored radial velocity: a radial velocity field odd in r (v_r = c r
// on the nodes inside, mirrored to the ghosts) interpolates to c r_p with the
// bilinear weights and to the hoop rate c, also for CPDI domains that cross the
// axis (measured 1.9e-16 relative; tolerance 1e-14 absolute, c = 0.3).
TEST(Walls, MirroredGhostsExtendAnOddRadialVelocity) {
  const GridGeometry grid = rz_grid();
  GridFields g;
  g.resize(grid.node_count());
  const double c = 0.3;
  for (int j = 0; j < grid.nodes_y(); ++j)
    for (int i = 0; i < grid.nodes_x(); ++i)
      g.velocity[std::size_t(grid.node(i, j))] = Vec2(c * std::abs(grid.node_position(i, j).x()), 0.1);
  mpmvv::apply_walls(grid, g);
  const Particles P = particles_at({{0.04, 1.0}, {0.05, 0.6}, {0.0625, 0.3}}, mpmvv::testing::simple_shear(0.4));
  const CpdiShapeT<kRz> shape = CpdiShapeT<kRz>::bind(grid, P);
  double worst = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    Stencil<CpdiShapeT<kRz>::stencil_size> s;
    shape.evaluate(p, s);
    double hoop_rate = 0.0;
    for (int k = 0; k < s.count; ++k) hoop_rate += s.hoop[k] * g.velocity[std::size_t(s.node[k])].x();
    worst = std::max(worst, std::abs(hoop_rate - c) / c);
    EXPECT_NEAR(hoop_rate, c, 1e-14) << P.position[p].transpose();
  }
  RecordProperty("worst_relative", scientific(worst));
}

}  // namespace
