// Second-order forward-mode automatic differentiation with a symmetric Hessian.
//
// Hess<N> holds a value v, its gradient g (N directions) and its Hessian in packed upper-
// triangular storage (N (N + 1) / 2 entries, H(i, j) for i <= j). It gives what the nested
// Dual<Dual<double, N>, N> gives (the value, gradient and full Hessian of a function of N
// seeded variables) for about a third of the arithmetic: a product costs ~4 N²/2 multiply-adds
// instead of ~2 N (2 N + 1), and nothing is computed twice for H(i, j) and H(j, i). Used where
// one interval's L~ is needed with its Hessian in all its coordinates (galerkin_group.hpp).
//
// Rules (a, b scalars of this type, f a univariate function):
//   (a b)''  = a'' b + a b'' + a' b'ᵀ + b' a'ᵀ
//   f(a)''   = f'(a) a'' + f''(a) a' a'ᵀ
#pragma once

#include "dual.hpp"
#include "scalar_tower.hpp"
#include "taylor.hpp"

#include <array>
#include <cmath>
#include <type_traits>

namespace lpshoot {

template <int N>
struct Hess {
  static constexpr int packed = N * (N + 1) / 2;
  double v;
  std::array<double, N> g;
  std::array<double, packed> H;

  // Hess() and constants are zero in every derivative. The arithmetic below writes every entry
  // of its result, which it constructs Uninitialized: zeroing the 440 bytes of a Hess<9> first
  // showed as `rep stos` in the paper scheme's window Hessians (bench/RESULTS.md).
  struct Uninitialized {};
  Hess() : v(0), g{}, H{} {}
  explicit Hess(Uninitialized) {}
  Hess(double value) : v(value), g{}, H{} {}  // NOLINT: implicit, a constant
  template <class A, std::enable_if_t<std::is_arithmetic_v<A> && !std::is_same_v<A, double>, int> = 0>
  Hess(A value) : v(double(value)), g{}, H{} {}  // NOLINT

  // g copied whole from a unit vector, as Dual::variable (dual.hpp: a store-forwarding stall).
  static Hess variable(double x, int i) {
    Hess r(x);
    r.g = Dual<double, N>::units[i];
    return r;
  }
  // Index of H(i, j), i <= j, in the packed storage (row-major upper triangle).
  static constexpr int at(int i, int j) { return i * N - i * (i - 1) / 2 + (j - i); }
  double hessian(int i, int j) const { return i <= j ? H[at(i, j)] : H[at(j, i)]; }

  Hess& operator+=(const Hess& b) { return *this = *this + b; }
  Hess& operator-=(const Hess& b) { return *this = *this - b; }
  Hess& operator*=(const Hess& b) { return *this = *this * b; }
  Hess& operator/=(const Hess& b) { return *this = *this / b; }

  friend Hess operator+(const Hess& a) { return a; }
  friend Hess operator-(const Hess& a) {
    Hess r{Uninitialized{}};
    r.v = -a.v;
    for (int i = 0; i < N; ++i) r.g[i] = -a.g[i];
    for (int k = 0; k < packed; ++k) r.H[k] = -a.H[k];
    return r;
  }
  friend Hess operator+(const Hess& a, const Hess& b) {
    Hess r{Uninitialized{}};
    r.v = a.v + b.v;
    for (int i = 0; i < N; ++i) r.g[i] = a.g[i] + b.g[i];
    for (int k = 0; k < packed; ++k) r.H[k] = a.H[k] + b.H[k];
    return r;
  }
  friend Hess operator-(const Hess& a, const Hess& b) {
    Hess r{Uninitialized{}};
    r.v = a.v - b.v;
    for (int i = 0; i < N; ++i) r.g[i] = a.g[i] - b.g[i];
    for (int k = 0; k < packed; ++k) r.H[k] = a.H[k] - b.H[k];
    return r;
  }
  friend Hess operator*(const Hess& a, const Hess& b) {
    Hess r{Uninitialized{}};
    r.v = a.v * b.v;
    for (int i = 0; i < N; ++i) r.g[i] = a.g[i] * b.v + a.v * b.g[i];
    int k = 0;
    for (int i = 0; i < N; ++i)
      for (int j = i; j < N; ++j, ++k)
        r.H[k] = a.H[k] * b.v + a.v * b.H[k] + a.g[i] * b.g[j] + b.g[i] * a.g[j];
    return r;
  }
  friend Hess operator/(const Hess& a, const Hess& b) { return a * reciprocal(b); }
  friend Hess reciprocal(const Hess& b) {
    const double inv = 1.0 / b.v;
    return chain(b, inv, -inv * inv, 2.0 * inv * inv * inv);
  }

