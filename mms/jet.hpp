// Forward-mode automatic differentiation: a value with N partial derivatives.
// Nesting a Jet in a Jet gives second derivatives (Jet<Jet<double, 2>, 2>
// carries a value, its gradient and its Hessian). Used to derive F, dF/dX and
// the acceleration of a manufactured motion, and dP/dX through the material.
#pragma once

#include <array>
#include <cmath>

#include <Eigen/Core>

// Each operation is small and a nested jet's are many: inlined, the
// compiler keeps a jet's parts in registers across a formula and computes
// the sine and cosine of one value once (a call per operation cost 3 times
// the arithmetic: callgrind, mpmvv-bench-forcing).
#define MPMVV_JET_INLINE inline __attribute__((always_inline))

namespace mpmvv::mms {

template <class T, int N>
struct Jet {
  T v{};                // value
  std::array<T, N> d{}; // partial derivatives

  Jet() = default;
  Jet(double constant) : v(constant) {}  // NOLINT: constants convert implicitly
  Jet(const T& value, const std::array<T, N>& partials) : v(value), d(partials) {}

  // The k-th independent variable at `value`.
  MPMVV_JET_INLINE static Jet variable(const T& value, int k) {
    Jet j(value, {});
    j.d[std::size_t(k)] = T(1.0);
    return j;
  }

