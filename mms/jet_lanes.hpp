// W points in the jets at once (four or eight): a scalar whose every
// operation is done lane by lane, for the derived body force
// (factored_force.hpp). A jet of it (Jet<JetLanesOf<W>, N>) carries W
// points' values and partial derivatives, and the jets' arithmetic on it
// becomes vector arithmetic where the function it is inlined into is
// compiled for AVX-512 (eight lanes) or AVX2 (four; factored_force.hpp: the
// target attribute), two lanes at a time in the baseline x86-64 build.
//
// +, -, * and / are the same IEEE operations lane by lane as the scalar
// jets make (no multiply is fused with an add: AVX2 has no FMA, and the
// AVX-512 build is compiled without contraction). sin, cos and ln come from
// the solver's lanes (solver/lane_math.hpp), W points a call, where libm's,
// called lane by lane, took 230 of the derived ring force's 540
// instructions a point (callgrind, mpmvv-bench-throughput with body_force =
// derived); they are within one unit in the last place of the exact value
// as libm's are, but not always libm's bits, so a lane's force differs from
// the scalar jets' (Manufactured::body_force) in its last places
// (tests/test_manufactured.cpp bounds it), and is the same on every build
// (the lanes' functions make the same operations on every build). The other
// elementary functions are libm's, lane by lane.
#pragma once

#include <cmath>
#include <cstring>

#include <Eigen/Core>

#include "jet.hpp"
#include "solver/lane_math.hpp"

namespace mpmvv::mms {

// GCC's vector of W doubles (a vector_size that depends on a template
// argument is not one).
template <int W>
struct LaneVector;
template <>
struct LaneVector<4> {
  typedef double type __attribute__((vector_size(32)));
};
template <>
struct LaneVector<8> {
  typedef double type __attribute__((vector_size(64)));
};

template <int W>
struct JetLanesOf {
  static constexpr int kCount = W;
  using Vector = typename LaneVector<W>::type;
  Vector v;

  JetLanesOf() = default;
  explicit JetLanesOf(double constant) : v(Vector{} + constant) {}
  explicit JetLanesOf(const Vector& values) : v(values) {}