  friend Hess operator+(Hess a, double b) { a.v += b; return a; }
  friend Hess operator+(double a, Hess b) { b.v += a; return b; }
  friend Hess operator-(Hess a, double b) { a.v -= b; return a; }
  friend Hess operator-(double a, const Hess& b) {
    Hess r{Uninitialized{}};
    r.v = a - b.v;
    for (int i = 0; i < N; ++i) r.g[i] = -b.g[i];
    for (int k = 0; k < packed; ++k) r.H[k] = -b.H[k];
    return r;
  }
  // One pass from a into the result (a by value was a copy of a's 440 bytes, for Hess<9>, then
  // a pass over the copy).
  friend Hess operator*(const Hess& a, double b) {
    Hess r{Uninitialized{}};
    r.v = a.v * b;
    for (int i = 0; i < N; ++i) r.g[i] = a.g[i] * b;
    for (int k = 0; k < packed; ++k) r.H[k] = a.H[k] * b;
    return r;
  }
  friend Hess operator*(double a, const Hess& b) { return b * a; }
  friend Hess operator/(const Hess& a, double b) { return a * (1.0 / b); }
  friend Hess operator/(double a, const Hess& b) { return reciprocal(b) * a; }

  friend bool operator<(const Hess& a, const Hess& b) { return a.v < b.v; }
  friend bool operator>(const Hess& a, const Hess& b) { return a.v > b.v; }
  friend bool operator<=(const Hess& a, const Hess& b) { return a.v <= b.v; }
  friend bool operator>=(const Hess& a, const Hess& b) { return a.v >= b.v; }
  friend bool operator==(const Hess& a, const Hess& b) { return a.v == b.v; }
  friend bool operator!=(const Hess& a, const Hess& b) { return a.v != b.v; }

