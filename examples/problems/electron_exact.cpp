#include "electron_exact.hpp"

#include <Eigen/LU>
#include <Eigen/SparseLU>
#include <unsupported/Eigen/MatrixFunctions>

#include <algorithm>
#include <cmath>

namespace lpshoot::problems {

using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

Vec12 ElectronOptimum::state(double t) const {
  const int M = static_cast<int>(nodes.size()) - 1;
  const int i = std::clamp(static_cast<int>(std::floor(t / tau)), 0, std::max(M - 1, 0));
  return (A * (t - i * tau)).exp() * nodes[i];
}

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

  // M pieces with |A τ|_1 <= 1.
  const double normA = o.A.cwiseAbs().colwise().sum().maxCoeff();
  const int M = std::max(1, static_cast<int>(std::ceil(T * normA)));
  o.tau = T / M;
  const Mat12 Phi = (o.A * o.tau).exp();

  // Unknowns y_0..y_M (12 each). Rows: (x, x')(0) = a; y_{i+1} − Φ y_i = 0; (x, x')(T) = b.
  const int n = 12 * (M + 1);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(M) * 156 + 24);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < 6; ++j) {
    entries.emplace_back(j, j, 1.0);
    entries.emplace_back(n - 6 + j, 12 * M + j, 1.0);
  }
  rhs.head<3>() = x0;
  rhs.segment<3>(3) = v0;
  rhs.segment<3>(n - 6) = xT;
  rhs.tail<3>() = vT;
  for (int i = 0; i < M; ++i) {
    const int row = 6 + 12 * i;
    for (int r = 0; r < 12; ++r) {
      entries.emplace_back(row + r, 12 * (i + 1) + r, 1.0);
      for (int c = 0; c < 12; ++c)
        if (Phi(r, c) != 0) entries.emplace_back(row + r, 12 * i + c, -Phi(r, c));
    }
  }
  Eigen::SparseMatrix<double> S(n, n);
  S.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
  lu.compute(S);
  Eigen::VectorXd y = lu.info() == Eigen::Success ? Eigen::VectorXd(lu.solve(rhs))
                                                  : Eigen::VectorXd::Constant(n, std::nan(""));
  o.residual = (S * y - rhs).lpNorm<Eigen::Infinity>() / std::max(1.0, y.lpNorm<Eigen::Infinity>());
  o.nodes.resize(M + 1);
  for (int i = 0; i <= M; ++i) o.nodes[i] = y.segment<12>(12 * i);
  o.y0 = o.nodes[0];

  // Van Loan on one piece: expm([[−Aᵀ, Q], [0, A]] τ) = [[·, F12], [0, e^{Aτ}]] and
  // ∫_0^τ e^{Aᵀs} Q e^{As} ds = e^{Aτ}ᵀ F12, with Q selecting u; the cost sums the pieces.
  Eigen::Matrix<double, 24, 24> Mv = Eigen::Matrix<double, 24, 24>::Zero();
  Mv.topLeftCorner<12, 12>() = -o.A.transpose();
  Mv.block<3, 3>(6, 18) = I;  // Q = diag(0, 0, I, 0) sits in the top-right block
  Mv.bottomRightCorner<12, 12>() = o.A;
  const Eigen::Matrix<double, 24, 24> E = (Mv * o.tau).exp();
  const Mat12 W = E.bottomRightCorner<12, 12>().transpose() * E.topRightCorner<12, 12>();
  const Mat12 Ws = 0.5 * (W + W.transpose());
  o.cost = 0;
  for (int i = 0; i < M; ++i) o.cost += 0.5 * o.nodes[i].dot(Ws * o.nodes[i]);
  return o;
}

}  // namespace lpshoot::problems
