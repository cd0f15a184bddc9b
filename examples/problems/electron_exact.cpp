#include "electron_exact.hpp"

#include <Eigen/LU>
#include <unsupported/Eigen/MatrixFunctions>

namespace lpshoot::problems {

Eigen::Matrix<double, 12, 1> ElectronOptimum::state(double t) const { return (A * t).exp() * y0; }

ElectronOptimum electron_exact_optimum(const Electron& e, double T, const Eigen::Vector3d& x0,
                                       const Eigen::Vector3d& v0, const Eigen::Vector3d& xT,
                                       const Eigen::Vector3d& vT) {
  const double m = e.mass, k2 = 2 * e.potential;  // ∇φ(x) = 2κ x
  Eigen::Matrix3d K;                              // K v = (e/c) B × v, so u = m x'' + K x' + 2κ x
  K << 0, -e.B(2), e.B(1), e.B(2), 0, -e.B(0), -e.B(1), e.B(0), 0;
  K *= e.e_over_c;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();

  // y = (x, x', u, u'):  x'' = (u − K x' − 2κ x)/m,  u'' = −(K u' + 2κ u)/m.
  ElectronOptimum o;
  o.A.setZero();
  o.A.block<3, 3>(0, 3) = I;
  o.A.block<3, 3>(3, 0) = -(k2 / m) * I;
  o.A.block<3, 3>(3, 3) = -K / m;
  o.A.block<3, 3>(3, 6) = I / m;
  o.A.block<3, 3>(6, 9) = I;
  o.A.block<3, 3>(9, 6) = -(k2 / m) * I;
  o.A.block<3, 3>(9, 9) = -K / m;

  // (x, x')(T) = Φ11 (x0, v0) + Φ12 (u0, u0'), Φ = expm(A T).
  const Eigen::Matrix<double, 12, 12> Phi = (o.A * T).exp();
  Eigen::Matrix<double, 6, 1> a, b;
  a << x0, v0;
  b << xT, vT;
  o.y0 << a, Phi.topRightCorner<6, 6>().fullPivLu().solve(b - Phi.topLeftCorner<6, 6>() * a);

  // Van Loan: expm([[−Aᵀ, Q], [0, A]] T) = [[·, F12], [0, e^{AT}]] and
  // ∫_0^T e^{Aᵀs} Q e^{As} ds = e^{AT}ᵀ F12, with Q selecting u.
  Eigen::Matrix<double, 24, 24> M = Eigen::Matrix<double, 24, 24>::Zero();
  M.topLeftCorner<12, 12>() = -o.A.transpose();
  M.block<3, 3>(6, 18) = I;  // Q = diag(0, 0, I, 0) sits in the top-right block
  M.bottomRightCorner<12, 12>() = o.A;
  const Eigen::Matrix<double, 24, 24> E = (M * T).exp();
  Eigen::Matrix<double, 12, 12> W = E.bottomRightCorner<12, 12>().transpose() * E.topRightCorner<12, 12>();
  o.cost = 0.5 * o.y0.dot(0.5 * (W + W.transpose()) * o.y0);
  return o;
}

}  // namespace lpshoot::problems
