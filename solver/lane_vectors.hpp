// For the lane kernels' sources only (lanes.hpp): GCC's vector types of W
// lanes, W the width of a build's registers (8 doubles for AVX-512, 4 for
// AVX2, 2 for SSE2), and the three builds of a kernel. A kernel is a struct
// with types Grid, In and Out and a function template
//   template <int W> static void body(const Grid&, const In&, Out&, int l0)
// computing lanes l0, ..., l0 + W - 1; run_lanes<Kernel>(build, ...) runs all
// eight with the given build, W at a time, so that a kernel's values stay in
// registers.
#pragma once

#include <cstring>

#include "lanes.hpp"

// Inlined into each build of a kernel, so that no vector crosses a call (the
// warning is about how one would be passed if it did).
#define MPMVV_LANE_INLINE inline __attribute__((always_inline))
#pragma GCC diagnostic ignored "-Wpsabi"

namespace mpmvv::lanes {

// W lanes of doubles, of their comparisons and of ints (one specialization
// per width: GCC keeps a vector size only where it is not a template's).
template <int W>
struct Width;
template <>
struct Width<8> {
  typedef double Lanes __attribute__((vector_size(64)));
  typedef long long Mask __attribute__((vector_size(64)));
  typedef int Ints __attribute__((vector_size(32)));
};
template <>
struct Width<4> {
  typedef double Lanes __attribute__((vector_size(32)));
  typedef long long Mask __attribute__((vector_size(32)));
  typedef int Ints __attribute__((vector_size(16)));
};
template <>
struct Width<2> {
  typedef double Lanes __attribute__((vector_size(16)));
  typedef long long Mask __attribute__((vector_size(16)));
  typedef int Ints __attribute__((vector_size(8)));
};

template <class V>
MPMVV_LANE_INLINE V load(const double* a) {
  V v;
  std::memcpy(&v, a, sizeof v);
  return v;
}

template <class V, class T>
MPMVV_LANE_INLINE void store(T* a, const V& v) {
  std::memcpy(a, &v, sizeof v);
}

template <class V>
MPMVV_LANE_INLINE V lane_min(const V& a, const V& b) {
  return a < b ? a : b;
}
template <class V>
MPMVV_LANE_INLINE V lane_max(const V& a, const V& b) {
  return a > b ? a : b;
}

#if defined(__x86_64__) && defined(__GNUC__)
template <class K>
__attribute__((target("avx512f"))) void run_avx512f(const typename K::Grid& g, const typename K::In& in,
                                                    typename K::Out& out) {
  K::template body<8>(g, in, out, 0);
}
template <class K>
__attribute__((target("avx2"))) void run_avx2(const typename K::Grid& g, const typename K::In& in,
                                              typename K::Out& out) {
  for (int l0 = 0; l0 < kLanes; l0 += 4) K::template body<4>(g, in, out, l0);
}
#endif
template <class K>
void run_baseline(const typename K::Grid& g, const typename K::In& in, typename K::Out& out) {
  for (int l0 = 0; l0 < kLanes; l0 += 2) K::template body<2>(g, in, out, l0);
}

template <class K>
void run_lanes(LaneBuild build, const typename K::Grid& g, const typename K::In& in, typename K::Out& out) {
  switch (build) {
#if defined(__x86_64__) && defined(__GNUC__)
    case LaneBuild::avx512f: run_avx512f<K>(g, in, out); return;
    case LaneBuild::avx2: run_avx2<K>(g, in, out); return;
#endif
    default: run_baseline<K>(g, in, out); return;
  }
}

// The build every kernel runs unless told otherwise, chosen once.
inline const LaneBuild widest = widest_lane_build();

}  // namespace mpmvv::lanes
