// Hessians by reverse over forward: a tape of first derivatives and one adjoint sweep.
//
// Taped<N> evaluates a function forward with its value and its gradient in N seeded directions,
// as Dual<double, N> would, and records every operation on a Tape: its one or two operands, its
// first partials, and its second partials when it is nonlinear. One reverse sweep then gives
// the adjoints v̄_i = ∂F/∂v_i of F = Σ_o w_o v_o (weighted outputs), and with them
//   ∇²F = Σ_i v̄_i Σ_{j,k ∈ args(i)} ∂²φ_i/∂v_j∂v_k ∇v_j ∇v_kᵀ,
// the Hessian of the graph's Lagrangian v_last − Σ v̄_i (v_i − φ_i(args)) reduced by the
// tangents ∇v (linear operations have no second partials and add nothing). Against Hess<N>
// (hessian_scalar.hpp), which carries a packed Hessian through every operation (a sum of two
// Hess<9> moves 1 320 bytes), each operation here costs a gradient, and each nonlinear one
// adds one symmetric update of N² entries at the end, scaled by its adjoint. Used for the paper
// windows' Hessians (step_window_hessian.hpp), where L~ = L_d + λ·χ_d is such a weighted sum.
//
// Operations between a Taped and a double record a unary node; between two constants none. The
// tape is not thread-safe: one per thread (its nodes and buffers are reused call after call).
#pragma once

#include "hessian_scalar.hpp"
#include "scalar_tower.hpp"

#include <Eigen/Core>

#include <cmath>
#include <type_traits>
#include <utility>
#include <vector>

namespace lpshoot {

template <int N>
class Tape;

template <int N>
struct Taped {
  double v = 0;
  int id = -1;              // node on the tape; -1 for a constant
  Tape<N>* tape = nullptr;  // null for a constant

  Taped() = default;
  Taped(double value) : v(value) {}  // NOLINT: implicit, a constant
  template <class A, std::enable_if_t<std::is_arithmetic_v<A> && !std::is_same_v<A, double>, int> = 0>
  Taped(A value) : v(double(value)) {}  // NOLINT

  Taped& operator+=(const Taped& b) { return *this = *this + b; }
  Taped& operator-=(const Taped& b) { return *this = *this - b; }
  Taped& operator*=(const Taped& b) { return *this = *this * b; }
  Taped& operator/=(const Taped& b) { return *this = *this / b; }

  friend Taped operator+(const Taped& a) { return a; }
  friend Taped operator-(const Taped& a) { return unary(a, -a.v, -1.0, 0.0); }
  friend Taped operator+(const Taped& a, const Taped& b) { return binary(a, b, a.v + b.v, 1.0, 1.0); }
  friend Taped operator-(const Taped& a, const Taped& b) { return binary(a, b, a.v - b.v, 1.0, -1.0); }
  friend Taped operator*(const Taped& a, const Taped& b) {
    return binary(a, b, a.v * b.v, b.v, a.v, 0.0, 1.0, 0.0);
  }
  // a / b: partials 1/b, −a/b²; second (0, −1/b², 2a/b³).
  friend Taped operator/(const Taped& a, const Taped& b) {
    const double inv = 1.0 / b.v, q = a.v * inv;
    return binary(a, b, q, inv, -q * inv, 0.0, -inv * inv, 2.0 * q * inv * inv);
  }

  friend bool operator<(const Taped& a, const Taped& b) { return a.v < b.v; }
  friend bool operator>(const Taped& a, const Taped& b) { return a.v > b.v; }
  friend bool operator<=(const Taped& a, const Taped& b) { return a.v <= b.v; }
  friend bool operator>=(const Taped& a, const Taped& b) { return a.v >= b.v; }
  friend bool operator==(const Taped& a, const Taped& b) { return a.v == b.v; }
  friend bool operator!=(const Taped& a, const Taped& b) { return a.v != b.v; }

