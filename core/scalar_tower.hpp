// Functions of nested AD scalars by their derivatives at the double value ("derivative towers").
//
// The engine differentiates through nested types (Dual<Dual<double, A>, B>, Taylor2 of those,
// and one more Dual level inside the group jets). Evaluating a function such as sinc by Horner's
// rule in such a type costs a full nested multiplication per term: Dual<Dual<Dual<double, 8>, 8>,
// 3> carries 324 doubles. The same result follows from the function's derivatives at the value,
// computed once in double arithmetic, and the chain rule applied level by level:
//   Dual:    f(v + d ε) = f(v) + f'(v) d ε
//   Taylor2: f(c0 + c1 s + c2 s²) = f(c0) + f'(c0) c1 s + (f'(c0) c2 + f''(c0) c1² / 2) s²
// where f(v), f'(v), f''(v) are themselves lifted to v's (less nested) type.
//
// `Poly<K>` (a truncated Taylor polynomial in double) gives the derivatives of any function
// written generically, f^(k)(x0) = k! [s^k] f(x0 + s); multivariate functions of a few arguments
// (the group's right Jacobian) are handled by `lift_gradient` / `lift_hessian`.
#pragma once

#include "taylor.hpp"

#include <array>
#include <cmath>
#include <type_traits>

namespace lpshoot {

// The number of derivative orders a scalar type carries: double 0, Dual +1, Taylor2 +2.
template <class T>
struct derivative_order : std::integral_constant<int, 0> {};
template <class T, int N>
struct derivative_order<Dual<T, N>> : std::integral_constant<int, 1 + derivative_order<T>::value> {};
template <class T>
struct derivative_order<Taylor2<T>> : std::integral_constant<int, 2 + derivative_order<T>::value> {};

// x0 + s truncated after s^K, in double: the Taylor coefficients of a function at x0.
template <int K>
struct Poly {
  std::array<double, K + 1> a{};

