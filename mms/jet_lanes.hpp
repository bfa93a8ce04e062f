// Four points in the jets at once: a scalar whose every operation is done
// lane by lane, for the derived body force (factored_force.hpp). A jet of it
// (Jet<JetLanes, N>) carries four points' values and partial derivatives,
// and the jets' arithmetic on it becomes vector arithmetic where the
// function it is inlined into is compiled for AVX2 (factored_force.hpp:
// the target attribute), two lanes at a time in the baseline x86-64 build.
//
// Every lane gets what the scalar jets give the same point, to the bit:
// +, -, * and / are the same IEEE operations lane by lane, no multiply is
// fused with an add (AVX2 without FMA), and the elementary functions are
// libm's, called lane by lane (as the scalar jets call them).
#pragma once

#include <cmath>
#include <cstring>

#include <Eigen/Core>

#include "jet.hpp"

namespace mpmvv::mms {

struct JetLanes {
  static constexpr int kCount = 4;
  typedef double Vector __attribute__((vector_size(8 * kCount)));
  Vector v;

  JetLanes() = default;
  explicit JetLanes(double constant) : v(Vector{} + constant) {}
  explicit JetLanes(const Vector& values) : v(values) {}

  // Lane l from values[l].
  MPMVV_JET_INLINE static JetLanes load(const double* values) {
    Vector v;
    std::memcpy(&v, values, sizeof v);
    return JetLanes(v);
  }
  MPMVV_JET_INLINE double operator[](int l) const { return v[l]; }
};

MPMVV_JET_INLINE JetLanes operator+(const JetLanes& a, const JetLanes& b) { return JetLanes(a.v + b.v); }
MPMVV_JET_INLINE JetLanes operator-(const JetLanes& a, const JetLanes& b) { return JetLanes(a.v - b.v); }
MPMVV_JET_INLINE JetLanes operator*(const JetLanes& a, const JetLanes& b) { return JetLanes(a.v * b.v); }
MPMVV_JET_INLINE JetLanes operator/(const JetLanes& a, const JetLanes& b) { return JetLanes(a.v / b.v); }
MPMVV_JET_INLINE JetLanes operator-(const JetLanes& a) { return JetLanes(-a.v); }
MPMVV_JET_INLINE JetLanes operator*(double a, const JetLanes& b) { return JetLanes(a * b.v); }
MPMVV_JET_INLINE JetLanes operator*(const JetLanes& a, double b) { return JetLanes(a.v * b); }
MPMVV_JET_INLINE JetLanes& operator+=(JetLanes& a, const JetLanes& b) { return a = a + b; }
MPMVV_JET_INLINE JetLanes& operator-=(JetLanes& a, const JetLanes& b) { return a = a - b; }
MPMVV_JET_INLINE JetLanes& operator*=(JetLanes& a, const JetLanes& b) { return a = a * b; }
MPMVV_JET_INLINE JetLanes& operator/=(JetLanes& a, const JetLanes& b) { return a = a / b; }

// The elementary functions, lane by lane through the scalar's own call.
template <class Function>
MPMVV_JET_INLINE JetLanes each_lane(const JetLanes& a, Function f) {
  JetLanes r;
  for (int l = 0; l < JetLanes::kCount; ++l) r.v[l] = f(a.v[l]);
  return r;
}
MPMVV_JET_INLINE JetLanes sin(const JetLanes& a) { return each_lane(a, [](double x) { return std::sin(x); }); }
MPMVV_JET_INLINE JetLanes cos(const JetLanes& a) { return each_lane(a, [](double x) { return std::cos(x); }); }
MPMVV_JET_INLINE SinCos<JetLanes> sin_cos(const JetLanes& a) {
  SinCos<JetLanes> r;
  for (int l = 0; l < JetLanes::kCount; ++l) {
    double s, c;
    ::sincos(a.v[l], &s, &c);
    r.sin.v[l] = s;
    r.cos.v[l] = c;
  }
  return r;
}
MPMVV_JET_INLINE JetLanes exp(const JetLanes& a) { return each_lane(a, [](double x) { return std::exp(x); }); }
MPMVV_JET_INLINE JetLanes log(const JetLanes& a) { return each_lane(a, [](double x) { return std::log(x); }); }
MPMVV_JET_INLINE JetLanes sqrt(const JetLanes& a) { return each_lane(a, [](double x) { return std::sqrt(x); }); }
MPMVV_JET_INLINE JetLanes pow(const JetLanes& a, double p) {
  return each_lane(a, [p](double x) { return std::pow(x, p); });
}
MPMVV_JET_INLINE JetLanes atan2(const JetLanes& y, const JetLanes& x) {
  JetLanes r;
  for (int l = 0; l < JetLanes::kCount; ++l) r.v[l] = std::atan2(y.v[l], x.v[l]);
  return r;
}
// A constant exponent (jet.hpp: pow of a jet by a jet) is the same in every lane.
inline double value_of(const JetLanes& a) { return a.v[0]; }

// The value part of a jet down to its innermost scalar (value_of for lanes).
MPMVV_JET_INLINE double base_value(double x) { return x; }
MPMVV_JET_INLINE const JetLanes& base_value(const JetLanes& x) { return x; }
template <class T, int N>
MPMVV_JET_INLINE auto base_value(const Jet<T, N>& a) {
  return base_value(a.v);
}

// A jet of plain numbers as the same jet in every lane.
MPMVV_JET_INLINE JetLanes to_lanes(double x) { return JetLanes(x); }
template <class T, int N>
MPMVV_JET_INLINE auto to_lanes(const Jet<T, N>& a) {
  using Inner = decltype(to_lanes(a.v));
  Jet<Inner, N> r(to_lanes(a.v), {});
  for (int k = 0; k < N; ++k) r.d[std::size_t(k)] = to_lanes(a.d[std::size_t(k)]);
  return r;
}

}  // namespace mpmvv::mms

namespace Eigen {
template <>
struct NumTraits<mpmvv::mms::JetLanes> : GenericNumTraits<double> {
  using Real = mpmvv::mms::JetLanes;
  using NonInteger = mpmvv::mms::JetLanes;
  using Nested = mpmvv::mms::JetLanes;
  using Literal = mpmvv::mms::JetLanes;
  enum { RequireInitialization = 1 };
};
}  // namespace Eigen
