// The exact continuous minimum-energy transfer of the electron (METHOD.md §6.1): the reference
// against which the discrete optimum's error and convergence order are measured.
#pragma once

#include "electron.hpp"

#include <vector>

namespace lpshoot::problems {

// With general constant B and φ(x) = potential |x|^2, write K v = (e/c) B × v (skew), so that
// u = m x'' + K x' + 2κ x; min ½ ∫_0^T |u|^2 gives the Euler–Lagrange equation
// m u'' + K u' + 2κ u = 0. The first-order system y' = A y with y = (x, x', u, u') is linear.
// expm(A T) grows like e^{|A| T} (with a potential, e^{√2 T}-fold over the horizon), so one
// exponential over [0, T] loses every digit for long horizons. Instead y is found at the ends
// of M pieces of length τ with |A|_1 τ <= 1 (each expm(A τ) well conditioned): continuity
// y_{i+1} = expm(A τ) y_i and the 12 boundary values form a block-bidiagonal linear system
// (multiple shooting, solved sparse), whose conditioning is the problem's own.
struct ElectronOptimum {
  Eigen::Matrix<double, 12, 12> A;
  Eigen::Matrix<double, 12, 1> y0;                     // y = (x, x', u, u') at t = 0
  double tau = 0;                                      // piece length
  std::vector<Eigen::Matrix<double, 12, 1>> nodes;     // y(i τ), i = 0..M
  double residual = 0;  // max-norm residual of the linear system, relative to the solution's size
  Eigen::Matrix<double, 12, 1> state(double t) const;  // expm(A (t - i τ)) y_i on piece i
  Eigen::Vector3d position(double t) const { return state(t).segment<3>(0); }
  Eigen::Vector3d velocity(double t) const { return state(t).segment<3>(3); }
  Eigen::Vector3d control(double t) const { return state(t).segment<3>(6); }
  double cost = 0;  // ½ ∫_0^T |u|^2 dt, by Van Loan's block exponential
};

ElectronOptimum electron_exact_optimum(const Electron& e, double T, const Eigen::Vector3d& x0,
                                       const Eigen::Vector3d& v0, const Eigen::Vector3d& xT,
                                       const Eigen::Vector3d& vT);

}  // namespace lpshoot::problems
