// Elroy's beanie (paper §4.1.2, METHOD.md §6.2): Q = SE(2) x S^1, q = (x, y, θ, ψ), G = SE(2),
// shape ψ. With c = I2/(I1+I2), μ = I1 I2/(I1+I2) and V(ψ) = amplitude (1 - cos ψ):
//   discrete connection (74): A(ψ_n, ψ_{n+1}) = rotation by c Δψ_n;
//   g~_n = (R(Δθ_n + c Δψ_n), R(θ_n)^T Δr_n), so h Ω3^n = angle(g~_n), h Ω12^n = translation(g~_n).
// BeanieFree (k = 1) is the free motion with the corrected L_d (76);
// BeanieControl (k = 2) is the minimum-energy control of the shape, L^_d of (79), with either
// the paper's forward-Euler constraints (80)–(82) or the exact-rotation ones (METHOD.md §6.2).
#pragma once

#include <lpshoot/core/lpshoot.hpp>

#include <cmath>

namespace lpshoot::problems {

struct BeanieParameters {
  double m = 1.0;
  double I1 = 1.0;
  double I2 = 1.0;
  double amplitude = 0.0;  // V(ψ) = amplitude (1 - cos ψ)

  double c() const { return I2 / (I1 + I2); }
  double mu() const { return I1 * I2 / (I1 + I2); }
  template <class T>
  T V(const T& psi) const {
    using std::cos;
    return amplitude * (1.0 - cos(psi));
  }
  template <class T>
  T dV(const T& psi) const {
    using std::sin;
    return amplitude * sin(psi);
  }
};

// A(ψ0, ψ1) = (R(c (ψ1 - ψ0)), 0), eq. (74).
template <class T>
SE2::Element<T> beanie_connection(const BeanieParameters& par, const Vec<T, 1>& p0, const Vec<T, 1>& p1) {
  return {par.c() * (p1(0) - p0(0)), Eigen::Matrix<T, 2, 1>(T(0.0), T(0.0))};
}

// Unreduced configuration q = (x, y, θ, ψ) <-> shape ψ and group g = (R(θ), (x, y)).
inline SE2::Element<double> beanie_group(const Eigen::Vector4d& q) { return {q(2), q.head<2>()}; }
// g~_n = W_n A(ψ_n, ψ_{n+1}) = (R(Δθ + c Δψ), R(θ_n)^T Δr)  (METHOD.md §6.2).
inline SE2::Element<double> beanie_increment(const BeanieParameters& par, const Eigen::Vector4d& q0,
                                             const Eigen::Vector4d& q1) {
  const Eigen::Vector4d dq = q1 - q0;
  return {dq(2) + par.c() * dq(3), SO2::rotation(q0(2)).transpose() * dq.head<2>()};
}

struct BeanieFree {
  using Group = SE2;
  static constexpr int shape_dim = 1;
  static constexpr int order = 1;
  static constexpr int num_constraints = 0;
  BeanieParameters par;

  // (76) corrected: (h m/2)|Ω12|^2 + (h (I1+I2)/2) Ω3^2 + μ Δψ^2/(2h) - h V(ψ_{n+1}).
  template <class T>
  T lagrangian(const Window<BeanieFree, T>& a, double h) const {
    const T dpsi = a.p[1](0) - a.p[0](0);
    const auto& g = a.g[0];
    return (0.5 * par.m / h) * g.t.squaredNorm() + (0.5 * (par.I1 + par.I2) / h) * g.angle * g.angle +
           (0.5 * par.mu() / h) * dpsi * dpsi - h * par.V(a.p[1](0));
  }
  template <class T>
  SE2::Element<T> connection(const Vec<T, 1>& p0, const Vec<T, 1>& p1) const {
    return beanie_connection(par, p0, p1);
  }
};

enum class BeanieConstraints {
  Paper,          // (80)–(82): Ω12^{n+1} = (I - h ϑ J) Ω12^n, forward Euler
  ExactRotation,  // Ω12^{n+1} = R(-(h Ω3^n - c Δψ_n)) Ω12^n, which keeps |Ω12|
};

struct BeanieControl {
  using Group = SE2;
  static constexpr int shape_dim = 1;
  static constexpr int order = 2;
  static constexpr int num_constraints = 3;
  BeanieParameters par;
  BeanieConstraints variant = BeanieConstraints::ExactRotation;

