// Truncated Taylor series in one variable, to second order: x(s) = c0 + c1 s + c2 s^2 + O(s^3).
//
// The Galerkin schemes (METHOD.md §9) need the velocity and acceleration of a group curve at a
// quadrature point: with s the time offset, log(g(0)^{-1} g(s)) = Ω s + Ω' s^2/2 + O(s^3), so
// one evaluation of the group's own exp/log/compose in Taylor2 arithmetic gives both, for any
// group. T is double or a Dual (the engine's derivatives flow through the coefficients).
#pragma once

#include "dual.hpp"

#include <cmath>

namespace lpshoot {

template <class T>
struct Taylor2 {
  T c0{}, c1{}, c2{};

  Taylor2() = default;
  Taylor2(const T& value) : c0(value) {}  // NOLINT: a constant
  template <class A, std::enable_if_t<std::is_arithmetic_v<A> && !std::is_same_v<A, T>, int> = 0>
  Taylor2(A value) : c0(T(value)) {}  // NOLINT
  Taylor2(const T& a, const T& b, const T& c) : c0(a), c1(b), c2(c) {}

  Taylor2& operator+=(const Taylor2& b) { return *this = *this + b; }
  Taylor2& operator-=(const Taylor2& b) { return *this = *this - b; }
  Taylor2& operator*=(const Taylor2& b) { return *this = *this * b; }
  Taylor2& operator/=(const Taylor2& b) { return *this = *this / b; }

  friend Taylor2 operator+(const Taylor2& a) { return a; }
  friend Taylor2 operator-(const Taylor2& a) { return {-a.c0, -a.c1, -a.c2}; }
  friend Taylor2 operator+(const Taylor2& a, const Taylor2& b) { return {a.c0 + b.c0, a.c1 + b.c1, a.c2 + b.c2}; }
  friend Taylor2 operator-(const Taylor2& a, const Taylor2& b) { return {a.c0 - b.c0, a.c1 - b.c1, a.c2 - b.c2}; }
  friend Taylor2 operator*(const Taylor2& a, const Taylor2& b) {
    return {a.c0 * b.c0, a.c0 * b.c1 + a.c1 * b.c0, a.c0 * b.c2 + a.c1 * b.c1 + a.c2 * b.c0};
  }
  friend Taylor2 operator/(const Taylor2& a, const Taylor2& b) {
    const T inv = T(1.0) / b.c0;
    const T q0 = a.c0 * inv;
    const T q1 = (a.c1 - q0 * b.c1) * inv;
    return {q0, q1, (a.c2 - q0 * b.c2 - q1 * b.c1) * inv};
  }
  friend Taylor2 operator+(const Taylor2& a, double b) { return {a.c0 + b, a.c1, a.c2}; }
  friend Taylor2 operator+(double a, const Taylor2& b) { return b + a; }
  friend Taylor2 operator-(const Taylor2& a, double b) { return {a.c0 - b, a.c1, a.c2}; }
  friend Taylor2 operator-(double a, const Taylor2& b) { return -(b - a); }
  friend Taylor2 operator*(const Taylor2& a, double b) { return {a.c0 * b, a.c1 * b, a.c2 * b}; }
  friend Taylor2 operator*(double a, const Taylor2& b) { return b * a; }
  friend Taylor2 operator/(const Taylor2& a, double b) { return a * (1.0 / b); }
  friend Taylor2 operator/(double a, const Taylor2& b) { return Taylor2(T(a)) / b; }