  Poly() = default;
  Poly(double x) { a[0] = x; }  // NOLINT: a constant
  static Poly variable(double x0) {
    Poly p(x0);
    if constexpr (K > 0) p.a[1] = 1.0;
    return p;
  }
  friend Poly operator+(Poly x, const Poly& y) {
    for (int k = 0; k <= K; ++k) x.a[k] += y.a[k];
    return x;
  }
  friend Poly operator-(Poly x, const Poly& y) {
    for (int k = 0; k <= K; ++k) x.a[k] -= y.a[k];
    return x;
  }
  friend Poly operator-(Poly x) {
    for (int k = 0; k <= K; ++k) x.a[k] = -x.a[k];
    return x;
  }
  friend Poly operator*(const Poly& x, const Poly& y) {
    Poly r;
    for (int i = 0; i <= K; ++i)
      for (int j = 0; i + j <= K; ++j) r.a[i + j] += x.a[i] * y.a[j];
    return r;
  }
  friend Poly operator/(const Poly& x, const Poly& y) {  // r y = x, solved term by term
    Poly r;
    for (int k = 0; k <= K; ++k) {
      double s = x.a[k];
      for (int j = 1; j <= k; ++j) s -= y.a[j] * r.a[k - j];
      r.a[k] = s / y.a[0];
    }
    return r;
  }
  friend Poly operator+(Poly x, double b) { x.a[0] += b; return x; }
  friend Poly operator+(double b, Poly x) { x.a[0] += b; return x; }
  friend Poly operator-(Poly x, double b) { x.a[0] -= b; return x; }
  friend Poly operator*(Poly x, double b) {
    for (double& c : x.a) c *= b;
    return x;
  }
  friend Poly operator*(double b, Poly x) { return x * b; }
};

template <int K>
double value(const Poly<K>& p) {
  return p.a[0];
}

// f(x0 + u(s)), u(0) = 0, for f with the period-4 derivative cycle d: Σ_k d[k mod 4] u^k / k!.
template <int K>
Poly<K> periodic_series(const Poly<K>& x, const double (&d)[4]) {
  Poly<K> u = x, r(d[0]), uk(1.0);
  u.a[0] = 0.0;
  double fact = 1.0;
  for (int k = 1; k <= K; ++k) {
    uk = uk * u;
    fact *= k;
    r = r + uk * (d[k % 4] / fact);
  }
  return r;
}
template <int K>
Poly<K> sin(const Poly<K>& x) {
  const double s = std::sin(x.a[0]), c = std::cos(x.a[0]);
  return periodic_series(x, {s, c, -s, -c});
}
template <int K>
Poly<K> cos(const Poly<K>& x) {
  const double s = std::sin(x.a[0]), c = std::cos(x.a[0]);
  return periodic_series(x, {c, -s, -c, s});
}

// acc += c x (in place where the type allows: hessian_scalar.hpp).
inline void add_scaled(double& acc, double c, double x) { acc += c * x; }
template <class T>
void add_scaled(T& acc, double c, const T& x) {
  acc = acc + c * x;
}
template <class T, int N>
void add_scaled(Dual<T, N>& acc, double c, const Dual<T, N>& x) {
  add_scaled(acc.v, c, x.v);
  for (int i = 0; i < N; ++i) add_scaled(acc.d[i], c, x.d[i]);
}

// acc += c a b (in place where the type allows: no temporary product; acc must not be a or b).
inline void add_product(double& acc, double c, double a, double b) { acc += c * a * b; }
template <class T>
void add_product(T& acc, double c, const T& a, const T& b) {
  acc = acc + c * (a * b);
}
template <class T, int N>
void add_product(Dual<T, N>& acc, double c, const Dual<T, N>& a, const Dual<T, N>& b) {
  for (int i = 0; i < N; ++i) {
    add_product(acc.d[i], c, a.d[i], b.v);
    add_product(acc.d[i], c, a.v, b.d[i]);
  }
  add_product(acc.v, c, a.v, b.v);
}
template <int N>
void add_product(Dual<double, N>& acc, double c, const Dual<double, N>& a, const Dual<double, N>& b) {
  const double ca = c * a.v, cb = c * b.v;
  for (int i = 0; i < N; ++i) acc.d[i] += cb * a.d[i] + ca * b.d[i];
  acc.v += ca * b.v;
}

namespace detail {

// f(x) for f given by its derivatives f[0..order] at value(x).
inline double lift(const double* f, double) { return f[0]; }
template <class T, int N>
Dual<T, N> lift(const double* f, const Dual<T, N>& x) {
  Dual<T, N> r;
  r.v = lift(f, x.v);
  const T fp = lift(f + 1, x.v);
  for (int i = 0; i < N; ++i) r.d[i] = fp * x.d[i];
  return r;
}
template <class T>
Taylor2<T> lift(const double* f, const Taylor2<T>& x) {
  return compose_series(x, lift(f, x.c0), lift(f + 1, x.c0), lift(f + 2, x.c0));
}

// f(x) for a scalar function written once generically (`impl(y)` for y double or Poly): in
// double directly, otherwise from its derivatives at value(x).
template <class T, class F>
T apply_univariate(const T& x, F&& impl) {
  if constexpr (std::is_same_v<T, double>) {
    return impl(x);
  } else {
    constexpr int K = derivative_order<T>::value;
    const Poly<K> p = impl(Poly<K>::variable(value(x)));
    double f[K + 1];
    double fact = 1.0;
    for (int k = 0; k <= K; ++k) {
      if (k > 0) fact *= k;
      f[k] = p.a[k] * fact;
    }
    return lift(f, x);
  }
}


// Dual<double, A> (K = 1) and Dual<Dual<double, A>, B> (K = 2): the types lift_multivariate takes.
template <class T, int K>
struct is_dual_over_double : std::false_type {};
template <int A>
struct is_dual_over_double<Dual<double, A>, 1> : std::true_type {};
template <int A, int B>
struct is_dual_over_double<Dual<Dual<double, A>, B>, 2> : std::true_type {};

// f(x(y)) for f of n arguments known at value(x) with its derivatives: f a double dual of width
// n (∂f/∂x_k in d[k]; nested twice, ∂²f/∂x_l∂x_k in d[l].d[k]), x(y) a vector of T, a
// Dual<double, A> or a Dual<Dual<double, A>, B>. The chain rule to first or second order:
//   r.v.d[a] = Σ_k f_k x_k.v.d[a],  r.d[b].v = Σ_k f_k x_k.d[b].v,
//   r.d[b].d[a] = Σ_k f_k x_k.d[b].d[a] + Σ_kl f_kl x_k.v.d[a] x_l.d[b].v.
template <class T, int n, class V>
T lift_multivariate(const Dual<double, n>& f, const V& x) {
  constexpr int A = sizeof(T::d) / sizeof(double);
  T r(f.v);
  for (int k = 0; k < n; ++k)
    for (int a = 0; a < A; ++a) r.d[a] += f.d[k] * x(k).d[a];
  return r;
}
template <class T, int n, class V>
T lift_multivariate(const Dual<Dual<double, n>, n>& f, const V& x) {
  using I = decltype(T::v);
  constexpr int A = sizeof(I::d) / sizeof(double), B = sizeof(T::d) / sizeof(I);
  T r;
  r.v = I(f.v.v);
  for (int k = 0; k < n; ++k)
    for (int a = 0; a < A; ++a) r.v.d[a] += f.v.d[k] * x(k).v.d[a];
  for (int b = 0; b < B; ++b) {
    double w[n];  // Σ_l f_kl x_l.d[b].v
    for (int k = 0; k < n; ++k) {
      w[k] = 0.0;
      for (int l = 0; l < n; ++l) w[k] += f.d[l].d[k] * x(l).d[b].v;
    }
    I& rb = r.d[b];
    rb = I(0.0);
    for (int k = 0; k < n; ++k) {
      const double g = f.v.d[k];
      rb.v += g * x(k).d[b].v;
      for (int a = 0; a < A; ++a) rb.d[a] += g * x(k).d[b].d[a] + w[k] * x(k).v.d[a];
    }
  }
  return r;
}
}  // namespace detail
}  // namespace lpshoot
