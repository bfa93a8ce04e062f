// Shape functions in r-z (axisymmetric; solver/shape/): linear, uGIMP and
// CPDI keep partition of unity, zero gradient sum, linear completeness and the
// hoop factors' identities at interior positions and beside the axis, the
// r weighting moves the centroid out, and uGIMP's r-weighted factors equal
// the quadrature of their definition.
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


}  // namespace
