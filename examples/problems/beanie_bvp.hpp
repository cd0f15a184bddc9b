// Elroy's beanie optimal control as a boundary value problem (METHOD.md §6.2). Each boundary
// quantity is optional: a missing one is free and gets its natural boundary condition.
//   psi, psi_dot -> shape nodes 0, 1 (N, N-1) through the closure;
//   theta, x, y  -> the group element at node 0 (N);
//   Omega1..3    -> the increment g~_0 (g~_{N-1}) = (h Omega3, h Omega12) (first-order closure).
// The well-posed problem of METHOD.md: psi, psi_dot at both ends, g(0) and Omega12(0) given,
// theta(T) given; Omega3(0), Omega(T), x(T), y(T) free.
#pragma once

#include "beanie.hpp"

#include <lpshoot/shooting/shooting.hpp>

#include <optional>
#include <stdexcept>

namespace lpshoot::problems {

struct BeanieBoundary {
  std::optional<double> psi, psi_dot, theta, x, y, Omega1, Omega2, Omega3;
};

inline BoundaryValueProblem<BeanieControl> beanie_bvp(const BeanieControl& b, double T, int N,
                                                      const BeanieBoundary& start, const BeanieBoundary& end,
                                                      Closure closure) {
  BoundaryValueProblem<BeanieControl> bvp{b, N, T, {}};
  const double h = bvp.h();
  for (End e : {End::Initial, End::Terminal}) {
    const BeanieBoundary& d = e == End::Initial ? start : end;
    const std::string side = e == End::Initial ? "initial " : "terminal ";
    if (d.psi_dot && !d.psi) throw std::invalid_argument(side + "psi_dot is given without psi");
    if (d.psi && d.psi_dot) {
      bvp.shape_with_velocity(e, 0, *d.psi, *d.psi_dot, closure, side + "psi");
    } else {
      if (d.psi)
        bvp.fix_shape(e, 0, 0, *d.psi, side + "psi");
      else
        bvp.natural(e, 0, 0, side + "psi (natural)");
      bvp.natural(e, 1, 0, side + "psi_dot (natural)");
    }
    // Group element at the end node: (v_x, v_y, w) components 0, 1, 2 <-> x, y, theta.
    const SE2::Element<double> g{d.theta.value_or(0.0), Eigen::Vector2d(d.x.value_or(0.0), d.y.value_or(0.0))};
    const std::optional<double> gq[3] = {d.x, d.y, d.theta};
    const char* gname[3] = {"x", "y", "theta"};
    for (int i = 0; i < 3; ++i) {
      if (gq[i])
        bvp.fix_group(e, 0, i, g, side + gname[i]);
      else
        bvp.natural(e, 0, 1 + i, side + gname[i] + " (natural)");
    }
    const SE2::Element<double> inc{h * d.Omega3.value_or(0.0),
                                   h * Eigen::Vector2d(d.Omega1.value_or(0.0), d.Omega2.value_or(0.0))};
    const std::optional<double> oq[3] = {d.Omega1, d.Omega2, d.Omega3};
    for (int i = 0; i < 3; ++i) {
      const std::string name = side + "Omega" + std::to_string(i + 1);
      if (oq[i])
        bvp.fix_increment(e, i, inc, name);
      else
        bvp.natural(e, 1, 1 + i, name + " (natural)");
    }
  }
  return bvp;
}

// Guess: ψ by cubic Hermite interpolation (missing data: constant / zero slope); increments that
// satisfy the chosen constraints from Omega(0) (missing: zero, or the Omega3 that reaches
// theta(T)); zero multipliers.
inline ShootingGuess<BeanieControl> beanie_guess(const BoundaryValueProblem<BeanieControl>& bvp,
                                                 const BeanieBoundary& start, const BeanieBoundary& end) {
  const BeanieControl& b = bvp.problem;
  const double h = bvp.h(), T = bvp.T, c = b.par.c();
  const double psi0 = start.psi.value_or(end.psi.value_or(0.0)), psiT = end.psi.value_or(psi0);
  const double v0 = start.psi_dot.value_or(0.0), vT = end.psi_dot.value_or(0.0);
  ShootingGuess<BeanieControl> guess;
  Trajectory<BeanieControl>& tr = guess.trajectory;
  tr.h = h;
  for (int n = 0; n <= bvp.N; ++n) {
    const double s = double(n) / bvp.N;
    const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
    const double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
    tr.p.push_back(Vec<double, 1>(h00 * psi0 + h10 * T * v0 + h01 * psiT + h11 * T * vT));
  }
  double Omega3 = start.Omega3.value_or(0.0);
  if (!start.Omega3 && start.theta && end.theta)  // θ(T) = θ(0) + Ω3 T - c (ψ(T) - ψ(0))
    Omega3 = (*end.theta - *start.theta + c * (psiT - psi0)) / T;
  SE2::Element<double> inc{h * Omega3, h * Eigen::Vector2d(start.Omega1.value_or(0.0), start.Omega2.value_or(0.0))};
  for (int n = 0; n < bvp.N; ++n) {
    tr.g.push_back(inc);
    inc = b.next_increment(inc, tr.p[n + 1](0) - tr.p[n](0));
  }
  tr.lam.assign(bvp.N - 1, Eigen::Vector3d::Zero());
  guess.g0 = {start.theta.value_or(0.0), Eigen::Vector2d(start.x.value_or(0.0), start.y.value_or(0.0))};
  return guess;
}

// The same problem for a Galerkin scheme of degree S (order 2S - 2): every quantity is node data
// (ψ, ψ' the node's shape and velocity, Ω1..3 its reduced group velocity, θ, x, y its group
// element), imposed exactly; a missing one gets its natural condition.
template <int S>
using BeanieGalerkin = Galerkin<BeanieModel, S>;

template <int S>
GalerkinBVP<BeanieGalerkin<S>> beanie_galerkin_bvp(const BeanieModel& model, double T, int N, const BeanieBoundary& start,
                                                   const BeanieBoundary& end) {
  using B = GalerkinBVP<BeanieGalerkin<S>>;
  B bvp{model, N, T, {}};
  for (End e : {End::Initial, End::Terminal}) {
    const BeanieBoundary& d = e == End::Initial ? start : end;
    const std::string side = e == End::Initial ? "initial " : "terminal ";
    if (d.psi_dot && !d.psi) throw std::invalid_argument(side + "psi_dot is given without psi");
    auto value = [&](const std::optional<double>& q, int component, const std::string& name) {
      if (q)
        bvp.fix(e, component, *q, side + name);
      else
        bvp.natural(e, component, side + name + " (natural)");
    };
    value(d.psi, B::x_component(0), "psi");
    value(d.psi_dot, B::v_component(0), "psi_dot");
    value(d.Omega1, B::Omega_component(0), "Omega1");
    value(d.Omega2, B::Omega_component(1), "Omega2");
    value(d.Omega3, B::Omega_component(2), "Omega3");
    const SE2::Element<double> g{d.theta.value_or(0.0), Eigen::Vector2d(d.x.value_or(0.0), d.y.value_or(0.0))};
    const std::optional<double> gq[3] = {d.x, d.y, d.theta};
    const char* gname[3] = {"x", "y", "theta"};
    for (int i = 0; i < 3; ++i) {
      if (gq[i])
        bvp.fix_group(e, i, g, side + gname[i]);
      else
        bvp.natural(e, B::g_component(i), side + gname[i] + " (natural)");
    }
  }
  return bvp;
}

// Guess: ψ by cubic Hermite interpolation (as beanie_guess); Ω3 constant (given, or the value that
// reaches θ(T)); the group motion of the free beanie on that ψ: θ = θ0 + Ω3 t - c (ψ - ψ0), the
// centre moving uniformly with the spatial velocity R(θ0) Ω12(0), Ω12 = R(-(θ - θ0)) Ω12(0); zero
// bubbles and multipliers.
template <int S>
GalerkinGuess<BeanieGalerkin<S>> beanie_galerkin_guess(const GalerkinBVP<BeanieGalerkin<S>>& bvp, const BeanieBoundary& start,
                                                       const BeanieBoundary& end) {
  const BeanieParameters& par = bvp.model.par;
  const double h = bvp.h(), T = bvp.T, c = par.c();
  const double psi0 = start.psi.value_or(end.psi.value_or(0.0)), psiT = end.psi.value_or(psi0);
  const double v0 = start.psi_dot.value_or(0.0), vT = end.psi_dot.value_or(0.0);
  auto psi = [&](double t, int k) {
    const double s = t / T;
    if (k == 0)
      return (2 * s * s * s - 3 * s * s + 1) * psi0 + (s * s * s - 2 * s * s + s) * T * v0 + (-2 * s * s * s + 3 * s * s) * psiT +
             (s * s * s - s * s) * T * vT;
    return ((6 * s * s - 6 * s) * psi0 + (3 * s * s - 4 * s + 1) * T * v0 + (-6 * s * s + 6 * s) * psiT + (3 * s * s - 2 * s) * T * vT) / T;
  };
  double Omega3 = start.Omega3.value_or(0.0);
  if (!start.Omega3 && start.theta && end.theta) Omega3 = (*end.theta - *start.theta + c * (psiT - psi0)) / T;
  const Eigen::Vector2d Om12(start.Omega1.value_or(0.0), start.Omega2.value_or(0.0));
  const double theta0 = start.theta.value_or(0.0);
  const Eigen::Vector2d r0(start.x.value_or(0.0), start.y.value_or(0.0));
  auto group = [&](double t) -> SE2::Element<double> {
    const double theta = theta0 + Omega3 * t - c * (psi(t, 0) - psi0);
    return {theta, Eigen::Vector2d(r0 + t * SO2::rotation(theta0) * Om12)};
  };
  GalerkinGuess<BeanieGalerkin<S>> guess;
  auto& tr = guess.trajectory;
  tr.h = h;
  tr.g0 = group(0);
  for (int n = 0; n < bvp.N; ++n) {
    const double t0 = n * h, t1 = (n + 1) * h;
    Interval<BeanieGalerkin<S>, double> iv;
    iv.x(0) = psi(t0, 0);
    iv.v(0) = psi(t0, 1);
    iv.X2(0) = (psi(t1, 0) - iv.x(0) - h * iv.v(0)) / (h * h);
    iv.V1(0) = (psi(t1, 1) - iv.v(0)) / h;
    const double dtheta0 = group(t0).angle - theta0, dtheta1 = group(t1).angle - theta0;
    iv.Om << SO2::rotation(-dtheta0) * Om12, Omega3;
    Eigen::Vector3d end_Om;
    end_Om << SO2::rotation(-dtheta1) * Om12, Omega3;
    iv.O1 = (end_Om - iv.Om) / h;
    iv.W = SE2::compose(SE2::inverse(group(t0)), group(t1));
    iv.w.setZero();
    tr.intervals.push_back(iv);
  }
  return guess;
}

}  // namespace lpshoot::problems
