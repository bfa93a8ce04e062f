// The lanes' sin, cos and log (solver/lane_math.hpp): within one unit in
// the last place of the exact values, the same bits from every build of the
// kernels this CPU can run, and libm's values beyond the lanes' range.
#include <gtest/gtest.h>

#include "support.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "solver/lane_math.hpp"

namespace {

using mpmvv::LaneBuild;

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

// |value - exact| in units of the last place of the exact value rounded to
// a double; the exact value from the x87's long double (64-bit significand).
double ulps(double value, long double exact) {
  const double rounded = double(exact);
  const double ulp = std::nextafter(std::abs(rounded), std::numeric_limits<double>::infinity()) - std::abs(rounded);
  return double(std::abs((long double)value - exact) / ulp);
}

// Arguments of every quadrant: random over +-40 and +-1e5, the ring's
// range (|alpha| < 2), the ends of the reduced interval (odd multiples of
// pi/4), near multiples of pi/2 (where one of the two is near zero), and
// tiny ones.
std::vector<double> arguments() {
  std::vector<double> x;
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> wide(-40.0, 40.0), wider(-1e5, 1e5), ring(-2.0, 2.0);
  for (int k = 0; k < 20000; ++k) x.push_back(wide(rng));
  for (int k = 0; k < 2000; ++k) x.push_back(wider(rng));
  for (int k = 0; k < 20000; ++k) x.push_back(ring(rng));
  for (int k = -40; k <= 40; ++k) {
    const double at = k * std::numbers::pi / 4.0;
    x.push_back(at);
    x.push_back(std::nextafter(at, 1e9));
    x.push_back(std::nextafter(at, -1e9));
  }
  for (double tiny : {0.0, -0.0, 1e-300, -1e-300, 1e-8, -3e-9, 5e-324}) x.push_back(tiny);
  return x;
}

// Measured largest errors on this set: 0.72 ulp (sin) and 0.75 ulp (cos).
TEST(LaneSinCos, WithinOneUnitInTheLastPlace) {
  const std::vector<double> x = arguments();
  std::vector<double> s(x.size()), c(x.size());
  mpmvv::lane_sincos(x.size(), x.data(), s.data(), c.data());
  double worst_sin = 0.0, worst_cos = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    worst_sin = std::max(worst_sin, ulps(s[k], std::sin((long double)x[k])));
    worst_cos = std::max(worst_cos, ulps(c[k], std::cos((long double)x[k])));
  }
  RecordProperty("largest_sin_error_ulp", std::to_string(worst_sin));
  RecordProperty("largest_cos_error_ulp", std::to_string(worst_cos));
  EXPECT_LE(worst_sin, 1.0);
  EXPECT_LE(worst_cos, 1.0);
  // Signs of zero and exact values: sin(+-0) = +-0, cos 0 = 1.
  const double zeros[2] = {0.0, -0.0};
  double sz[2], cz[2];
  mpmvv::lane_sincos(2, zeros, sz, cz);
  EXPECT_EQ(bits(sz[0]), bits(0.0));
  EXPECT_EQ(bits(sz[1]), bits(-0.0));
  EXPECT_EQ(cz[0], 1.0);
  EXPECT_EQ(cz[1], 1.0);
}

// Every build, whatever its width, and every count (the last few through a
// padded vector) gives the bits of the baseline build on whole arrays.
TEST(LaneSinCos, EveryBuildAndCountGivesTheSameBits) {
  const std::vector<double> x = arguments();
  std::vector<double> s0(x.size()), c0(x.size());
  mpmvv::lane_sincos(LaneBuild::baseline, x.size(), x.data(), s0.data(), c0.data());
  ASSERT_FALSE(mpmvv::testing::lane_builds_of_this_cpu().empty());
  for (LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
    SCOPED_TRACE(mpmvv::name(build));
    std::vector<double> s(x.size()), c(x.size());
    mpmvv::lane_sincos(build, x.size(), x.data(), s.data(), c.data());
    for (std::size_t k = 0; k < x.size(); ++k) {
      ASSERT_EQ(bits(s[k]), bits(s0[k])) << "x = " << x[k];
      ASSERT_EQ(bits(c[k]), bits(c0[k])) << "x = " << x[k];
    }
    for (std::size_t count = 1; count <= 19; ++count) {
      std::vector<double> sc(count), cc(count);
      mpmvv::lane_sincos(build, count, x.data() + 5, sc.data(), cc.data());
      for (std::size_t k = 0; k < count; ++k) {
        EXPECT_EQ(bits(sc[k]), bits(s0[5 + k])) << "count " << count;
        EXPECT_EQ(bits(cc[k]), bits(c0[5 + k])) << "count " << count;
      }
    }
  }
}

