// For the lane kernels' sources only (lanes.hpp), each compiled once per
// build with MPMVV_LANE_BUILD_NS (avx512, avx2 or baseline) and
// MPMVV_LANE_WIDTH (8, 4 or 2 doubles: the width of the build's registers)
// defined by solver/CMakeLists.txt: GCC's vector types of W lanes and the
// loop that runs a kernel over all eight lanes, W at a time. A kernel is a
// struct with types Grid, In and Out and a function template
//   template <int W> static void body(const Grid&, const In&, Out&, int l0)
// computing lanes l0, ..., l0 + W - 1.
//
// Everything here lives in a namespace of the build's own name, so that no
// two builds share a symbol the linker could pick either copy of.
#pragma once

#include <cstring>
#include <utility>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "lanes.hpp"

#if !defined(MPMVV_LANE_BUILD_NS) || !defined(MPMVV_LANE_WIDTH)
#error "lane_vectors.hpp is compiled once per build of the lane kernels (solver/CMakeLists.txt)"
#endif

// In the baseline build, which holds the dispatch: `call` (a function of
// each build's namespace, with its arguments) in the namespace of `build`.
#if defined(MPMVV_LANES_X86)
#define MPMVV_LANE_BUILD_CALL(build, call)                           \
  do {                                                               \
    switch (build) {                                                 \
      case ::mpmvv::LaneBuild::avx512: lanes::avx512::call; break;   \
      case ::mpmvv::LaneBuild::avx2: lanes::avx2::call; break;       \
      default: lanes::baseline::call; break;                         \
    }                                                                \
  } while (false)
#else
#define MPMVV_LANE_BUILD_CALL(build, call) lanes::baseline::call
#endif

// The two dispatching functions of a kernel whose call has nothing around it:
// name(build, params) runs the given build, name(params) the one the kernels
// run (lane_build). `params` and `args` in parentheses.
#define MPMVV_LANE_EXPAND(...) __VA_ARGS__
#define MPMVV_LANE_DISPATCH_OF(name, params, args)                                   \
  void name(::mpmvv::LaneBuild build, MPMVV_LANE_EXPAND params) {                    \
    MPMVV_LANE_BUILD_CALL(build, name args);                                         \
  }                                                                                  \
  void name(MPMVV_LANE_EXPAND params) { name(::mpmvv::lane_build(), MPMVV_LANE_EXPAND args); }

// Inlined into the build's loop, so that no vector crosses a call (the
// warning is about how one would be passed if it did).
#define MPMVV_LANE_INLINE inline __attribute__((always_inline))
#pragma GCC diagnostic ignored "-Wpsabi"

