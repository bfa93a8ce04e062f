// The lane kernels of lane_math.hpp (lane_vectors.hpp says how they are built).
//
// sin and cos: x = k pi/2 + r with k the integer nearest x 2/pi and |r| <=
// pi/4, r formed in three steps (Cody and Waite's reduction) with pi/2 split
// into P1 + P2 + P3, P1 and P2 of 33 significant bits, so that k P1 and k P2
// are exact for |k| < 2^20 (|x| up to kLaneSinCosLimit), and kept with the
// rounding error of its second step as a low part. Then the Taylor
// series of sin r to r^17 and of cos r to r^16, whose first omitted terms are
// below 2e-19 and 3e-18 of the value on |r| <= pi/4 (a few thousandths of a
// unit in the last place), and the quadrant k mod 4 picks and signs them:
// (sin, cos) x = (s, c), (c, -s), (-s, -c), (-c, s) for k = 0, 1, 2, 3.
// Measured against long double on 2 million arguments each over |x| < 0.78,
// 2, 40 and 1e5: at most 0.79 units in the last place (libm: 0.52).
#include "lane_math.hpp"

#include "lane_log.hpp"
#include "lane_vectors.hpp"

#if defined(MPMVV_LANE_DISPATCH)
#include <cmath>
#include <limits>
#endif

