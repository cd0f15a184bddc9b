// Shooting on the electron (METHOD.md §5, §6.1): the discrete optimum converges to the exact
// continuous optimum (matrix exponential of the 12x12 linear system) at order 1 under the paper's
// closure and order 2 under the second-order closure; single and multiple shooting agree, and
// so do KINSOL and NLopt.
#include "oracles/continuous.hpp"

#include <lpshoot/problems/electron_bvp.hpp>

#include <gtest/gtest.h>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {
const ElectronBoundary kStart{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
const ElectronBoundary kEnd{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};

ShootingResult<Electron> solve(const Electron& e, double T, int N, Closure c, ShootingOptions opt = {}) {
  const auto bvp = electron_bvp(e, T, N, kStart, kEnd, c);
  return solve_bvp(bvp, electron_guess(bvp, kStart, kEnd), opt);
}

double max_error(const ShootingResult<Electron>& r, const oracles::ElectronOptimum& exact) {
  double err = 0;
  for (int n = 0; n <= r.trajectory.N(); ++n)
    err = std::max(err, (r.trajectory.p[n] - exact.position(r.trajectory.time(n))).lpNorm<Eigen::Infinity>());
  return err;
}
}  // namespace

TEST(ShootingElectron, ConvergesToTheExactOptimumAtTheClosuresOrder) {
  const Electron e{};  // the paper's parameters: m = 1, e/c = 1, B = (0, 0, 1), φ = |x|^2
  const double T = 2.0;
  const auto exact = oracles::electron_exact_optimum(e, T, kStart.position, kStart.velocity, kEnd.position, kEnd.velocity);
  for (Closure c : {Closure::Paper, Closure::SecondOrder}) {
    std::vector<double> err, cost_err;
    for (int N : {25, 50, 100, 200, 400}) {
      // Single shooting's roundoff grows like N^4 eps (METHOD.md §5): segments of 25 steps.
      ShootingOptions opt;
      opt.method = ShootingMethod::Multiple;
      opt.segments = N / 25;
      const auto r = solve(e, T, N, c, opt);
      ASSERT_TRUE(r.ok()) << r.message;
      err.push_back(max_error(r, exact));
      cost_err.push_back(std::abs(r.cost - exact.cost));
    }
    const double expected = c == Closure::Paper ? 1.0 : 2.0, tol = c == Closure::Paper ? 0.1 : 0.15;
    for (size_t i = 1; i < err.size(); ++i) {
      const double order = std::log2(err[i - 1] / err[i]);
      std::printf("%s closure: N = %d error %.3e order %.3f, cost error %.3e\n",
                  c == Closure::Paper ? "paper" : "second-order", 25 << i, err[i], order, cost_err[i]);
      EXPECT_NEAR(order, expected, tol) << "halving " << i;
    }
    // The discrete cost ½ Σ h |U_n|^2 is a one-sided quadrature of ½ ∫ |u|^2: first order.
    const double cost_order = std::log2(cost_err[cost_err.size() - 2] / cost_err.back());
    EXPECT_GT(cost_order, 0.85);
  }
}

TEST(ShootingElectron, SingleMultipleKinsolNloptAgree) {
  const Electron e{};
  const double T = 2.0;
  const int N = 100;
  ShootingOptions single;
  const auto a = solve(e, T, N, Closure::SecondOrder, single);
  ShootingOptions multiple;
  multiple.method = ShootingMethod::Multiple;
  multiple.segments = 5;
  const auto b = solve(e, T, N, Closure::SecondOrder, multiple);
  ShootingOptions nl;
  nl.solver.backend = Backend::Nlopt;
  const auto c = solve(e, T, N, Closure::SecondOrder, nl);
  ASSERT_TRUE(a.ok()) << a.message;
  ASSERT_TRUE(b.ok()) << b.message;
  ASSERT_TRUE(c.ok()) << c.message;
  double dab = 0, dac = 0;
  for (int n = 0; n <= N; ++n) {
    dab = std::max(dab, (a.trajectory.p[n] - b.trajectory.p[n]).lpNorm<Eigen::Infinity>());
    dac = std::max(dac, (a.trajectory.p[n] - c.trajectory.p[n]).lpNorm<Eigen::Infinity>());
  }
  std::printf("single vs multiple %.2e, kinsol vs nlopt %.2e (iterations %d / %d / %d, condition %.2e / %.2e)\n",
              dab, dac, a.iterations, b.iterations, c.iterations, a.condition, b.condition);
  EXPECT_LT(dab, 1e-8);
  EXPECT_LT(dac, 1e-8);
}