namespace mpmvv::lanes::MPMVV_LANE_BUILD_NS {

inline constexpr int kWidth = MPMVV_LANE_WIDTH;

// W lanes of doubles, of their comparisons, of ints and of the doubles' bits
// (one specialization per width: GCC keeps a vector size only where it is not
// a template's).
template <int W>
struct Width;
template <>
struct Width<8> {
  typedef double Lanes __attribute__((vector_size(64)));
  typedef long long Mask __attribute__((vector_size(64)));
  typedef int Ints __attribute__((vector_size(32)));
  typedef unsigned long long Bits __attribute__((vector_size(64)));  // a double's bits
};
template <>
struct Width<4> {
  typedef double Lanes __attribute__((vector_size(32)));
  typedef long long Mask __attribute__((vector_size(32)));
  typedef int Ints __attribute__((vector_size(16)));
  typedef unsigned long long Bits __attribute__((vector_size(32)));  // a double's bits
};
template <>
struct Width<2> {
  typedef double Lanes __attribute__((vector_size(16)));
  typedef long long Mask __attribute__((vector_size(16)));
  typedef int Ints __attribute__((vector_size(8)));
  typedef unsigned long long Bits __attribute__((vector_size(16)));  // a double's bits
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

// Lanes of an array that holds S values per lane, one lane after another
// (S = 2 or 4: Particles keeps x_p, v_p, F_p and sigma_p so): value c of
// every lane in v[c], from S vectors' worth of doubles by shuffles, with no
// copy of the particles into lanes beforehand.
template <class V>
MPMVV_LANE_INLINE void deinterleave(const V& a, const V& b, V& even, V& odd) {
  constexpr std::size_t W = sizeof(V) / sizeof(double);
  using Index = typename Width<int(W)>::Mask;
  // Indices into the 2W values of a then b.
  constexpr Index evens = []<std::size_t... k>(std::index_sequence<k...>) {
    return Index{(long long)(2 * k)...};
  }(std::make_index_sequence<W>{});
  even = __builtin_shuffle(a, b, evens);
  odd = __builtin_shuffle(a, b, evens + 1);
}

template <class V, int S>
MPMVV_LANE_INLINE void load_interleaved(const double* a, V (&v)[S]) {
  constexpr int W = int(sizeof(V) / sizeof(double));
  static_assert(S == 2 || S == 4);
  if constexpr (S == 2) {
    deinterleave(load<V>(a), load<V>(a + W), v[0], v[1]);
  } else {
    // Values 0 and 2 of each lane, then 1 and 3; then each pair apart.
    V even[2], odd[2];
    deinterleave(load<V>(a), load<V>(a + W), even[0], odd[0]);
    deinterleave(load<V>(a + 2 * W), load<V>(a + 3 * W), even[1], odd[1]);
    deinterleave(even[0], even[1], v[0], v[2]);
    deinterleave(odd[0], odd[1], v[1], v[3]);
  }
}

// The inverse of load_interleaved: value c of every lane from v[c] into an
// array that holds S values per lane, one lane after another. For S = 4 a
// 4 x W transpose by the shuffles each width does in one instruction (the
// unpacks of pairs, then whole halves or quarters), each row stored as it
// is formed; for S = 2 the lanes' pairs, half a vector's lanes at a time.
template <class V, int S>
MPMVV_LANE_INLINE void store_interleaved(double* a, const V (&v)[S]) {
  constexpr int W = int(sizeof(V) / sizeof(double));
  using Index = typename Width<W>::Mask;
  static_assert(S == 2 || S == 4);
  if constexpr (S == 2) {
    // Lane l's pair from v[0][l] and v[1][l] (index W + l in the shuffle).
    constexpr Index low = []<std::size_t... k>(std::index_sequence<k...>) {
      return Index{(long long)(k % 2 == 0 ? k / 2 : W + k / 2)...};
    }(std::make_index_sequence<W>{});
    store(a, __builtin_shuffle(v[0], v[1], low));
    store(a + W, __builtin_shuffle(v[0], v[1], low + W / 2));
  } else if constexpr (W == 2) {
    store(a, __builtin_shuffle(v[0], v[1], Index{0, 2}));
    store(a + 2, __builtin_shuffle(v[2], v[3], Index{0, 2}));
    store(a + 4, __builtin_shuffle(v[0], v[1], Index{1, 3}));
    store(a + 6, __builtin_shuffle(v[2], v[3], Index{1, 3}));
  } else if constexpr (W == 4) {
    // t0 = v0_0 v1_0 v0_2 v1_2, t1 = v0_1 v1_1 v0_3 v1_3, t2 and t3 the same of v2 and v3.
    const V t0 = __builtin_shuffle(v[0], v[1], Index{0, 4, 2, 6});
    const V t1 = __builtin_shuffle(v[0], v[1], Index{1, 5, 3, 7});
    const V t2 = __builtin_shuffle(v[2], v[3], Index{0, 4, 2, 6});
    const V t3 = __builtin_shuffle(v[2], v[3], Index{1, 5, 3, 7});
    store(a, __builtin_shuffle(t0, t2, Index{0, 1, 4, 5}));
    store(a + 4, __builtin_shuffle(t1, t3, Index{0, 1, 4, 5}));
    store(a + 8, __builtin_shuffle(t0, t2, Index{2, 3, 6, 7}));
    store(a + 12, __builtin_shuffle(t1, t3, Index{2, 3, 6, 7}));
  } else {
    static_assert(W == 8);
    const V t0 = __builtin_shuffle(v[0], v[1], Index{0, 8, 2, 10, 4, 12, 6, 14});
    const V t1 = __builtin_shuffle(v[0], v[1], Index{1, 9, 3, 11, 5, 13, 7, 15});
    const V t2 = __builtin_shuffle(v[2], v[3], Index{0, 8, 2, 10, 4, 12, 6, 14});
    const V t3 = __builtin_shuffle(v[2], v[3], Index{1, 9, 3, 11, 5, 13, 7, 15});
    // Lanes 0 and 2, 1 and 3, 4 and 6, 5 and 7.
    const V r02 = __builtin_shuffle(t0, t2, Index{0, 1, 8, 9, 2, 3, 10, 11});
    const V r13 = __builtin_shuffle(t1, t3, Index{0, 1, 8, 9, 2, 3, 10, 11});
    const V r46 = __builtin_shuffle(t0, t2, Index{4, 5, 12, 13, 6, 7, 14, 15});
    const V r57 = __builtin_shuffle(t1, t3, Index{4, 5, 12, 13, 6, 7, 14, 15});
    store(a, __builtin_shuffle(r02, r13, Index{0, 1, 2, 3, 8, 9, 10, 11}));
    store(a + 8, __builtin_shuffle(r02, r13, Index{4, 5, 6, 7, 12, 13, 14, 15}));
    store(a + 16, __builtin_shuffle(r46, r57, Index{0, 1, 2, 3, 8, 9, 10, 11}));
    store(a + 24, __builtin_shuffle(r46, r57, Index{4, 5, 6, 7, 12, 13, 14, 15}));
  }
}

// |a| as std::abs gives it, the sign bit cleared (one instruction; a
// comparison and a blend took three, and left -0 as it was).
template <class V>
MPMVV_LANE_INLINE V lane_abs(const V& a) {
  using Bits = typename Width<int(sizeof(V) / sizeof(double))>::Bits;
  return V(Bits(a) & 0x7fffffffffffffffULL);
}

// The correctly rounded square root of each lane, as std::sqrt gives it.
template <class V>
MPMVV_LANE_INLINE V lane_sqrt(const V& a) {
#if defined(__AVX512F__)
  // (masked with every lane set: the unmasked form trips a false warning of GCC 12)
  if constexpr (sizeof(V) == 64) return V(_mm512_mask_sqrt_pd(__m512d(a), __mmask8(0xff), __m512d(a)));
#endif
#if defined(__AVX__)
  if constexpr (sizeof(V) == 32) return V(_mm256_sqrt_pd(__m256d(a)));
#endif
#if defined(__SSE2__)
  if constexpr (sizeof(V) == 16) return V(_mm_sqrt_pd(__m128d(a)));
#endif
  V r;
  for (int l = 0; l < int(sizeof(V) / sizeof(double)); ++l) r[l] = __builtin_sqrt(a[l]);
  return r;
}

// Each lane's int as a double (exactly), and an int comparison's lanes as a
// double comparison's: GCC 12 widens a vector of ints by halves and joins
// them again (__builtin_convertvector: four instructions where the one the
// build has does; 12 instructions a CPDI stencil, callgrind).
template <class Lanes, class Ints>
MPMVV_LANE_INLINE Lanes to_doubles(const Ints& v) {
#if defined(__AVX512F__)
  // (zero-masked with every lane set, as lane_sqrt is masked)
  if constexpr (sizeof(Lanes) == 64) return Lanes(_mm512_maskz_cvtepi32_pd(__mmask8(0xff), __m256i(v)));
#endif
#if defined(__AVX__)
  if constexpr (sizeof(Lanes) == 32) return Lanes(_mm256_cvtepi32_pd(__m128i(v)));
#endif
  return __builtin_convertvector(v, Lanes);
}
template <class Mask, class Ints>
MPMVV_LANE_INLINE Mask to_mask(const Ints& m) {
#if defined(__AVX512F__)
  if constexpr (sizeof(Mask) == 64) return Mask(_mm512_maskz_cvtepi32_epi64(__mmask8(0xff), __m256i(m)));
#endif
#if defined(__AVX2__)
  if constexpr (sizeof(Mask) == 32) return Mask(_mm256_cvtepi32_epi64(__m128i(m)));
#endif
  return __builtin_convertvector(m, Mask);
}

// A double comparison's lanes (0 or -1) as ints: the inverse of to_mask,
// which GCC 12 forms by four shuffles.
template <class Ints, class Mask>
MPMVV_LANE_INLINE Ints to_ints(const Mask& m) {
#if defined(__AVX512F__)
  if constexpr (sizeof(Mask) == 64) return Ints(_mm512_maskz_cvtepi64_epi32(__mmask8(0xff), __m512i(m)));
#endif
#if defined(__AVX2__)
  if constexpr (sizeof(Mask) == 32)
    return Ints(_mm256_castsi256_si128(
        _mm256_permutevar8x32_epi32(__m256i(m), _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6))));
#endif
  return __builtin_convertvector(m, Ints);
}

template <class V>
MPMVV_LANE_INLINE V lane_min(const V& a, const V& b) {
  return a < b ? a : b;
}
template <class V>
MPMVV_LANE_INLINE V lane_max(const V& a, const V& b) {
  return a > b ? a : b;
}

// All eight lanes, kWidth at a time, so that a kernel's values stay in registers.
template <class K>
void run(const typename K::Grid& g, const typename K::In& in, typename K::Out& out) {
  for (int l0 = 0; l0 < kLanes; l0 += kWidth) K::template body<kWidth>(g, in, out, l0);
}

}  // namespace mpmvv::lanes::MPMVV_LANE_BUILD_NS