namespace mpmvv {

namespace {

using namespace lanes::MPMVV_LANE_BUILD_NS;

constexpr double kTwoOverPi = 0x1.45f306dc9c883p-1;
constexpr double kHalfPi1 = 0x1.921fb54400000p+0;   // pi/2's first 33 bits
constexpr double kHalfPi2 = 0x1.0b4611a600000p-34;  // its next 33
constexpr double kHalfPi3 = 0x1.3198a2e037073p-69;  // the rest, rounded
// 1.5 2^52: added and taken away, it rounds a double below 2^51 to the
// nearest integer (ties to even).
constexpr double kRoundingShift = 0x1.8p52;

// The series' coefficients from the highest power down, each 1 / n! with
// its sign: sin r = r + r^3 (-1/3! + r^2 (1/5! + ...)) to r^17, cos r = 1 -
// r^2 / 2 + r^4 (1/4! - r^2 (1/6! ...)) to r^16. Every n! is an integer
// below 2^53, so each quotient is the correctly rounded 1 / n!.
constexpr double kSinSeries[8] = {
    1.0 / 355687428096000.0, -1.0 / 1307674368000.0, 1.0 / 6227020800.0, -1.0 / 39916800.0,
    1.0 / 362880.0,          -1.0 / 5040.0,          1.0 / 120.0,        -1.0 / 6.0};
constexpr double kCosSeries[7] = {1.0 / 20922789888000.0, -1.0 / 87178291200.0, 1.0 / 479001600.0, -1.0 / 3628800.0,
                                  1.0 / 40320.0,          -1.0 / 720.0,         1.0 / 24.0};

// Returns the lanes past kLaneSinCosLimit (or NaN), which the caller gives
// libm's values.
template <int W>
MPMVV_LANE_INLINE typename Width<W>::Mask sincos_lanes(const double* x_in, double* sin_out, double* cos_out) {
  using Lanes = typename Width<W>::Lanes;
  using Mask = typename Width<W>::Mask;
  using Ints = typename Width<W>::Ints;
  const Lanes zero = {};
  const Lanes x = load<Lanes>(x_in);
  Lanes k = (x * kTwoOverPi + kRoundingShift) - kRoundingShift;
  // Beyond the limit (or NaN) the caller takes libm's values; k = 0 keeps
  // the conversion below defined.
  k = (k < 1.0e9) & (k > -1.0e9) ? k : zero;
  // r = x - k pi/2 as r + r_lo, the sum of two doubles: k P1 and k P2 are
  // exact, x - k P1 too (the two are close), and the rounding of the
  // subtraction of k P2 is kept (Knuth's two-sum), so that r is good to
  // well below its last place and each result rounds about once.
  const Lanes t1 = x - k * kHalfPi1, kp2 = k * kHalfPi2;
  const Lanes t2 = t1 - kp2;
  const Lanes t2_back = t2 - t1;
  const Lanes t2_error = (t1 - (t2 - t2_back)) + (-kp2 - t2_back);
  const Lanes tail = t2_error - k * kHalfPi3;
  const Lanes r = t2 + tail;
  const Lanes r_lo = (t2 - r) + tail;
  const Lanes z = r * r;
  Lanes sin_poly = zero + kSinSeries[0], cos_poly = zero + kCosSeries[0];
  for (int i = 1; i < 8; ++i) sin_poly = sin_poly * z + kSinSeries[i];
  for (int i = 1; i < 7; ++i) cos_poly = cos_poly * z + kCosSeries[i];
  // sin(r + r_lo) = sin r + r_lo cos r and cos(r + r_lo) = cos r - r_lo
  // sin r, to first order in r_lo (below half a unit of r's last place).
  const Lanes half_z = 0.5 * z;
  // x = -0 gives r = +0, and sin(-0) is -0.
  const Lanes s = x == zero ? x : r + ((z * r) * sin_poly + r_lo * (1.0 - half_z));
  // 1 - z/2 rounded, and what that rounding took off added back with the
  // series' tail, so that the result is good to the last place near pi/4.
  const Lanes w = 1.0 - half_z;
  const Lanes c = w + (((1.0 - w) - half_z) + ((z * z) * cos_poly - r * r_lo));
  const Ints quadrant = __builtin_convertvector(k, Ints);
  const Ints none = {};
  const Mask odd = to_mask<Mask>((quadrant & 1) != none);
  const Mask sin_negative = to_mask<Mask>((quadrant & 2) != none);
  const Mask cos_negative = to_mask<Mask>(((quadrant + 1) & 2) != none);
  const Lanes sin_x = odd ? c : s, cos_x = odd ? s : c;
  store(sin_out, sin_negative ? -sin_x : sin_x);
  store(cos_out, cos_negative ? -cos_x : cos_x);
  return ~(lane_abs(x) <= kLaneSinCosLimit);
}

}  // namespace

namespace lanes::MPMVV_LANE_BUILD_NS {
void sincos_array(std::size_t n, const double* x, double* sin_x, double* cos_x, bool& any_beyond) {
  Width<kWidth>::Mask beyond = {};
  std::size_t k = 0;
  for (; k + kWidth <= n; k += kWidth) beyond |= sincos_lanes<kWidth>(x + k, sin_x + k, cos_x + k);
  if (k < n) {
    // The last few through a full vector: spare lanes hold zero.
    double xt[kWidth] = {}, st[kWidth], ct[kWidth];
    for (std::size_t l = 0; k + l < n; ++l) xt[l] = x[k + l];
    beyond |= sincos_lanes<kWidth>(xt, st, ct);
    for (std::size_t l = 0; k + l < n; ++l) {
      sin_x[k + l] = st[l];
      cos_x[k + l] = ct[l];
    }
  }
  any_beyond = false;
  for (int l = 0; l < kWidth; ++l) any_beyond |= beyond[l] != 0;
}

void log_array(std::size_t n, const double* x, double* log_x, bool& any_outside) {
  using Lanes = Width<kWidth>::Lanes;
  // The lanes' domain: positive, finite and normal (NaN is outside).
  constexpr double kSmallest = 0x1p-1022, kLargest = 0x1.fffffffffffffp+1023;
  Width<kWidth>::Mask outside = {};
  auto lanes = [&](const double* in, double* out) {
    const Lanes v = load<Lanes>(in);
    outside |= ~((v >= kSmallest) & (v <= kLargest));
    store(out, lane_log(v));
  };
  std::size_t k = 0;
  for (; k + kWidth <= n; k += kWidth) lanes(x + k, log_x + k);
  if (k < n) {
    double xt[kWidth], lt[kWidth];  // the last few through a full vector: spare lanes hold 1
    for (std::size_t l = 0; l < std::size_t(kWidth); ++l) xt[l] = k + l < n ? x[k + l] : 1.0;
    lanes(xt, lt);
    for (std::size_t l = 0; k + l < n; ++l) log_x[k + l] = lt[l];
  }
  any_outside = false;
  for (int l = 0; l < kWidth; ++l) any_outside |= outside[l] != 0;
}
}  // namespace lanes::MPMVV_LANE_BUILD_NS

#if defined(MPMVV_LANE_DISPATCH)
void lane_sincos(LaneBuild build, std::size_t n, const double* x, double* sin_x, double* cos_x) {
  // The scalar pass only where the lanes saw an argument past the limit (or
  // NaN): a test of each point here cost 7-9 instructions a point (callgrind).
  bool beyond = false;
  MPMVV_LANE_BUILD_CALL(build, sincos_array(n, x, sin_x, cos_x, beyond));
  if (!beyond) return;
  for (std::size_t k = 0; k < n; ++k)
    if (!(std::abs(x[k]) <= kLaneSinCosLimit)) {
      sin_x[k] = std::sin(x[k]);
      cos_x[k] = std::cos(x[k]);
    }
}

void lane_sincos(std::size_t n, const double* x, double* sin_x, double* cos_x) {
  lane_sincos(lane_build(), n, x, sin_x, cos_x);
}

void lane_log(LaneBuild build, std::size_t n, const double* x, double* log_x) {
  // The scalar pass only where the lanes saw an argument outside their
  // domain, as for sin and cos (a test of each point here was three quarters
  // of what the lanes' log costs four points: callgrind).
  bool outside = false;
  MPMVV_LANE_BUILD_CALL(build, log_array(n, x, log_x, outside));
  if (!outside) return;
  for (std::size_t k = 0; k < n; ++k)
    if (!(x[k] >= std::numeric_limits<double>::min() && x[k] <= std::numeric_limits<double>::max()))
      log_x[k] = std::log(x[k]);
}

void lane_log(std::size_t n, const double* x, double* log_x) { lane_log(lane_build(), n, x, log_x); }
#endif

}  // namespace mpmvv
