// Forward-mode automatic differentiation: a small, fixed-size, nestable dual number.
//
// Dual<T, N> holds a value v and N directional derivatives d[i], all of type T. T is double
// or another Dual, so Dual<Dual<double, No>, Ni> carries the mixed second derivatives the
// engine needs (the inner level differentiates the local action, the outer level the
// residual). Sizes are compile-time: nothing allocates. Branches in user code should compare
// with value(x), which strips every level down to the double value.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <type_traits>

namespace lpshoot {

template <class T, int N>
struct Dual {
  T v{};
  std::array<T, N> d{};

  Dual() = default;
  Dual(const T& value) : v(value) {}  // NOLINT: implicit, a constant has zero derivatives
  template <class A, std::enable_if_t<std::is_arithmetic_v<A> && !std::is_same_v<A, T>, int> = 0>
  Dual(A value) : v(T(value)) {}  // NOLINT

  // A variable: value x with derivative 1 in direction i. Over doubles d is copied whole from a
  // table of unit vectors: set one entry at a time after zeroing, it was read back by vector
  // loads that could not be forwarded from the smaller stores, a stall in every seeded
  // evaluation (the electron Galerkin 4 interval gradient: 325 against 240 ns; bench/RESULTS.md,
  // "The small solves in registers").
  static Dual variable(const T& x, int i) {
    Dual r(x);
    if constexpr (std::is_same_v<T, double>)
      r.d = units[i];
    else
      r.d[i] = T(1);
    return r;
  }

  static constexpr std::array<std::array<double, N>, N> unit_vectors() {
    std::array<std::array<double, N>, N> t{};
    for (int i = 0; i < N; ++i) t[i][i] = 1.0;
    return t;
  }
  static constexpr std::array<std::array<double, N>, N> units = unit_vectors();

  Dual& operator+=(const Dual& b) { return *this = *this + b; }
  Dual& operator-=(const Dual& b) { return *this = *this - b; }
  Dual& operator*=(const Dual& b) { return *this = *this * b; }
  Dual& operator/=(const Dual& b) { return *this = *this / b; }

  friend Dual operator+(const Dual& a) { return a; }
  friend Dual operator-(const Dual& a) {
    Dual r;
    r.v = -a.v;
    for (int i = 0; i < N; ++i) r.d[i] = -a.d[i];
    return r;
  }
  friend Dual operator+(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v + b.v;
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] + b.d[i];
    return r;
  }
  friend Dual operator-(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v - b.v;
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] - b.d[i];
    return r;
  }
  friend Dual operator*(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v * b.v;
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * b.v + a.v * b.d[i];
    return r;
  }
  friend Dual operator/(const Dual& a, const Dual& b) {
    Dual r;
    const T inv = T(1) / b.v;
    r.v = a.v * inv;
    for (int i = 0; i < N; ++i) r.d[i] = (a.d[i] - r.v * b.d[i]) * inv;
    return r;
  }
  // Mixed with plain doubles, without promoting the double to a full Dual.
  friend Dual operator+(const Dual& a, double b) { Dual r = a; r.v = r.v + b; return r; }
  friend Dual operator+(double a, const Dual& b) { return b + a; }
  friend Dual operator-(const Dual& a, double b) { Dual r = a; r.v = r.v - b; return r; }
  friend Dual operator-(double a, const Dual& b) { return -(b - a); }
  friend Dual operator*(const Dual& a, double b) {
    Dual r;
    r.v = a.v * b;
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * b;
    return r;
  }
  friend Dual operator*(double a, const Dual& b) { return b * a; }
  friend Dual operator/(const Dual& a, double b) { return a * (1.0 / b); }
  friend Dual operator/(double a, const Dual& b) { return Dual(T(a)) / b; }

  friend bool operator<(const Dual& a, const Dual& b) { return a.v < b.v; }
  friend bool operator>(const Dual& a, const Dual& b) { return a.v > b.v; }
  friend bool operator<=(const Dual& a, const Dual& b) { return a.v <= b.v; }
  friend bool operator>=(const Dual& a, const Dual& b) { return a.v >= b.v; }
  friend bool operator==(const Dual& a, const Dual& b) { return a.v == b.v; }
  friend bool operator!=(const Dual& a, const Dual& b) { return a.v != b.v; }
};

