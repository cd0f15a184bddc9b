// The exact continuous minimum-energy transfer of the electron (METHOD.md §6.1): the reference
// against which the discrete optimum's error and convergence order are measured.
#pragma once

#include "electron.hpp"

namespace lpshoot::problems {

// With general constant B and φ(x) = potential |x|^2, write K v = (e/c) B × v (skew), so that
// u = m x'' + K x' + 2κ x; min ½ ∫_0^T |u|^2 gives the Euler–Lagrange equation
// m u'' + K u' + 2κ u = 0. The first-order system y' = A y with y = (x, x', u, u') is linear, so
// y(t) = expm(A t) y(0) exactly; u(0), u'(0) come from a 6×6 linear solve that hits x(T), x'(T).
struct ElectronOptimum {
  Eigen::Matrix<double, 12, 12> A;
  Eigen::Matrix<double, 12, 1> y0;                     // y = (x, x', u, u') at t = 0
  Eigen::Matrix<double, 12, 1> state(double t) const;  // expm(A t) y0
  Eigen::Vector3d position(double t) const { return state(t).segment<3>(0); }
  Eigen::Vector3d velocity(double t) const { return state(t).segment<3>(3); }
  Eigen::Vector3d control(double t) const { return state(t).segment<3>(6); }
  double cost = 0;  // ½ ∫_0^T |u|^2 dt, by Van Loan's block exponential
};

ElectronOptimum electron_exact_optimum(const Electron& e, double T, const Eigen::Vector3d& x0,
                                       const Eigen::Vector3d& v0, const Eigen::Vector3d& xT,
                                       const Eigen::Vector3d& vT);

}  // namespace lpshoot::problems
