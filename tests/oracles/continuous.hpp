// Continuous-time optimal controls of the paper's examples (METHOD.md §6.1, §6.2): reference
// solutions ("oracles") against which the discrete optimal controls' convergence is measured.
#pragma once

#include <lpshoot/problems/beanie.hpp>
#include <lpshoot/problems/electron.hpp>

#include <string>
#include <vector>

namespace lpshoot::oracles {

// Electron, METHOD.md §6.1, with general constant B and φ(x) = potential |x|^2. With
// K v = (e/c) B × v (skew), u = m x'' + K x' + 2κ x and min ½ ∫_0^T |u|^2 gives the
// Euler–Lagrange equation m u'' + K u' + 2κ u = 0. The first-order system y' = A y with
// y = (x, x', u, u') is linear, so y(t) = expm(A t) y(0) exactly; u(0), u'(0) come from a 6×6
// linear solve that hits x(T), x'(T).
struct ElectronOptimum {
  Eigen::Matrix<double, 12, 12> A;
  Eigen::Matrix<double, 12, 1> y0;  // y = (x, x', u, u') at t = 0
  Eigen::Matrix<double, 12, 1> state(double t) const;  // expm(A t) y0
  Eigen::Vector3d position(double t) const { return state(t).segment<3>(0); }
  Eigen::Vector3d velocity(double t) const { return state(t).segment<3>(3); }
  Eigen::Vector3d control(double t) const { return state(t).segment<3>(6); }
  double cost = 0;  // ½ ∫_0^T |u|^2 dt, by Van Loan's block exponential
};

ElectronOptimum electron_exact_optimum(const problems::Electron& e, double T, const Eigen::Vector3d& x0,
                                       const Eigen::Vector3d& v0, const Eigen::Vector3d& xT,
                                       const Eigen::Vector3d& vT);

// Elroy's beanie, METHOD.md §6.2, with natural terminal conditions (zero multipliers): the shape
// solves min ½ ∫_0^T u^2, u = μ ψ'' + V'(ψ), with ψ, ψ' given at both ends. Necessary conditions:
// ψ'' = (u − V'(ψ))/μ, u'' = −V''(ψ) u/μ; solved by Newton shooting on (u(0), u'(0)) with an
// adaptive dense-output Dormand–Prince integrator (tolerances 1e-13) and variational equations.
struct BeanieOptimum {
  bool converged = false;
  std::string message;
  int iterations = 0;      // Newton steps taken
  double u0 = 0, du0 = 0;  // u(0), u'(0)
  double cost = 0;         // ½ ∫ u^2 dt (integrated as an extra state component)
  // Values at the requested times (sorted, in [0, T]): psi, dpsi, u.
  std::vector<double> times, psi, dpsi, u;
};

// Throws std::invalid_argument unless T > 0 and times is sorted in [0, T]. Newton starts from the
// cubic Hermite interpolant of the boundary data (the exact answer when amplitude = 0).
BeanieOptimum beanie_continuous_optimum(const problems::BeanieParameters& par, double T, double psi0,
                                        double dpsi0, double psiT, double dpsiT,
                                        const std::vector<double>& times);

}  // namespace lpshoot::oracles