  // u_n = μ Δ²ψ_n / h^2 + V'(ψ_{n+1}), the shape control of window n.
  template <class T>
  T control(const Window<BeanieControl, T>& a, double h) const {
    return par.mu() * (a.p[2](0) - 2.0 * a.p[1](0) + a.p[0](0)) / (h * h) + par.dV(a.p[1](0));
  }
  // L^_d = (h/2) u_n^2, eq. (79).
  template <class T>
  T lagrangian(const Window<BeanieControl, T>& a, double h) const {
    const T u = control(a, h);
    return 0.5 * h * u * u;
  }
  // chi^{1,2} = Ω12^{n+1} - Rot(ϑ) Ω12^n with h ϑ = h Ω3^n - c Δψ_n = Δθ_n, chi^3 = ΔΩ3^n.
  template <class T>
  Vec<T, 3> constraints(const Window<BeanieControl, T>& a, double h) const {
    using std::cos;
    using std::sin;
    const T beta = a.g[0].angle - par.c() * (a.p[1](0) - a.p[0](0));
    const Eigen::Matrix<T, 2, 1>& t0 = a.g[0].t;
    Eigen::Matrix<T, 2, 1> rotated;
    if (variant == BeanieConstraints::ExactRotation) {
      const T cb = cos(beta), sb = sin(beta);  // R(-β) t0
      rotated(0) = cb * t0(0) + sb * t0(1);
      rotated(1) = cb * t0(1) - sb * t0(0);
    } else {  // (I - β J) t0
      rotated(0) = t0(0) + beta * t0(1);
      rotated(1) = t0(1) - beta * t0(0);
    }
    Vec<T, 3> chi;
    chi(0) = (a.g[1].t(0) - rotated(0)) / h;
    chi(1) = (a.g[1].t(1) - rotated(1)) / h;
    chi(2) = (a.g[1].angle - a.g[0].angle) / h;
    return chi;
  }
  template <class T>
  SE2::Element<T> connection(const Vec<T, 1>& p0, const Vec<T, 1>& p1) const {
    return beanie_connection(par, p0, p1);
  }
  // The increment g~_{n+1} that satisfies chi(a_n) = 0 given g~_n and Δψ_n (Ω3 kept, Ω12 rotated
  // by Rot(β), β = angle(g~_n) - c Δψ_n): used to build initial data and guesses.
  SE2::Element<double> next_increment(const SE2::Element<double>& g, double dpsi) const {
    const double beta = g.angle - par.c() * dpsi;
    const Eigen::Vector2d t = variant == BeanieConstraints::ExactRotation
                                  ? Eigen::Vector2d(SO2::rotation(-beta) * g.t)
                                  : Eigen::Vector2d(g.t(0) + beta * g.t(1), g.t(1) - beta * g.t(0));
    return {g.angle, t};
  }
};

// The continuous optimal control (METHOD.md §6.2, §9) for the Galerkin schemes: ℓ = ½ u² with
// u = μ ψ'' + V'(ψ); the free beanie's group equations as constraints on Ω = ξ + (0, 0, c ψ'),
//   χ = (Ω1' - w Ω2, Ω2' + w Ω1, Ω3'),  w = Ω3 - c ψ' = θ'
// (Ω12 turns against θ: the spatial velocity R(θ) Ω12 is constant), and the connection
// form 𝒜 = (0, 0, c).
struct BeanieModel {
  using Group = SE2;
  static constexpr int shape_dim = 1;
  static constexpr int num_constraints = 3;
  BeanieParameters par;

  template <class T>
  T control(const Jet<BeanieModel, T>& q) const {
    return par.mu() * q.ddp(0) + par.dV(q.p(0));
  }
  template <class T>
  T lagrangian(const Jet<BeanieModel, T>& q) const {
    const T u = control(q);
    return 0.5 * u * u;
  }
  template <class T>
  Vec<T, 3> constraints(const Jet<BeanieModel, T>& q) const {
    const T w = q.Omega(2) - par.c() * q.dp(0);
    Vec<T, 3> chi;
    chi(0) = q.dOmega(0) - w * q.Omega(1);
    chi(1) = q.dOmega(1) + w * q.Omega(0);
    chi(2) = q.dOmega(2);
    return chi;
  }
  template <class T>
  Eigen::Matrix<T, 3, 1> connection_form(const Vec<T, 1>&) const {
    return Eigen::Matrix<T, 3, 1>(T(0.0), T(0.0), T(par.c()));
  }
};

}  // namespace lpshoot::problems

extern template class lpshoot::DiscreteFlow<lpshoot::problems::BeanieFree>;
extern template class lpshoot::DiscreteFlow<lpshoot::problems::BeanieControl>;
