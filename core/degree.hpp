// Which problems have affine step equations: a scalar that tracks the polynomial degree of a
// computation instead of its derivatives.
//
// Without a group, a Lagrangian that is a polynomial of degree <= 2 in its arguments (the jet, or
// a window's nodes) with constraints of degree <= 1 has step equations that are affine in the
// unknowns and the state, with the same matrix at every step: ∂F/∂z and ∂F/∂(state) are made of
// the Lagrangian's (constant) second derivatives and the constraints' (constant) first
// derivatives, combined with weights that depend on h only. A flow may then factor that matrix
// once: a chord step on it is the Newton step, and the step's sensitivity is the same matrix at
// every step (flow.hpp, galerkin_flow.hpp).
//
// The degree is found by evaluating the user's functions once on a Degree scalar: every argument
// a variable of degree 1, constants of degree 0; + and - take the larger degree, * adds them
// (a product with an exact zero constant is a zero constant), division by a non-constant and any
// elementary function of a non-constant are not polynomial. The answer holds everywhere, not only
// at the probed point, because the evaluation follows the same operations at every point, except
// where the code branches on a non-constant value (value(x), comparisons, abs): such a problem is
// never called affine.
#pragma once

#include "continuous.hpp"
#include "problem.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace lpshoot {

struct Degree {
  static constexpr int non_polynomial = 1 << 20;
  double v = 0;  // the value, for the user's branches
  int deg = 0;   // degree in the probe's variables (non_polynomial: not a polynomial)

  Degree() = default;
  Degree(double value) : v(value) {}  // NOLINT: implicit, a constant has degree 0
  template <class A, std::enable_if_t<std::is_arithmetic_v<A> && !std::is_same_v<A, double>, int> = 0>
  Degree(A value) : v(static_cast<double>(value)) {}  // NOLINT
  static Degree variable(double x) {
    Degree r(x);
    r.deg = 1;
    return r;
  }
  bool zero_constant() const { return deg == 0 && v == 0.0; }

  Degree& operator+=(const Degree& b) { return *this = *this + b; }
  Degree& operator-=(const Degree& b) { return *this = *this - b; }
  Degree& operator*=(const Degree& b) { return *this = *this * b; }
  Degree& operator/=(const Degree& b) { return *this = *this / b; }

  friend Degree operator+(const Degree& a) { return a; }
  friend Degree operator-(const Degree& a) { return with(-a.v, a.deg); }
  friend Degree operator+(const Degree& a, const Degree& b) { return with(a.v + b.v, std::max(a.deg, b.deg)); }
  friend Degree operator-(const Degree& a, const Degree& b) { return with(a.v - b.v, std::max(a.deg, b.deg)); }
  friend Degree operator*(const Degree& a, const Degree& b) {
    if (a.zero_constant() || b.zero_constant()) return Degree(0.0);
    return with(a.v * b.v, std::min(a.deg + b.deg, non_polynomial));
  }
  friend Degree operator/(const Degree& a, const Degree& b) {
    return with(a.v / b.v, b.deg == 0 ? a.deg : non_polynomial);
  }
  friend bool operator<(const Degree& a, const Degree& b) { return branch(a, b), a.v < b.v; }
  friend bool operator>(const Degree& a, const Degree& b) { return branch(a, b), a.v > b.v; }
  friend bool operator<=(const Degree& a, const Degree& b) { return branch(a, b), a.v <= b.v; }
  friend bool operator>=(const Degree& a, const Degree& b) { return branch(a, b), a.v >= b.v; }
  friend bool operator==(const Degree& a, const Degree& b) { return branch(a, b), a.v == b.v; }
  friend bool operator!=(const Degree& a, const Degree& b) { return branch(a, b), a.v != b.v; }

  static Degree with(double value, int degree) {
    Degree r(value);
    r.deg = degree;
    return r;
  }
  // Set when the evaluation looked at the value of a non-constant (a possible branch).
  static bool& branched() {
    static thread_local bool flag = false;
    return flag;
  }
  static void branch(const Degree& a) {
    if (a.deg > 0) branched() = true;
  }
  static void branch(const Degree& a, const Degree& b) { branch(a), branch(b); }
};

inline double value(const Degree& x) {
  Degree::branch(x);
  return x.v;
}

namespace detail {
// f(a) for an elementary f: a constant of a constant, not a polynomial otherwise.
inline Degree elementary(const Degree& a, double f) { return Degree::with(f, a.deg == 0 ? 0 : Degree::non_polynomial); }
}  // namespace detail