  // f(a) from f, f', f'' at a's value.
  friend Taped unary(const Taped& a, double f, double df, double ddf) {
    if (!a.tape) return Taped(f);
    return a.tape->record(f, a.id, -1, df, 0.0, ddf, 0.0, 0.0);
  }
  // f(a, b) from f, its partials and (optionally) its second partials (aa, ab, bb).
  friend Taped binary(const Taped& a, const Taped& b, double f, double da, double db, double saa = 0.0,
                      double sab = 0.0, double sbb = 0.0) {
    if (!a.tape && !b.tape) return Taped(f);
    if (!b.tape) return a.tape->record(f, a.id, -1, da, 0.0, saa, 0.0, 0.0);
    if (!a.tape) return b.tape->record(f, b.id, -1, db, 0.0, sbb, 0.0, 0.0);
    return a.tape->record(f, a.id, b.id, da, db, saa, sab, sbb);
  }
};

template <int N>
class Tape {
 public:
  using Vector = Eigen::Matrix<double, N, 1>;
  using Matrix = Eigen::Matrix<double, N, N>;

  void clear() { size_ = 0, seeds_.clear(); }
  int size() const { return size_; }

  // Variable i of the N directions, at x.
  Taped<N> variable(double x, int i) {
    Vector g = Vector::Zero();
    g(i) = 1.0;
    return source(x, g);
  }
  // A value with a given gradient and no operands (its own curvature, if any, is the caller's).
  Taped<N> source(double x, const Vector& g) {
    Taped<N> r = record_node(x, -1, -1, 0.0, 0.0, 0.0, 0.0, 0.0);
    gradient_row(r.id) = g;
    return r;
  }

  // The node f = φ(a, b): its gradient da ∇a + db ∇b now, its partials kept for the sweep.
  Taped<N> record(double f, int a, int b, double da, double db, double saa, double sab, double sbb) {
    Taped<N> r = record_node(f, a, b, da, db, saa, sab, sbb);
    auto g = gradient_row(r.id);
    if (b < 0)
      g = da * gradient_row(a);
    else
      g = da * gradient_row(a) + db * gradient_row(b);
    return r;
  }

  // ∇x for a recorded x (zero for a constant).
  Vector gradient(const Taped<N>& x) const {
    return x.tape ? Vector(Eigen::Map<const Vector>(gradients_.data() + std::size_t(x.id) * N)) : Vector::Zero();
  }

  // Adds w x to F (an output's weight; any time before sweep()).
  void seed(const Taped<N>& x, double w) {
    if (x.tape) seeds_.push_back({x.id, w});
  }

  // The reverse sweep from the seeds: the adjoints of all nodes, and ∇²F (the file comment) added
  // to H (symmetric on entry: it leaves exactly so). Clears the seeds.
  void sweep(Matrix& H) {
    if (adjoints_.size() < std::size_t(size_)) adjoints_.resize(size_);
    std::fill(adjoints_.begin(), adjoints_.begin() + size_, 0.0);
    for (const auto& [id, w] : seeds_) adjoints_[id] += w;
    seeds_.clear();
    for (int i = size_ - 1; i >= 0; --i) {
      const double w = adjoints_[i];
      if (w == 0.0) continue;
      const Node& n = nodes_[i];
      if (n.a < 0) continue;
      adjoints_[n.a] += w * n.da;
      if (n.b >= 0) adjoints_[n.b] += w * n.db;
      if (!n.curved) continue;
      // w (saa ga gaᵀ + sab (ga gbᵀ + gb gaᵀ) + sbb gb gbᵀ) = u gaᵀ + v gbᵀ, column by column
      // (fixed-size loops: Eigen's outer product went through a generic kernel call).
      const Vector ga = gradient_row(n.a);
      if (n.b < 0) {
        const Vector u = (w * n.saa) * ga;
        for (int j = 0; j < N; ++j) H.col(j) += ga(j) * u;
      } else {
        const Vector gb = gradient_row(n.b);
        const Vector u = w * (n.saa * ga + n.sab * gb), v = w * (n.sab * ga + n.sbb * gb);
        for (int j = 0; j < N; ++j) H.col(j) += ga(j) * u + gb(j) * v;
      }
    }
    // Each update is symmetric to rounding only: the upper triangle is kept, mirrored.
    for (int j = 0; j < N; ++j)
      for (int i = j + 1; i < N; ++i) H(i, j) = H(j, i);
  }
  // ∂F/∂x after sweep(), for a node x (a variable or source: its weight in F's gradient).
  double adjoint(const Taped<N>& x) const { return x.tape ? adjoints_[x.id] : 0.0; }

 private:
  struct Node {
    int a, b;  // operands (-1: none)
    bool curved;
    double da, db, saa, sab, sbb;
  };

