// The natural logarithm in lanes, for the lane kernels' sources only
// (lane_vectors.hpp): the same operations in every build, so the same bits.
//
// x = 2^e m with m in [sqrt(1/2), sqrt(2)), found from x's bits by adding
// the offset that carries m = sqrt(2) into the next exponent, so that
// f = m - 1 is exact and |f| < 0.42. With s = f / (2 + f),
//   ln m = 2 atanh s = 2s + 2s^3/3 + 2s^5/5 + ... = f - f^2/2 + s (f^2/2 + R),
//   R = 2s^2/3 + 2s^4/5 + ... + 2s^20/21
// (2s = f - s f), where |s| <= 0.1716, so the first omitted term is below
// 1e-18 of the value; f, the exact leading term, comes last. ln 2 is split
// into kLn2High of 42 significant bits, so that e kLn2High is exact for
// every exponent, and the rest kLn2Low. Measured against long double
// (tests/test_lane_math.cpp): within one unit in the last place.
#pragma once

#include "lane_vectors.hpp"

namespace mpmvv::lanes::MPMVV_LANE_BUILD_NS {

inline constexpr double kLn2High = 0x1.62e42fefa3800p-1;
inline constexpr double kLn2Low = 0x1.ef35793c76730p-45;
// The bits of sqrt(1/2) rounded, and what carries m = sqrt(2) over.
inline constexpr unsigned long long kRootHalfBits = 0x3fe6a09e667f3bcdULL;
inline constexpr unsigned long long kOffset = 0x3ff0000000000000ULL - kRootHalfBits;
// 2 / (2k + 1) for k = 10 down to 1, each correctly rounded.
inline constexpr double kAtanhSeries[10] = {2.0 / 21.0, 2.0 / 19.0, 2.0 / 17.0, 2.0 / 15.0, 2.0 / 13.0,
                                            2.0 / 11.0, 2.0 / 9.0,  2.0 / 7.0,  2.0 / 5.0,  2.0 / 3.0};

// ln x in each lane where x is positive, finite and normal (from
// std::numeric_limits<double>::min() to max()); a caller takes other lanes
// elsewhere.
template <class Lanes>
MPMVV_LANE_INLINE Lanes lane_log(const Lanes& x) {
  constexpr int W = int(sizeof(Lanes) / sizeof(double));
  using Bits = typename Width<W>::Bits;
  const Bits shifted = (Bits)x + kOffset;
  const Bits biased_exponent = shifted >> 52;
  const Lanes m = (Lanes)((shifted & 0x000fffffffffffffULL) + kRootHalfBits);
  // The exponent as a double: 2^52 + b has b as its last bits.
  const Lanes e = (Lanes)(biased_exponent | 0x4330000000000000ULL) - (0x1p52 + 1023.0);
  const Lanes f = m - 1.0;
  const Lanes s = f / (2.0 + f);
  const Lanes z = s * s;
  Lanes series = Lanes{} + kAtanhSeries[0];
  for (int k = 1; k < 10; ++k) series = series * z + kAtanhSeries[k];
  const Lanes R = z * series;
  const Lanes half_f2 = 0.5 * f * f;
  return e * kLn2High - ((half_f2 - (s * (half_f2 + R) + e * kLn2Low)) - f);
}

}  // namespace mpmvv::lanes::MPMVV_LANE_BUILD_NS