inline Degree sin(const Degree& a) { return detail::elementary(a, std::sin(a.v)); }
inline Degree cos(const Degree& a) { return detail::elementary(a, std::cos(a.v)); }
inline Degree exp(const Degree& a) { return detail::elementary(a, std::exp(a.v)); }
inline Degree log(const Degree& a) { return detail::elementary(a, std::log(a.v)); }
inline Degree sqrt(const Degree& a) { return detail::elementary(a, std::sqrt(a.v)); }
inline Degree tanh(const Degree& a) { return detail::elementary(a, std::tanh(a.v)); }
inline Degree abs(const Degree& a) { return detail::elementary(a, std::abs(a.v)); }
inline Degree pow(const Degree& a, double p) {
  const bool whole = p >= 0 && p <= 64 && p == std::floor(p);
  if (a.deg == 0) return Degree(std::pow(a.v, p));
  return Degree::with(std::pow(a.v, p), whole ? std::min(static_cast<int>(p) * a.deg, Degree::non_polynomial)
                                              : Degree::non_polynomial);
}
inline Degree atan2(const Degree& y, const Degree& x) {
  return Degree::with(std::atan2(y.v, x.v), y.deg == 0 && x.deg == 0 ? 0 : Degree::non_polynomial);
}
inline bool isfinite(const Degree& a) {
  Degree::branch(a);
  return std::isfinite(a.v);
}

// True when the continuous model (core/continuous.hpp) has no group, a Lagrangian of degree <= 2
// in the jet and constraints of degree <= 1: the Galerkin step equations are then affine.
template <class C>
bool model_is_quadratic(const C& model) {
  if constexpr (C::Group::dim != 0) {
    (void)model;
    return false;
  } else {
    constexpr int r = C::shape_dim;
    Jet<C, Degree> q;
    for (int a = 0; a < r; ++a) {  // generic values: only the user's constant branches see them
      q.p(a) = Degree::variable(0.3 + 0.1 * a);
      q.dp(a) = Degree::variable(-0.7 + 0.2 * a);
      q.ddp(a) = Degree::variable(1.1 - 0.3 * a);
    }
    Degree::branched() = false;
    bool quadratic = model.template lagrangian<Degree>(q).deg <= 2;
    const Vec<Degree, C::num_constraints> chi = model_constraints(model, q);
    for (int i = 0; i < C::num_constraints; ++i) quadratic = quadratic && chi(i).deg <= 1;
    return quadratic && !Degree::branched();
  }
}

// The same for a discrete problem (core/problem.hpp): no group and no connection, L_d of degree
// <= 2 in the window's nodes and constraints of degree <= 1: the paper scheme's steps are affine.
template <class P>
bool discrete_problem_is_quadratic(const P& problem, double h) {
  if constexpr (P::Group::dim != 0) {
    (void)problem, (void)h;
    return false;
  } else {
    constexpr int r = P::shape_dim, k = P::order;
    Window<P, Degree> a;
    for (int i = 0; i <= k; ++i)
      for (int c = 0; c < r; ++c) a.p[i](c) = Degree::variable(0.3 + 0.1 * c - 0.2 * i);
    for (int i = 0; i < k; ++i) a.g[i] = P::Group::template identity<Degree>();
    Degree::branched() = false;
    bool quadratic = problem.template lagrangian<Degree>(a, h).deg <= 2;
    if constexpr (P::num_constraints > 0) {
      const Vec<Degree, P::num_constraints> chi = problem.template constraints<Degree>(a, h);
      for (int i = 0; i < P::num_constraints; ++i) quadratic = quadratic && chi(i).deg <= 1;
    }
    return quadratic && !Degree::branched();
  }
}

}  // namespace lpshoot

namespace Eigen {
template <>
struct NumTraits<lpshoot::Degree> : NumTraits<double> {
  using Real = lpshoot::Degree;
  using NonInteger = lpshoot::Degree;
  using Nested = lpshoot::Degree;
  using Literal = lpshoot::Degree;
  enum { IsComplex = 0, IsInteger = 0, IsSigned = 1, RequireInitialization = 1, ReadCost = 1, AddCost = 2, MulCost = 2 };
};
template <class Op>
struct ScalarBinaryOpTraits<lpshoot::Degree, double, Op> {
  using ReturnType = lpshoot::Degree;
};
template <class Op>
struct ScalarBinaryOpTraits<double, lpshoot::Degree, Op> {
  using ReturnType = lpshoot::Degree;
};
}  // namespace Eigen
