// Momentum (METHOD.md §4): the spatial momentum J_n = Ad*_{g_n^{-1}} M_n is constant along every
// discrete solution, for any h and any multipliers, up to the Newton tolerance.
#include "helpers.hpp"

#include <gtest/gtest.h>

using namespace lpshoot;
using problems::BeanieConstraints;
using problems::BeanieControl;
using problems::BeanieFree;
using problems::BeanieParameters;

namespace {
double relative_drift(const std::vector<Eigen::Vector3d>& J) {
  double drift = 0;
  for (const auto& Jn : J) drift = std::max(drift, (Jn - J.front()).lpNorm<Eigen::Infinity>());
  return drift / J.front().lpNorm<Eigen::Infinity>();
}
}  // namespace

TEST(Momentum, FreeBeanieConservesSpatialMomentumOver1000Steps) {
  const BeanieParameters par{1.0, 1.0, 0.5, 1.0};  // V = 1 - cos ψ
  for (double h : {0.001, 0.01, 0.1}) {
    const int N = 1000;
    const Eigen::Vector4d q0(0.3, -0.1, 0.2, 0.8), v0(1.0, 0.5, 0.3, 0.4);
    const BeanieFree b{par};
    const auto res = DiscreteFlow<BeanieFree>(b, h).run(test_support::beanie_free_initial(par, q0, v0, h), N);
    ASSERT_TRUE(res.report.ok()) << res.report.message;
    const auto J = spatial_momentum(b, res.trajectory, problems::beanie_group(q0));
    ASSERT_EQ(static_cast<int>(J.size()), N);
    const double drift = relative_drift(J);
    std::printf("free beanie h = %g: %d steps, relative momentum drift %.2e\n", h, N, drift);
    EXPECT_LE(drift, 1e-11);

    // METHOD.md §4's closed form for k = 1: J = (m Δx/h, m Δy/h, (I1+I2)(Δθ + cΔψ)/h + m (x Δy - y Δx)/h).
    const auto g = reconstruct_group(b, res.trajectory, problems::beanie_group(q0));
    for (int n : {0, N / 2, N - 1}) {
      const Eigen::Vector2d r = g[n].t;
      const Eigen::Vector2d dr = g[n + 1].t - g[n].t;
      const double dth = g[n + 1].angle - g[n].angle;
      const double dpsi = res.trajectory.p[n + 1](0) - res.trajectory.p[n](0);
      const Eigen::Vector3d expected(par.m * dr(0) / h, par.m * dr(1) / h,
                                     (par.I1 + par.I2) * (dth + par.c() * dpsi) / h +
                                         par.m * (r(0) * dr(1) - r(1) * dr(0)) / h);
      EXPECT_LT((J[n] - expected).norm(), 1e-10 * expected.norm()) << "n = " << n;
    }
  }
}

TEST(Momentum, ControlFlowWithNonzeroMultipliersConservesMomentum) {
  for (auto variant : {BeanieConstraints::ExactRotation, BeanieConstraints::Paper}) {
    BeanieControl b;
    b.par = {1.0, 1.0, 0.5, 1.0};
    b.variant = variant;
    const double h = 0.01;
    const int N = 600;
    const auto init = test_support::beanie_control_initial(b, Eigen::Vector3d(0.5, 0.8, -0.5), Eigen::Vector3d(0.8, -0.3, 0.6),
                                                      Eigen::Vector3d(0.3, -0.2, 0.1),
                                                      Eigen::Vector3d(0.302, -0.199, 0.101), h);
    const auto res = DiscreteFlow<BeanieControl>(b, h).run(init, N);
    ASSERT_TRUE(res.report.ok()) << res.report.message;
    const auto J = spatial_momentum(b, res.trajectory, SE2::Element<double>{0.2, Eigen::Vector2d(1.0, -1.0)});
    const double drift = relative_drift(J);
    std::printf("control beanie (%s constraints): %zu momenta, relative drift %.2e, |J| = %.3f\n",
                variant == BeanieConstraints::ExactRotation ? "exact-rotation" : "paper", J.size(), drift,
                J.front().norm());
    EXPECT_LE(drift, 1e-11);
    // The multipliers really are non-zero along the flow.
    EXPECT_GT(res.trajectory.lam.back().norm(), 1e-2);
  }
}

TEST(Momentum, ExactRotationKeepsOmegaNormsAndPaperConstraintsDoNot) {
  double spread[2];
  int i = 0;
  for (auto variant : {BeanieConstraints::ExactRotation, BeanieConstraints::Paper}) {
    BeanieControl b;
    b.par = {1.0, 1.0, 0.5, 1.0};
    b.variant = variant;
    const double h = 0.01;
    const int N = 600;
    const auto init = test_support::beanie_control_initial(b, Eigen::Vector3d(0.5, 0.8, -0.5), Eigen::Vector3d(0.8, -0.3, 0.6),
                                                      Eigen::Vector3d(0.3, -0.2, 0.1),
                                                      Eigen::Vector3d(0.302, -0.199, 0.101), h);
    const auto res = DiscreteFlow<BeanieControl>(b, h).run(init, N);
    ASSERT_TRUE(res.report.ok()) << res.report.message;
    double lo = 1e300, hi = 0, w_spread = 0;
    for (const auto& gt : res.trajectory.g) {
      lo = std::min(lo, gt.t.norm() / h);
      hi = std::max(hi, gt.t.norm() / h);
      w_spread = std::max(w_spread, std::abs(gt.angle - res.trajectory.g.front().angle) / h);
    }
    spread[i++] = hi - lo;
    EXPECT_LE(w_spread, 1e-12);  // Ω3 constant in both variants
  }
  std::printf("|Omega12| spread over 600 steps: exact-rotation %.2e, paper %.2e\n", spread[0], spread[1]);
  EXPECT_LE(spread[0], 1e-13);  // |Ω12| = 0.854..: a few ulps
  EXPECT_GT(spread[1], 1e-6);   // forward Euler grows |Ω12| by (1 + (hϑ)^2)^{1/2} a step
}