// The double value under every level of nesting.
inline double value(double x) { return x; }
template <class T, int N>
double value(const Dual<T, N>& x) {
  return value(x.v);
}

namespace detail {
// f(a) with derivative f'(a) = df, by the chain rule.
template <class T, int N>
Dual<T, N> chain(const Dual<T, N>& a, const T& f, const T& df) {
  Dual<T, N> r;
  r.v = f;
  for (int i = 0; i < N; ++i) r.d[i] = df * a.d[i];
  return r;
}
}  // namespace detail

template <class T, int N>
Dual<T, N> sin(const Dual<T, N>& a) {
  using std::cos;
  using std::sin;
  return detail::chain(a, T(sin(a.v)), T(cos(a.v)));
}
template <class T, int N>
Dual<T, N> cos(const Dual<T, N>& a) {
  using std::cos;
  using std::sin;
  return detail::chain(a, T(cos(a.v)), T(-sin(a.v)));
}
template <class T, int N>
Dual<T, N> exp(const Dual<T, N>& a) {
  using std::exp;
  const T e = exp(a.v);
  return detail::chain(a, e, e);
}
template <class T, int N>
Dual<T, N> log(const Dual<T, N>& a) {
  using std::log;
  return detail::chain(a, T(log(a.v)), T(T(1) / a.v));
}
template <class T, int N>
Dual<T, N> sqrt(const Dual<T, N>& a) {
  using std::sqrt;
  const T s = sqrt(a.v);
  return detail::chain(a, s, T(T(0.5) / s));
}
template <class T, int N>
Dual<T, N> tanh(const Dual<T, N>& a) {
  using std::tanh;
  const T t = tanh(a.v);
  return detail::chain(a, t, T(T(1) - t * t));
}
template <class T, int N>
Dual<T, N> abs(const Dual<T, N>& a) {
  return value(a) < 0 ? -a : a;
}
template <class T, int N>
Dual<T, N> pow(const Dual<T, N>& a, double p) {
  using std::pow;
  return detail::chain(a, T(pow(a.v, p)), T(p * pow(a.v, p - 1.0)));
}
template <class T, int N>
Dual<T, N> atan2(const Dual<T, N>& y, const Dual<T, N>& x) {
  using std::atan2;
  const T r2 = x.v * x.v + y.v * y.v;
  Dual<T, N> r;
  r.v = atan2(y.v, x.v);
  for (int i = 0; i < N; ++i) r.d[i] = (x.v * y.d[i] - y.v * x.d[i]) / r2;
  return r;
}
template <class T, int N>
bool isfinite(const Dual<T, N>& a) {
  using std::isfinite;
  if (!isfinite(a.v)) return false;
  for (int i = 0; i < N; ++i)
    if (!isfinite(a.d[i])) return false;
  return true;
}

}  // namespace lpshoot

namespace Eigen {
template <class T, int N>
struct NumTraits<lpshoot::Dual<T, N>> : NumTraits<double> {
  using Real = lpshoot::Dual<T, N>;
  using NonInteger = lpshoot::Dual<T, N>;
  using Nested = lpshoot::Dual<T, N>;
  using Literal = lpshoot::Dual<T, N>;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1,
    AddCost = 1 + N,
    MulCost = 1 + 2 * N
  };
};
template <class T, int N, class Op>
struct ScalarBinaryOpTraits<lpshoot::Dual<T, N>, double, Op> {
  using ReturnType = lpshoot::Dual<T, N>;
};
template <class T, int N, class Op>
struct ScalarBinaryOpTraits<double, lpshoot::Dual<T, N>, Op> {
  using ReturnType = lpshoot::Dual<T, N>;
};
}  // namespace Eigen