  // f(a) from f, f', f'' at a's value.
  friend Hess chain(const Hess& a, double f, double df, double ddf) {
    Hess r{Uninitialized{}};
    r.v = f;
    for (int i = 0; i < N; ++i) r.g[i] = df * a.g[i];
    int k = 0;
    for (int i = 0; i < N; ++i) {
      const double s = ddf * a.g[i];
      for (int j = i; j < N; ++j, ++k) r.H[k] = df * a.H[k] + s * a.g[j];
    }
    return r;
  }
};

template <int N>
double value(const Hess<N>& x) {
  return x.v;
}

template <int N>
Hess<N> sin(const Hess<N>& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return chain(a, s, c, -s);
}
template <int N>
Hess<N> cos(const Hess<N>& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return chain(a, c, -s, -c);
}
template <int N>
Hess<N> exp(const Hess<N>& a) {
  const double e = std::exp(a.v);
  return chain(a, e, e, e);
}
template <int N>
Hess<N> log(const Hess<N>& a) {
  const double inv = 1.0 / a.v;
  return chain(a, std::log(a.v), inv, -inv * inv);
}
template <int N>
Hess<N> sqrt(const Hess<N>& a) {
  const double s = std::sqrt(a.v);
  return chain(a, s, 0.5 / s, -0.25 / (s * a.v));
}
template <int N>
Hess<N> tanh(const Hess<N>& a) {
  const double t = std::tanh(a.v), d1 = 1.0 - t * t;
  return chain(a, t, d1, -2.0 * t * d1);
}
template <int N>
Hess<N> abs(const Hess<N>& a) {
  return a.v < 0 ? -a : a;
}
template <int N>
Hess<N> pow(const Hess<N>& a, double p) {
  return chain(a, std::pow(a.v, p), p * std::pow(a.v, p - 1.0), p * (p - 1.0) * std::pow(a.v, p - 2.0));
}
// atan2(y, x): first derivatives (x, -y) / r², second (-2xy, y² - x², 2xy) / r⁴ for (yy, yx, xx).
template <int N>
Hess<N> atan2(const Hess<N>& y, const Hess<N>& x) {
  const double r2 = x.v * x.v + y.v * y.v, r4 = r2 * r2;
  const double fy = x.v / r2, fx = -y.v / r2;
  const double fyy = -2.0 * x.v * y.v / r4, fxx = -fyy, fxy = (y.v * y.v - x.v * x.v) / r4;
  Hess<N> r{typename Hess<N>::Uninitialized{}};
  r.v = std::atan2(y.v, x.v);
  for (int i = 0; i < N; ++i) r.g[i] = fy * y.g[i] + fx * x.g[i];
  int k = 0;
  for (int i = 0; i < N; ++i)
    for (int j = i; j < N; ++j, ++k)
      r.H[k] = fy * y.H[k] + fx * x.H[k] + fyy * y.g[i] * y.g[j] + fxx * x.g[i] * x.g[j] +
               fxy * (y.g[i] * x.g[j] + x.g[i] * y.g[j]);
  return r;
}
template <int N>
bool isfinite(const Hess<N>& a) {
  if (!std::isfinite(a.v)) return false;
  for (double x : a.g)
    if (!std::isfinite(x)) return false;
  for (double x : a.H)
    if (!std::isfinite(x)) return false;
  return true;
}

template <int N>
void add_scaled(Hess<N>& acc, double c, const Hess<N>& x) {
  acc.v += c * x.v;
  for (int i = 0; i < N; ++i) acc.g[i] += c * x.g[i];
  for (int k = 0; k < Hess<N>::packed; ++k) acc.H[k] += c * x.H[k];
}

template <int N>
void add_product(Hess<N>& acc, double c, const Hess<N>& a, const Hess<N>& b) {
  const double cav = c * a.v, cbv = c * b.v;
  int k = 0;
  for (int i = 0; i < N; ++i) {
    const double cai = c * a.g[i], cbi = c * b.g[i];
    for (int j = i; j < N; ++j, ++k) acc.H[k] += cbv * a.H[k] + cav * b.H[k] + cai * b.g[j] + cbi * a.g[j];
  }
  for (int i = 0; i < N; ++i) acc.g[i] += cbv * a.g[i] + cav * b.g[i];
  acc.v += cav * b.v;
}

// e += a, with a (a function of M variables) taken as a function of N >= M whose variables
// first .. first + M - 1 are a's.
template <int N, int M>
void add_embedded(Hess<N>& e, const Hess<M>& a, int first) {
  e.v += a.v;
  int k = 0;
  for (int i = 0; i < M; ++i) {
    e.g[first + i] += a.g[i];
    double* row = &e.H[Hess<N>::at(first + i, first + i)];
    for (int j = i; j < M; ++j, ++k) row[j - i] += a.H[k];
  }
}

// o = Hess<N>::variable(x, i) for an o that is zero (Hess()), written in place: building the
// variable as a temporary and copying it moves the whole scalar (440 bytes for Hess<9>) twice.
template <int N>
void make_variable_in_place(Hess<N>& o, double x, int i) {
  o.v = x;
  o.g[i] = 1.0;
}

// v's gradient into g(0 .. N-1) and its Hessian, mirrored from the packed upper triangle, into the
// leading N x N block of H.
template <int N, class Gradient, class Matrix>
void unpack_derivatives(const Hess<N>& v, Gradient& g, Matrix& H) {
  int q = 0;
  for (int i = 0; i < N; ++i) {
    g(i) = v.g[i];
    for (int j = i; j < N; ++j, ++q) H(i, j) = H(j, i) = v.H[q];
  }
}

// e = a, as in add_embedded (when e is already zero, add_embedded alone does it without zeroing e).
template <int N, int M>
void embed(Hess<N>& e, const Hess<M>& a, int first) {
  e = Hess<N>();
  add_embedded(e, a, first);
}

template <int N>
struct derivative_order<Hess<N>> : std::integral_constant<int, 2> {};

// detail::lift (scalar_tower.hpp) for Hess; in this namespace so that argument-dependent lookup
// finds it from templates defined before this file.
template <int N>
Hess<N> lift(const double* f, const Hess<N>& x) {
  return chain(x, f[0], f[1], f[2]);
}

namespace detail {
template <int A>
struct is_dual_over_double<Hess<A>, 2> : std::true_type {};
template <class T>
struct is_hess : std::false_type {};
template <int A>
struct is_hess<Hess<A>> : std::true_type {
  static constexpr int width = A;
};

// lift_multivariate (scalar_tower.hpp) for Hess: r'' = Σ_k f_k x_k'' + Σ_kl f_kl x_k' x_l'ᵀ.
template <int A, int n, class V>
Hess<A> lift_multivariate_hess(const Dual<Dual<double, n>, n>& f, const V& x) {
  Hess<A> r(f.v.v);
  for (int k = 0; k < n; ++k) {
    const double fk = f.v.d[k];
    for (int a = 0; a < A; ++a) r.g[a] += fk * x(k).g[a];
    for (int p = 0; p < Hess<A>::packed; ++p) r.H[p] += fk * x(k).H[p];
  }
  for (int k = 0; k < n; ++k)
    for (int l = 0; l < n; ++l) {
      const double fkl = f.d[l].d[k];
      if (fkl == 0.0) continue;
      int p = 0;
      for (int i = 0; i < A; ++i) {
        const double s = fkl * x(k).g[i];
        for (int j = i; j < A; ++j, ++p) r.H[p] += s * x(l).g[j];
      }
    }
  // The double sum above adds f_kl x_k'(i) x_l'(j) over ordered (k, l): symmetric in (i, j) as
  // f_kl = f_lk, so the upper triangle holds the full second-order term.
  return r;
}

// f(x_0, ..., x_{M-1}) given as Hess<M> in its arguments, composed with arguments x_k in Hess<N>:
// the rule above, summed over each argument's non-zero gradient entries only (arguments that
// depend on a few of the N directions, as a group curve's ends do: galerkin_group_interval.hpp).
template <int N, int M>
Hess<N> compose_sparse(const Hess<M>& f, const Hess<N>* const* x) {
  Hess<N> r(f.v);
  std::array<std::array<int, N>, M> nz;
  std::array<int, M> count{};
  for (int k = 0; k < M; ++k) {
    for (int i = 0; i < N; ++i)
      if (x[k]->g[i] != 0.0) nz[k][count[k]++] = i;
    const double fk = f.g[k];
    if (fk == 0.0) continue;
    for (int c = 0; c < count[k]; ++c) r.g[nz[k][c]] += fk * x[k]->g[nz[k][c]];
    for (int p = 0; p < Hess<N>::packed; ++p) r.H[p] += fk * x[k]->H[p];
  }
  // Σ over ordered (k, l) of f_kl x_k'(i) x_l'(j), i <= j: the (l, k) term supplies i > j.
  for (int k = 0; k < M; ++k)
    for (int l = 0; l < M; ++l) {
      const double fkl = f.hessian(k, l);
      if (fkl == 0.0) continue;
      for (int a = 0; a < count[k]; ++a) {
        const int i = nz[k][a];
        const double s = fkl * x[k]->g[i];
        for (int b = 0; b < count[l]; ++b) {
          const int j = nz[l][b];
          if (i <= j) r.H[Hess<N>::at(i, j)] += s * x[l]->g[j];
        }
      }
    }
  return r;
}

// f, a function of M scalar arguments written for any scalar type and returning K of them, at
// arguments given in Hess<N>: f runs in Hess<M> at the arguments' values and each output is
// composed with the arguments (compose_sparse). Worth it when M < N and f is more than a few
// operations: a group's log and exp then run in M directions instead of N.
template <int N, int M, int K, class F>
Eigen::Matrix<Hess<N>, K, 1> compose_through(const std::array<const Hess<N>*, M>& x, F&& f) {
  std::array<Hess<M>, M> seeded;
  for (int k = 0; k < M; ++k) seeded[k] = Hess<M>::variable(x[k]->v, k);
  const Eigen::Matrix<Hess<M>, K, 1> y = f(seeded);
  Eigen::Matrix<Hess<N>, K, 1> out;
  for (int i = 0; i < K; ++i) out(i) = compose_sparse<N, M>(y(i), x.data());
  return out;
}
}  // namespace detail

}  // namespace lpshoot

namespace Eigen {
template <int N>
struct NumTraits<lpshoot::Hess<N>> : NumTraits<double> {
  using Real = lpshoot::Hess<N>;
  using NonInteger = lpshoot::Hess<N>;
  using Nested = lpshoot::Hess<N>;
  using Literal = lpshoot::Hess<N>;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1,
    AddCost = 1 + N * (N + 3) / 2,
    MulCost = 1 + 2 * N * (N + 2)
  };
};
template <int N, class Op>
struct ScalarBinaryOpTraits<lpshoot::Hess<N>, double, Op> {
  using ReturnType = lpshoot::Hess<N>;
};
template <int N, class Op>
struct ScalarBinaryOpTraits<double, lpshoot::Hess<N>, Op> {
  using ReturnType = lpshoot::Hess<N>;
};
}  // namespace Eigen