// Past kLaneSinCosLimit, and for infinities and NaN, the values are libm's.
TEST(LaneSinCos, BeyondTheLimitTheValuesAreLibms) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> x = {std::nextafter(mpmvv::kLaneSinCosLimit, inf), -3e7, 1e300, inf, -inf,
                                 std::numeric_limits<double>::quiet_NaN(), 12.5};
  for (LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
    SCOPED_TRACE(mpmvv::name(build));
    std::vector<double> s(x.size()), c(x.size());
    mpmvv::lane_sincos(build, x.size(), x.data(), s.data(), c.data());
    for (std::size_t k = 0; k + 1 < x.size(); ++k) {
      if (std::isnan(std::sin(x[k]))) {
        EXPECT_TRUE(std::isnan(s[k]) && std::isnan(c[k])) << "x = " << x[k];
        continue;
      }
      EXPECT_EQ(bits(s[k]), bits(std::sin(x[k]))) << "x = " << x[k];
      EXPECT_EQ(bits(c[k]), bits(std::cos(x[k]))) << "x = " << x[k];
    }
    // And within it the lanes' own: 12.5 is reduced by 4 pi/2.
    EXPECT_LE(ulps(s.back(), std::sin(12.5L)), 1.0);
    EXPECT_LE(ulps(c.back(), std::cos(12.5L)), 1.0);
    // One such argument alone, in a full vector or among the last few.
    for (std::size_t at = 0; at < 11; ++at) {
      std::vector<double> y(11, 0.5), sy(11), cy(11);
      y[at] = 1e300;
      mpmvv::lane_sincos(build, y.size(), y.data(), sy.data(), cy.data());
      EXPECT_EQ(bits(sy[at]), bits(std::sin(1e300))) << "at " << at;
      EXPECT_EQ(bits(cy[at]), bits(std::cos(1e300))) << "at " << at;
    }
  }
}

// Arguments of ln: random over the J a solid reaches (0.05 to 20) and over
// every exponent, near 1 (where ln x is near zero and f - f^2/2 cancels),
// both sides of sqrt(2) and sqrt(1/2) (where the reduction changes the
// exponent), powers of two and the ends of the normal range.
std::vector<double> log_arguments() {
  std::vector<double> x;
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> solid(0.05, 20.0), exponent(-1021.0, 1023.0), near_one(-1e-3, 1e-3);
  for (int k = 0; k < 30000; ++k) x.push_back(solid(rng));
  for (int k = 0; k < 10000; ++k) x.push_back(std::exp2(exponent(rng)));
  for (int k = 0; k < 10000; ++k) x.push_back(1.0 + near_one(rng));
  for (double at : {std::sqrt(2.0), std::sqrt(0.5), 1.0, 2.0, 0.5}) {
    double up = at, down = at;
    for (int k = 0; k < 50; ++k) {
      x.push_back(up);
      x.push_back(down);
      up = std::nextafter(up, 10.0);
      down = std::nextafter(down, 0.0);
    }
  }
  for (int e = -1022; e <= 1023; e += 7) x.push_back(std::ldexp(1.0, e));
  x.push_back(std::numeric_limits<double>::min());
  x.push_back(std::numeric_limits<double>::max());
  return x;
}

// Measured largest error on this set: printed as a property.
TEST(LaneLog, WithinOneUnitInTheLastPlace) {
  const std::vector<double> x = log_arguments();
  std::vector<double> l(x.size());
  mpmvv::lane_log(x.size(), x.data(), l.data());
  double worst = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (x[k] == 1.0) {
      EXPECT_EQ(bits(l[k]), bits(0.0));  // ln 1 = +0 exactly
      continue;
    }
    worst = std::max(worst, ulps(l[k], std::log((long double)x[k])));
  }
  RecordProperty("largest_log_error_ulp", std::to_string(worst));
  EXPECT_LE(worst, 1.0);
}

TEST(LaneLog, EveryBuildAndCountGivesTheSameBits) {
  const std::vector<double> x = log_arguments();
  std::vector<double> l0(x.size());
  mpmvv::lane_log(LaneBuild::baseline, x.size(), x.data(), l0.data());
  for (LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
    SCOPED_TRACE(mpmvv::name(build));
    std::vector<double> l(x.size());
    mpmvv::lane_log(build, x.size(), x.data(), l.data());
    for (std::size_t k = 0; k < x.size(); ++k) ASSERT_EQ(bits(l[k]), bits(l0[k])) << "x = " << x[k];
    for (std::size_t count = 1; count <= 19; ++count) {
      std::vector<double> lc(count);
      mpmvv::lane_log(build, count, x.data() + 3, lc.data());
      for (std::size_t k = 0; k < count; ++k) EXPECT_EQ(bits(lc[k]), bits(l0[3 + k])) << "count " << count;
    }
  }
}

// Zero, negative, subnormal, infinite and NaN arguments take libm's values.
TEST(LaneLog, OutsideTheNormalRangeTheValuesAreLibms) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> x = {0.0, -0.0, -1.0, 5e-324, std::numeric_limits<double>::denorm_min() * 77,
                                 inf, -inf, 3.0};
  for (LaneBuild build : mpmvv::testing::lane_builds_of_this_cpu()) {
    SCOPED_TRACE(mpmvv::name(build));
    std::vector<double> l(x.size());
    mpmvv::lane_log(build, x.size(), x.data(), l.data());
    for (std::size_t k = 0; k + 1 < x.size(); ++k) {
      if (std::isnan(std::log(x[k]))) {
        EXPECT_TRUE(std::isnan(l[k])) << "x = " << x[k];
        continue;
      }
      EXPECT_EQ(bits(l[k]), bits(std::log(x[k]))) << "x = " << x[k];
    }
    EXPECT_LE(ulps(l.back(), std::log(3.0L)), 1.0);
    // One such argument alone, in a full vector or among the last few.
    for (const double outside : {0.0, -2.0, 5e-324, inf, std::numeric_limits<double>::quiet_NaN()})
      for (std::size_t at = 0; at < 11; ++at) {
        std::vector<double> y(11, 2.0), ly(11);
        y[at] = outside;
        mpmvv::lane_log(build, y.size(), y.data(), ly.data());
        if (std::isnan(std::log(outside))) EXPECT_TRUE(std::isnan(ly[at])) << outside << " at " << at;
        else EXPECT_EQ(bits(ly[at]), bits(std::log(outside))) << outside << " at " << at;
      }
  }
}

}  // namespace
