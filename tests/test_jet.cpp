// Forward-mode derivatives (mms/jet.hpp) are exact: compositions against
// closed forms, nested jets' Hessians, Eigen matrices of jets.
#include <gtest/gtest.h>

#include "mms_cases.hpp"
#include "support.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "mms/axis_aligned.hpp"
#include "mms/exact_solution.hpp"
#include "mms/expanding_ring.hpp"
#include "mms/jet.hpp"
#include "mms/manufactured.hpp"
#include "mms/residual_check.hpp"
#include "mms/ring.hpp"
#include "mms/rz_cylinder.hpp"
#include "tools/app/scene/setup.hpp"

namespace {

using mpmvv::testing::scientific;
using namespace mpmvv::testing::mms_cases;  // the problems and the names they use

// ---------------------------------------------------------------- Jet

using Jet2 = Jet<double, 2>;
using Hessian2 = Jet<Jet2, 2>;

// A function of (x, y) with its gradient in closed form.
struct Composition {
  const char* name;
  Jet2 (*f)(const Jet2& x, const Jet2& y);
  std::array<double, 2> (*gradient)(double x, double y);
};

const Composition kCompositions[] = {
    {"sin(x y)", [](const Jet2& x, const Jet2& y) { return sin(x * y); },
     [](double x, double y) { return std::array<double, 2>{y * std::cos(x * y), x * std::cos(x * y)}; }},
    {"cos(x) / y", [](const Jet2& x, const Jet2& y) { return cos(x) / y; },
     [](double x, double y) { return std::array<double, 2>{-std::sin(x) / y, -std::cos(x) / (y * y)}; }},
    {"exp(x) log(y)", [](const Jet2& x, const Jet2& y) { return exp(x) * log(y); },
     [](double x, double y) { return std::array<double, 2>{std::exp(x) * std::log(y), std::exp(x) / y}; }},
    {"sqrt(x^2 + y^2)", [](const Jet2& x, const Jet2& y) { return sqrt(x * x + y * y); },
     [](double x, double y) {
       const double r = std::sqrt(x * x + y * y);
       return std::array<double, 2>{x / r, y / r};
     }},
    {"pow(x y, 2.5)", [](const Jet2& x, const Jet2& y) { return pow(x * y, 2.5); },
     [](double x, double y) {
       const double p = 2.5 * std::pow(x * y, 1.5);
       return std::array<double, 2>{p * y, p * x};
     }},
    {"atan2(y, x)", [](const Jet2& x, const Jet2& y) { return atan2(y, x); },
     [](double x, double y) {
       const double r2 = x * x + y * y;
       return std::array<double, 2>{-y / r2, x / r2};
     }},
    {"x / (1 + y^2) - 3 x y", [](const Jet2& x, const Jet2& y) { return x / (1.0 + y * y) - 3.0 * x * y; },
     [](double x, double y) {
       const double q = 1.0 + y * y;
       return std::array<double, 2>{1.0 / q - 3.0 * y, -2.0 * x * y / (q * q) - 3.0 * x};
     }},
    {"exp(sin(x) cos(y)) / sqrt(x)", [](const Jet2& x, const Jet2& y) { return exp(sin(x) * cos(y)) / sqrt(x); },
     [](double x, double y) {
       const double e = std::exp(std::sin(x) * std::cos(y)), s = std::sqrt(x);
       return std::array<double, 2>{e * std::cos(x) * std::cos(y) / s - 0.5 * e / (x * s),
                                    -e * std::sin(x) * std::sin(y) / s};
     }},
};

// Points with x, y > 0 (log, sqrt and pow need them) in every quadrant of the
// atan2 angle that matters: both of order one, one small, one large.
const std::array<double, 2> kJetPoints[] = {{0.7, 1.3}, {2.1, 0.4}, {0.05, 3.0}, {4.5, 2.2}, {1.0, 1.0}};

// Each composition's two partials equal the closed form at every point to
// 1e-14 relative. Measured worst: 2.2e-16 (one rounding step); 1e-14 allows
// about fifty.
TEST(Jet, DerivativesOfCompositionsMatchClosedForms) {
  double worst = 0.0;
  for (const Composition& c : kCompositions)
    for (const auto& [x, y] : kJetPoints) {
      const Jet2 f = c.f(Jet2::variable(x, 0), Jet2::variable(y, 1));
      const std::array<double, 2> g = c.gradient(x, y);
      for (int k = 0; k < 2; ++k) {
        const double e = relative_difference(f.d[std::size_t(k)], g[std::size_t(k)]);
        worst = std::max(worst, e);
        EXPECT_LE(e, 1e-14) << c.name << " at (" << x << ", " << y << ") d" << k << ": " << f.d[std::size_t(k)]
                            << " vs " << g[std::size_t(k)];
      }
    }
  RecordProperty("worst_relative_error", scientific(worst));
}

// Mixed with plain numbers and with the compound assignments, a Jet gives the
// same value and derivatives as the expression written with Jets only.
TEST(Jet, ConstantsAndCompoundAssignmentsAreConsistent) {
  const Jet2 x = Jet2::variable(0.8, 0), y = Jet2::variable(-1.7, 1);
  Jet2 a = x;
  a *= y;
  a += 2.0;
  a /= x;
  a -= y;
  const Jet2 b = (x * y + Jet2(2.0)) / x - y;
  EXPECT_DOUBLE_EQ(a.v, b.v);
  for (int k = 0; k < 2; ++k) EXPECT_DOUBLE_EQ(a.d[std::size_t(k)], b.d[std::size_t(k)]);
  // d/dx (y + 2/x) = -2 / x^2, d/dy = 0 (the y terms cancel).
  EXPECT_NEAR(a.d[0], -2.0 / (0.8 * 0.8), 1e-15 * 2.0 / (0.8 * 0.8));
  EXPECT_NEAR(a.d[1], 0.0, 1e-15);
  // -x and +x, and a comparison that looks at values only.
  EXPECT_EQ((-x).d[0], -1.0);
  EXPECT_EQ((+x).d[0], 1.0);
  EXPECT_TRUE(y < x);
  EXPECT_FALSE(x < y);
}

// x seeded in both levels of a nested jet: value, the gradient twice (inner
// and outer) and the Hessian.
struct NestedResult {
  double value;
  std::array<double, 2> inner, outer;
  std::array<std::array<double, 2>, 2> hessian;
};

template <class F>
NestedResult nested(F f, double x, double y) {
  const double X[2] = {x, y};
  Hessian2 v[2];
  for (int J = 0; J < 2; ++J) {
    std::array<Jet2, 2> outer{};
    outer[std::size_t(J)] = Jet2(1.0);
    v[J] = Hessian2(Jet2::variable(X[J], J), outer);
  }
  const Hessian2 r = f(v[0], v[1]);
  NestedResult n{};
  n.value = r.v.v;
  for (int i = 0; i < 2; ++i) {
    n.inner[std::size_t(i)] = r.v.d[std::size_t(i)];
    n.outer[std::size_t(i)] = r.d[std::size_t(i)].v;
    for (int j = 0; j < 2; ++j) n.hessian[std::size_t(i)][std::size_t(j)] = r.d[std::size_t(i)].d[std::size_t(j)];
  }
  return n;
}

// Jet<Jet<double, 2>, 2> gives the exact Hessian of p = x^3 y^2 - 2 x y +
// 3 y^3 + 5: at points with few binary digits every product is exact, so the
// Hessian is equal, not close (measured: bit-for-bit).
TEST(Jet, NestedJetGivesExactHessianOfPolynomial) {
  for (const auto& [x, y] : {std::array<double, 2>{1.5, -0.75}, {2.0, 0.5}, {-0.25, 3.0}}) {
    const NestedResult n = nested(
        [](const Hessian2& a, const Hessian2& b) { return a * a * a * b * b - 2.0 * a * b + 3.0 * b * b * b + 5.0; },
        x, y);
    EXPECT_EQ(n.value, x * x * x * y * y - 2.0 * x * y + 3.0 * y * y * y + 5.0);
    EXPECT_EQ(n.inner[0], 3.0 * x * x * y * y - 2.0 * y);
    EXPECT_EQ(n.inner[1], 2.0 * x * x * x * y - 2.0 * x + 9.0 * y * y);
    EXPECT_EQ(n.outer, n.inner);
    EXPECT_EQ(n.hessian[0][0], 6.0 * x * y * y);
    EXPECT_EQ(n.hessian[0][1], 6.0 * x * x * y - 2.0);
    EXPECT_EQ(n.hessian[1][0], 6.0 * x * x * y - 2.0);
    EXPECT_EQ(n.hessian[1][1], 2.0 * x * x * x + 18.0 * y);
  }
}

// The nested jet's Hessian of sin(x y) matches the closed form
//   [[-y^2 s, c - x y s], [c - x y s, -x^2 s]],  s = sin(x y), c = cos(x y),
// to 1e-14 relative (measured worst 1.4e-16), and is symmetric.
TEST(Jet, NestedJetGivesHessianOfSinProduct) {
  double worst = 0.0;
  for (const auto& [x, y] : kJetPoints) {
    const NestedResult n = nested([](const Hessian2& a, const Hessian2& b) { return sin(a * b); }, x, y);
    const double s = std::sin(x * y), c = std::cos(x * y);
    const double expected[2][2] = {{-y * y * s, c - x * y * s}, {c - x * y * s, -x * x * s}};
    EXPECT_EQ(n.hessian[0][1], n.hessian[1][0]);
    for (int i = 0; i < 2; ++i) {
      EXPECT_LE(relative_difference(n.inner[std::size_t(i)], (i == 0 ? y : x) * c), 1e-14);
      for (int j = 0; j < 2; ++j) {
        const double e = relative_difference(n.hessian[std::size_t(i)][std::size_t(j)], expected[i][j]);
        worst = std::max(worst, e);
        EXPECT_LE(e, 1e-14) << "(" << x << ", " << y << ") H" << i << j;
      }
    }
  }
  RecordProperty("worst_relative_error", scientific(worst));
}

// Eigen 2x2 matrices of jets: d/ds det(F(s)) by the product of matrices and the
// inverse by cofactors, against the closed form. F(s) = [[1 + s, s^2],
// [sin s, 2 - s]], G(s) = [[cos s, 1], [s, 3]]:
//   det(F G)' = (det F det G)',  det F = (1 + s)(2 - s) - s^2 sin s,
// and Jacobi's formula det F' = det F tr(F^-1 F') with F^-1 from cofactors.
// Measured worst 8.9e-16 relative; tolerance 1e-14.
TEST(Jet, EigenMatricesOfJetsDifferentiateDeterminants) {
  using J1 = Jet<double, 1>;
  using M = Eigen::Matrix<J1, 2, 2>;
  double worst = 0.0;
  for (double s0 : {-0.6, 0.1, 0.9, 1.7}) {
    const J1 s = J1::variable(s0, 0);
    M F, G;
    F << 1.0 + s, s * s, sin(s), 2.0 - s;
    G << cos(s), J1(1.0), s, J1(3.0);
    const M FG = F * G;
    const J1 det_fg = FG(0, 0) * FG(1, 1) - FG(0, 1) * FG(1, 0);
    const J1 det_f = F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
    M F_inverse;
    F_inverse << F(1, 1) / det_f, -F(0, 1) / det_f, -F(1, 0) / det_f, F(0, 0) / det_f;
    const M identity = F * F_inverse;

    const double det_f_value = (1.0 + s0) * (2.0 - s0) - s0 * s0 * std::sin(s0);
    const double det_f_prime = (2.0 - s0) - (1.0 + s0) - 2.0 * s0 * std::sin(s0) - s0 * s0 * std::cos(s0);
    const double det_g_value = 3.0 * std::cos(s0) - s0, det_g_prime = -3.0 * std::sin(s0) - 1.0;
    EXPECT_LE(relative_difference(det_f.d[0], det_f_prime), 1e-14) << s0;
    EXPECT_LE(relative_difference(det_fg.v, det_f_value * det_g_value), 1e-14) << s0;
    EXPECT_LE(relative_difference(det_fg.d[0], det_f_prime * det_g_value + det_f_value * det_g_prime), 1e-14) << s0;
    // F F^-1 = I with a zero derivative, and Jacobi's formula.
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        EXPECT_NEAR(identity(i, j).v, i == j ? 1.0 : 0.0, 1e-15);
        EXPECT_NEAR(identity(i, j).d[0], 0.0, 1e-14);
      }
    double trace = 0.0;
    for (int i = 0; i < 2; ++i)
      for (int k = 0; k < 2; ++k) trace += F_inverse(i, k).v * F(k, i).d[0];
    EXPECT_LE(relative_difference(det_f.v * trace, det_f_prime), 1e-14) << s0;
    worst = std::max({worst, relative_difference(det_f.d[0], det_f_prime),
                      relative_difference(det_fg.d[0], det_f_prime * det_g_value + det_f_value * det_g_prime),
                      relative_difference(det_f.v * trace, det_f_prime)});
  }
  RecordProperty("worst_relative_error", scientific(worst));
}


}  // namespace