  Taped<N> record_node(double f, int a, int b, double da, double db, double saa, double sab, double sbb) {
    if (size_ == static_cast<int>(nodes_.size())) {
      const std::size_t grown = std::max<std::size_t>(64, 2 * nodes_.size());
      nodes_.resize(grown);
      gradients_.resize(grown * N);
    }
    nodes_[size_] = Node{a, b, saa != 0.0 || sab != 0.0 || sbb != 0.0, da, db, saa, sab, sbb};
    Taped<N> r;
    r.v = f;
    r.id = size_++;
    r.tape = this;
    return r;
  }
  Eigen::Map<Vector> gradient_row(int i) { return Eigen::Map<Vector>(gradients_.data() + std::size_t(i) * N); }
  Eigen::Map<const Vector> gradient_row(int i) const {
    return Eigen::Map<const Vector>(gradients_.data() + std::size_t(i) * N);
  }

  std::vector<Node> nodes_;
  std::vector<double> gradients_;  // row i: ∇ of node i
  std::vector<double> adjoints_;
  std::vector<std::pair<int, double>> seeds_;
  int size_ = 0;
};

template <int N>
double value(const Taped<N>& x) {
  return x.v;
}

template <int N>
Taped<N> sin(const Taped<N>& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return unary(a, s, c, -s);
}
template <int N>
Taped<N> cos(const Taped<N>& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return unary(a, c, -s, -c);
}
template <int N>
Taped<N> exp(const Taped<N>& a) {
  const double e = std::exp(a.v);
  return unary(a, e, e, e);
}
template <int N>
Taped<N> log(const Taped<N>& a) {
  const double inv = 1.0 / a.v;
  return unary(a, std::log(a.v), inv, -inv * inv);
}
template <int N>
Taped<N> sqrt(const Taped<N>& a) {
  const double s = std::sqrt(a.v);
  return unary(a, s, 0.5 / s, -0.25 / (s * a.v));
}
template <int N>
Taped<N> tanh(const Taped<N>& a) {
  const double t = std::tanh(a.v), d1 = 1.0 - t * t;
  return unary(a, t, d1, -2.0 * t * d1);
}
template <int N>
Taped<N> abs(const Taped<N>& a) {
  return a.v < 0 ? -a : a;
}
template <int N>
Taped<N> pow(const Taped<N>& a, double p) {
  return unary(a, std::pow(a.v, p), p * std::pow(a.v, p - 1.0), p * (p - 1.0) * std::pow(a.v, p - 2.0));
}
// atan2(y, x): first derivatives (x, -y) / r², second (-2xy, y² - x², 2xy) / r⁴ for (yy, yx, xx).
template <int N>
Taped<N> atan2(const Taped<N>& y, const Taped<N>& x) {
  const double r2 = x.v * x.v + y.v * y.v, r4 = r2 * r2;
  const double fyy = -2.0 * x.v * y.v / r4;
  return binary(y, x, std::atan2(y.v, x.v), x.v / r2, -y.v / r2, fyy, (y.v * y.v - x.v * x.v) / r4, -fyy);
}
template <int N>
bool isfinite(const Taped<N>& a) {
  return std::isfinite(a.v) && (!a.tape || a.tape->gradient(a).allFinite());
}

template <int N>
struct derivative_order<Taped<N>> : std::integral_constant<int, 2> {};

// detail::lift (scalar_tower.hpp) for Taped: f(x) from f, f', f'' at x's value.
template <int N>
Taped<N> lift(const double* f, const Taped<N>& x) {
  return unary(x, f[0], f[1], f[2]);
}

}  // namespace lpshoot

namespace Eigen {
template <int N>
struct NumTraits<lpshoot::Taped<N>> : NumTraits<double> {
  using Real = lpshoot::Taped<N>;
  using NonInteger = lpshoot::Taped<N>;
  using Nested = lpshoot::Taped<N>;
  using Literal = lpshoot::Taped<N>;
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
template <int N, class Op>
struct ScalarBinaryOpTraits<lpshoot::Taped<N>, double, Op> {
  using ReturnType = lpshoot::Taped<N>;
};
template <int N, class Op>
struct ScalarBinaryOpTraits<double, lpshoot::Taped<N>, Op> {
  using ReturnType = lpshoot::Taped<N>;
};
}  // namespace Eigen
