// A shooting system's Jacobian against finite differences of its residual, for the tests.
#pragma once

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace lpshoot::test_support {

// A point near 0 for a Jacobian check: n entries scale * N(0, 1), from a fixed seed.
inline Eigen::VectorXd random_point(int n, double scale = 1e-3, unsigned seed = 5) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x(i) = scale * n01(rng);
  return x;
}

// The largest relative error, over the columns j, of J(:, j) against Richardson-extrapolated
// central differences of sys.residual at x in direction j: (4 D(eps) - D(2 eps)) / 3, truncation
// O(eps^4) (plus the residual's noise over eps). Relative to max(1, |difference|).
template <class System>
double richardson_jacobian_error(System& sys, const Eigen::VectorXd& x, const Eigen::MatrixXd& J, double eps) {
  double worst = 0;
  for (int j = 0; j < sys.size(); ++j) {
    auto central = [&](double step) {
      Eigen::VectorXd xp = x, xm = x, Fp, Fm;
      xp(j) += step;
      xm(j) -= step;
      EXPECT_TRUE(sys.residual(xp, Fp) && sys.residual(xm, Fm));
      return Eigen::VectorXd((Fp - Fm) / (2 * step));
    };
    const Eigen::VectorXd fd = (4 * central(eps) - central(2 * eps)) / 3;
    worst = std::max(worst, (J.col(j) - fd).lpNorm<Eigen::Infinity>() / std::max(1.0, fd.lpNorm<Eigen::Infinity>()));
  }
  return worst;
}

}  // namespace lpshoot::test_support