  MPMVV_JET_INLINE Jet& operator+=(const Jet& o) { return *this = *this + o; }
  MPMVV_JET_INLINE Jet& operator-=(const Jet& o) { return *this = *this - o; }
  MPMVV_JET_INLINE Jet& operator*=(const Jet& o) { return *this = *this * o; }
  MPMVV_JET_INLINE Jet& operator/=(const Jet& o) { return *this = *this / o; }
};

template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> operator+(const Jet<T, N>& a, const Jet<T, N>& b) {
  Jet<T, N> r(a.v + b.v, {});
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] + b.d[k];
  return r;
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> operator-(const Jet<T, N>& a, const Jet<T, N>& b) {
  Jet<T, N> r(a.v - b.v, {});
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] - b.d[k];
  return r;
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> operator-(const Jet<T, N>& a) {
  Jet<T, N> r(-a.v, {});
  for (int k = 0; k < N; ++k) r.d[k] = -a.d[k];
  return r;
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> operator+(const Jet<T, N>& a) {
  return a;
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> operator*(const Jet<T, N>& a, const Jet<T, N>& b) {
  Jet<T, N> r(a.v * b.v, {});
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] * b.v + a.v * b.d[k];
  return r;
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> operator/(const Jet<T, N>& a, const Jet<T, N>& b) {
  const T inv = T(1.0) / b.v;
  const T q = a.v * inv;
  Jet<T, N> r(q, {});
  for (int k = 0; k < N; ++k) r.d[k] = (a.d[k] - q * b.d[k]) * inv;
  return r;
}
// The plain number inside any nesting of Jets.
inline double value_of(double x) { return x; }
template <class T, int N>
double value_of(const Jet<T, N>& a) {
  return value_of(a.v);
}

// Mixed with plain numbers (the constant converts to a Jet).
template <class T, int N> MPMVV_JET_INLINE Jet<T, N> operator+(const Jet<T, N>& a, double b) { return a + Jet<T, N>(b); }
template <class T, int N> MPMVV_JET_INLINE Jet<T, N> operator+(double a, const Jet<T, N>& b) { return Jet<T, N>(a) + b; }
template <class T, int N> MPMVV_JET_INLINE Jet<T, N> operator-(const Jet<T, N>& a, double b) { return a - Jet<T, N>(b); }
template <class T, int N> MPMVV_JET_INLINE Jet<T, N> operator-(double a, const Jet<T, N>& b) { return Jet<T, N>(a) - b; }
template <class T, int N> MPMVV_JET_INLINE Jet<T, N> operator*(const Jet<T, N>& a, double b) { return a * Jet<T, N>(b); }
template <class T, int N> MPMVV_JET_INLINE Jet<T, N> operator*(double a, const Jet<T, N>& b) { return Jet<T, N>(a) * b; }
template <class T, int N> MPMVV_JET_INLINE Jet<T, N> operator/(const Jet<T, N>& a, double b) { return a / Jet<T, N>(b); }
template <class T, int N> MPMVV_JET_INLINE Jet<T, N> operator/(double a, const Jet<T, N>& b) { return Jet<T, N>(a) / b; }

// Comparisons look at values only: a motion may branch on where it is.
template <class T, int N> bool operator<(const Jet<T, N>& a, const Jet<T, N>& b) { return a.v < b.v; }
template <class T, int N> bool operator>(const Jet<T, N>& a, const Jet<T, N>& b) { return a.v > b.v; }
template <class T, int N> bool operator<=(const Jet<T, N>& a, const Jet<T, N>& b) { return a.v <= b.v; }
template <class T, int N> bool operator>=(const Jet<T, N>& a, const Jet<T, N>& b) { return a.v >= b.v; }
template <class T, int N> bool operator==(const Jet<T, N>& a, const Jet<T, N>& b) { return a.v == b.v; }
template <class T, int N> bool operator!=(const Jet<T, N>& a, const Jet<T, N>& b) { return a.v != b.v; }

// f(a) with f' known: the chain rule.
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> chain(const Jet<T, N>& a, const T& value, const T& derivative) {
  Jet<T, N> r(value, {});
  for (int k = 0; k < N; ++k) r.d[k] = derivative * a.d[k];
  return r;
}

template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> sin(const Jet<T, N>& a) {
  using std::cos;
  using std::sin;
  return chain(a, T(sin(a.v)), T(cos(a.v)));
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> cos(const Jet<T, N>& a) {
  using std::cos;
  using std::sin;
  return chain(a, T(cos(a.v)), T(-sin(a.v)));
}
// sin x and cos x of one x together: a motion that takes both (a rotation)
// makes one call of libm's sincos where it would make two (GCC merges
// std::sin and std::cos of one double; jet_lanes.hpp makes one call of the
// lanes' sincos for four points). Each is what sin(x) and cos(x) give, to
// the bit.
template <class T>
struct SinCos {
  T sin, cos;
};
MPMVV_JET_INLINE SinCos<double> sin_cos(double x) { return {std::sin(x), std::cos(x)}; }
template <class T, int N>
MPMVV_JET_INLINE SinCos<Jet<T, N>> sin_cos(const Jet<T, N>& a) {
  const auto inner = sin_cos(a.v);
  return {chain(a, T(inner.sin), T(inner.cos)), chain(a, T(inner.cos), T(-inner.sin))};
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> exp(const Jet<T, N>& a) {
  using std::exp;
  const T e = exp(a.v);
  return chain(a, e, e);
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> log(const Jet<T, N>& a) {
  using std::log;
  return chain(a, T(log(a.v)), T(T(1.0) / a.v));
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> sqrt(const Jet<T, N>& a) {
  using std::sqrt;
  const T s = sqrt(a.v);
  return chain(a, s, T(T(0.5) / s));
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> pow(const Jet<T, N>& a, double p) {
  using std::pow;
  return chain(a, T(pow(a.v, p)), T(p * pow(a.v, p - 1.0)));
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> pow(const Jet<T, N>& a, const Jet<T, N>& p) {  // p must be a constant
  return pow(a, value_of(p));
}
template <class T, int N>
MPMVV_JET_INLINE Jet<T, N> atan2(const Jet<T, N>& y, const Jet<T, N>& x) {
  using std::atan2;
  const T denominator = x.v * x.v + y.v * y.v;
  Jet<T, N> r(atan2(y.v, x.v), {});
  for (int k = 0; k < N; ++k) r.d[k] = (x.v * y.d[k] - y.v * x.d[k]) / denominator;
  return r;
}

}  // namespace mpmvv::mms

// Eigen matrices of Jets (F, sigma, P) need the scalar's traits.
namespace Eigen {
template <class T, int N>
struct NumTraits<mpmvv::mms::Jet<T, N>> : GenericNumTraits<mpmvv::mms::Jet<T, N>> {
  using Real = mpmvv::mms::Jet<T, N>;
  using NonInteger = mpmvv::mms::Jet<T, N>;
  using Nested = mpmvv::mms::Jet<T, N>;
  using Literal = mpmvv::mms::Jet<T, N>;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = (N + 1) * NumTraits<T>::ReadCost,
    AddCost = (N + 1) * NumTraits<T>::AddCost,
    MulCost = (2 * N + 1) * NumTraits<T>::MulCost,
  };
  static inline Real epsilon() { return Real(NumTraits<double>::epsilon()); }
  static inline Real dummy_precision() { return Real(NumTraits<double>::dummy_precision()); }
  static inline int digits10() { return NumTraits<double>::digits10(); }
};
template <class T, int N, typename BinaryOp>
struct ScalarBinaryOpTraits<mpmvv::mms::Jet<T, N>, double, BinaryOp> {
  using ReturnType = mpmvv::mms::Jet<T, N>;
};
template <class T, int N, typename BinaryOp>
struct ScalarBinaryOpTraits<double, mpmvv::mms::Jet<T, N>, BinaryOp> {
  using ReturnType = mpmvv::mms::Jet<T, N>;
};
}  // namespace Eigen
