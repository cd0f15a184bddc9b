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

}  // namespace lpshoot::problems