  friend bool operator<(const Taylor2& a, const Taylor2& b) { return a.c0 < b.c0; }
  friend bool operator>(const Taylor2& a, const Taylor2& b) { return a.c0 > b.c0; }
  friend bool operator<=(const Taylor2& a, const Taylor2& b) { return a.c0 <= b.c0; }
  friend bool operator>=(const Taylor2& a, const Taylor2& b) { return a.c0 >= b.c0; }
  friend bool operator==(const Taylor2& a, const Taylor2& b) { return a.c0 == b.c0; }
  friend bool operator!=(const Taylor2& a, const Taylor2& b) { return a.c0 != b.c0; }
};

template <class T>
double value(const Taylor2<T>& x) {
  return value(x.c0);
}

namespace detail {
// f(a(s)) from f, f', f'' at a0: f0 + f1 a1 s + (f1 a2 + f2 a1^2 / 2) s^2.
template <class T>
Taylor2<T> compose_series(const Taylor2<T>& a, const T& f0, const T& f1, const T& f2) {
  return {f0, f1 * a.c1, f1 * a.c2 + 0.5 * f2 * a.c1 * a.c1};
}
}  // namespace detail

template <class T>
Taylor2<T> sin(const Taylor2<T>& a) {
  using std::cos;
  using std::sin;
  const T s = sin(a.c0), c = cos(a.c0);
  return detail::compose_series(a, s, c, T(-s));
}
template <class T>
Taylor2<T> cos(const Taylor2<T>& a) {
  using std::cos;
  using std::sin;
  const T s = sin(a.c0), c = cos(a.c0);
  return detail::compose_series(a, c, T(-s), T(-c));
}
template <class T>
Taylor2<T> exp(const Taylor2<T>& a) {
  using std::exp;
  const T e = exp(a.c0);
  return detail::compose_series(a, e, e, e);
}
template <class T>
Taylor2<T> log(const Taylor2<T>& a) {
  using std::log;
  const T inv = T(1.0) / a.c0;
  return detail::compose_series(a, T(log(a.c0)), inv, T(-(inv * inv)));
}
template <class T>
Taylor2<T> sqrt(const Taylor2<T>& a) {
  using std::sqrt;
  const T r = sqrt(a.c0);
  const T d1 = 0.5 / r;
  return detail::compose_series(a, r, d1, T(-0.5 * d1 / a.c0));
}
template <class T>
Taylor2<T> tanh(const Taylor2<T>& a) {
  using std::tanh;
  const T t = tanh(a.c0);
  const T d1 = 1.0 - t * t;
  return detail::compose_series(a, t, d1, T(-2.0 * t * d1));
}
template <class T>
Taylor2<T> pow(const Taylor2<T>& a, double p) {
  using std::pow;
  const T f0 = pow(a.c0, p);
  return detail::compose_series(a, f0, T(p * pow(a.c0, p - 1.0)), T(p * (p - 1.0) * pow(a.c0, p - 2.0)));
}
template <class T>
Taylor2<T> abs(const Taylor2<T>& a) {
  return value(a) < 0 ? -a : a;
}
// atan2(y, x): value, then the derivative (x y' - y x') / (x^2 + y^2) as a series.
template <class T>
Taylor2<T> atan2(const Taylor2<T>& y, const Taylor2<T>& x) {
  using std::atan2;
  const Taylor2<T> dy(y.c1, 2.0 * y.c2, T(0.0)), dx(x.c1, 2.0 * x.c2, T(0.0));
  const Taylor2<T> rate = (x * dy - y * dx) / (x * x + y * y);
  return {T(atan2(y.c0, x.c0)), rate.c0, 0.5 * rate.c1};
}
template <class T>
bool isfinite(const Taylor2<T>& a) {
  using std::isfinite;
  return isfinite(a.c0) && isfinite(a.c1) && isfinite(a.c2);
}

}  // namespace lpshoot

namespace Eigen {
template <class T>
struct NumTraits<lpshoot::Taylor2<T>> : NumTraits<double> {
  using Real = lpshoot::Taylor2<T>;
  using NonInteger = lpshoot::Taylor2<T>;
  using Nested = lpshoot::Taylor2<T>;
  using Literal = lpshoot::Taylor2<T>;
  enum { IsComplex = 0, IsInteger = 0, IsSigned = 1, RequireInitialization = 1, ReadCost = 3, AddCost = 3, MulCost = 9 };
};
template <class T, class Op>
struct ScalarBinaryOpTraits<lpshoot::Taylor2<T>, double, Op> {
  using ReturnType = lpshoot::Taylor2<T>;
};
template <class T, class Op>
struct ScalarBinaryOpTraits<double, lpshoot::Taylor2<T>, Op> {
  using ReturnType = lpshoot::Taylor2<T>;
};
}  // namespace Eigen