  // Lane l from values[l].
  MPMVV_JET_INLINE static JetLanesOf load(const double* values) {
    Vector v;
    std::memcpy(&v, values, sizeof v);
    return JetLanesOf(v);
  }
  MPMVV_JET_INLINE double operator[](int l) const { return v[l]; }
};
// Four points: one AVX2 vector (the AVX-512 build of the derived force takes
// eight, factored_force.hpp).
using JetLanes = JetLanesOf<4>;

template <int W>
MPMVV_JET_INLINE JetLanesOf<W> operator+(const JetLanesOf<W>& a, const JetLanesOf<W>& b) {
  return JetLanesOf<W>(a.v + b.v);
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> operator-(const JetLanesOf<W>& a, const JetLanesOf<W>& b) {
  return JetLanesOf<W>(a.v - b.v);
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> operator*(const JetLanesOf<W>& a, const JetLanesOf<W>& b) {
  return JetLanesOf<W>(a.v * b.v);
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> operator/(const JetLanesOf<W>& a, const JetLanesOf<W>& b) {
  return JetLanesOf<W>(a.v / b.v);
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> operator-(const JetLanesOf<W>& a) {
  return JetLanesOf<W>(-a.v);
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> operator*(double a, const JetLanesOf<W>& b) {
  return JetLanesOf<W>(a * b.v);
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> operator*(const JetLanesOf<W>& a, double b) {
  return JetLanesOf<W>(a.v * b);
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W>& operator+=(JetLanesOf<W>& a, const JetLanesOf<W>& b) {
  return a = a + b;
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W>& operator-=(JetLanesOf<W>& a, const JetLanesOf<W>& b) {
  return a = a - b;
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W>& operator*=(JetLanesOf<W>& a, const JetLanesOf<W>& b) {
  return a = a * b;
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W>& operator/=(JetLanesOf<W>& a, const JetLanesOf<W>& b) {
  return a = a / b;
}

// The elementary functions, lane by lane through the scalar's own call.
template <int W, class Function>
MPMVV_JET_INLINE JetLanesOf<W> each_lane(const JetLanesOf<W>& a, Function f) {
  JetLanesOf<W> r;
  for (int l = 0; l < W; ++l) r.v[l] = f(a.v[l]);
  return r;
}
// The build whose sin, cos and ln W lanes call, chosen once: for eight
// lanes the CPU's widest, for four the widest but AVX-512, whose eight
// lanes would take four points through a vector of eight (every build gives
// the same bits, so the choice is one of speed only).
template <int W>
inline LaneBuild jet_lane_build() {
  static const LaneBuild build = W < 8 && lane_build() == LaneBuild::avx512 ? LaneBuild::avx2 : lane_build();
  return build;
}

// Manufactured::body_force evaluates a separable motion twice at each point,
// in a jet of t (the acceleration) and in a jet of X (F and dF/dX), and the
// value part of every jet is the plain evaluation: a rotation asks for the
// sine and cosine of the same W angles twice in a row. The second time
// takes the first's (the angles compared bit for bit, so that -0 against +0
// is computed again); the lanes' sincos was a fifth of the derived ring
// force's instructions for each of the two.
template <int W>
MPMVV_JET_INLINE SinCos<JetLanesOf<W>> sin_cos(const JetLanesOf<W>& a) {
  thread_local struct {
    alignas(8 * W) double x[W], sin[W], cos[W];
    bool held = false;
  } last;
  if (!(last.held && std::memcmp(last.x, &a.v, sizeof last.x) == 0)) {
    std::memcpy(last.x, &a.v, sizeof last.x);
    lane_sincos(jet_lane_build<W>(), W, last.x, last.sin, last.cos);
    last.held = true;
  }
  return {JetLanesOf<W>::load(last.sin), JetLanesOf<W>::load(last.cos)};
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> sin(const JetLanesOf<W>& a) {
  return sin_cos(a).sin;
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> cos(const JetLanesOf<W>& a) {
  return sin_cos(a).cos;
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> exp(const JetLanesOf<W>& a) {
  return each_lane(a, [](double x) { return std::exp(x); });
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> log(const JetLanesOf<W>& a) {
  alignas(8 * W) double x[W], y[W];
  std::memcpy(x, &a.v, sizeof x);
  lane_log(jet_lane_build<W>(), W, x, y);
  return JetLanesOf<W>::load(y);
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> sqrt(const JetLanesOf<W>& a) {
  return each_lane(a, [](double x) { return std::sqrt(x); });
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> pow(const JetLanesOf<W>& a, double p) {
  return each_lane(a, [p](double x) { return std::pow(x, p); });
}
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> atan2(const JetLanesOf<W>& y, const JetLanesOf<W>& x) {
  JetLanesOf<W> r;
  for (int l = 0; l < W; ++l) r.v[l] = std::atan2(y.v[l], x.v[l]);
  return r;
}
// A constant exponent (jet.hpp: pow of a jet by a jet) is the same in every lane.
template <int W>
inline double value_of(const JetLanesOf<W>& a) {
  return a.v[0];
}

// The value part of a jet down to its innermost scalar (value_of for lanes).
MPMVV_JET_INLINE double base_value(double x) { return x; }
template <int W>
MPMVV_JET_INLINE const JetLanesOf<W>& base_value(const JetLanesOf<W>& x) {
  return x;
}
template <class T, int N>
MPMVV_JET_INLINE auto base_value(const Jet<T, N>& a) {
  return base_value(a.v);
}

// A jet of plain numbers as the same jet in every one of W lanes.
template <int W>
MPMVV_JET_INLINE JetLanesOf<W> to_lanes(double x) {
  return JetLanesOf<W>(x);
}
template <int W, class T, int N>
MPMVV_JET_INLINE auto to_lanes(const Jet<T, N>& a) {
  using Inner = decltype(to_lanes<W>(a.v));
  Jet<Inner, N> r(to_lanes<W>(a.v), {});
  for (int k = 0; k < N; ++k) r.d[std::size_t(k)] = to_lanes<W>(a.d[std::size_t(k)]);
  return r;
}

}  // namespace mpmvv::mms

namespace Eigen {
template <int W>
struct NumTraits<mpmvv::mms::JetLanesOf<W>> : GenericNumTraits<double> {
  using Real = mpmvv::mms::JetLanesOf<W>;
  using NonInteger = mpmvv::mms::JetLanesOf<W>;
  using Nested = mpmvv::mms::JetLanesOf<W>;
  using Literal = mpmvv::mms::JetLanesOf<W>;
  enum { RequireInitialization = 1 };
};
}  // namespace Eigen
