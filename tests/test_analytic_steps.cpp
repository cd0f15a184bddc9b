// The engine's derived step against hand-solved steps of the same schemes (the oracles that are
// also the benchmark baselines): the electron and the k = 2 beanie control, both constraint sets.
#include "helpers.hpp"
#include "oracles/analytic_steps.hpp"

#include <gtest/gtest.h>

using namespace lpshoot;
using problems::BeanieConstraints;
using problems::BeanieControl;
using problems::Electron;

TEST(AnalyticSteps, ElectronFlowMatchesHandSolvedStep) {
  const Electron e{1.0, 1.0, Eigen::Vector3d(0, 0, 1.0), 1.0};
  const double h = 0.01;
  const int N = 400;
  FlowState<Electron> s;
  const Eigen::Vector3d x0(1, 0, 0.5), v0(0, 1, -0.2), a0(0.3, -0.1, 0.2);
  for (int i = 0; i < 4; ++i) s.p[i] = x0 + i * h * v0 + 0.5 * (i * h) * (i * h) * a0;
  const auto res = DiscreteFlow<Electron>(e, h).run(s, N);
  ASSERT_TRUE(res.report.ok()) << res.report.message;
  std::vector<Eigen::Vector3d> x(s.p.begin(), s.p.end());
  for (int n = 2; n + 2 <= N; ++n) x.push_back(oracles::electron_analytic_step(e, {x[n - 2], x[n - 1], x[n], x[n + 1]}, h));
  double diff = 0, scale = 0;
  for (int n = 0; n <= N; ++n) {
    diff = std::max(diff, (x[n] - res.trajectory.p[n]).lpNorm<Eigen::Infinity>());
    scale = std::max(scale, x[n].lpNorm<Eigen::Infinity>());
  }
  std::printf("electron: engine vs hand-solved over %d steps: %.2e (max |x| %.2f)\n", N, diff, scale);
  // A k = 2 recursion amplifies roundoff like N^4 eps (METHOD.md §5): 400^4 * 2.2e-16 = 5.6e-6
  // is the bound; both are the same scheme, so they stay much closer.
  EXPECT_LT(diff, 1e-8 * scale);
}

// The closed-form step map (the hand-written paper electron flow of bench_ratios) against the
// hand-solved step at a state, and against the engine's derived sensitivity dz/d(state): the step
// is linear, so both are the same matrix up to rounding.
TEST(AnalyticSteps, ElectronStepMapMatchesHandSolvedStepAndEngineSensitivity) {
  const Electron e{1.3, 0.7, Eigen::Vector3d(0.2, -0.4, 1.1), 0.6};
  const double h = 0.02;
  FlowState<Electron> s;
  const Eigen::Vector3d x0(1, 0, 0.5), v0(0, 1, -0.2), a0(0.3, -0.1, 0.2);
  for (int i = 0; i < 4; ++i) s.p[i] = x0 + i * h * v0 + 0.5 * (i * h) * (i * h) * a0;
  const Eigen::Matrix<double, 3, 12> Phi = oracles::electron_paper_step_map(e, h);
  Eigen::Matrix<double, 12, 1> state;
  state << s.p[0], s.p[1], s.p[2], s.p[3];
  const Eigen::Vector3d by_map = Phi * state;
  const Eigen::Vector3d by_step = oracles::electron_analytic_step(e, {s.p[0], s.p[1], s.p[2], s.p[3]}, h);
  // Both cancel terms of size m/h² |x| ~ 3e3 down to |x| ~ 1: rounding ~ 1e-12.
  EXPECT_LT((by_map - by_step).lpNorm<Eigen::Infinity>(), 1e-11 * by_step.lpNorm<Eigen::Infinity>());
  StepUnknowns<Electron> z;
  ASSERT_EQ(solve_step(e, h, s, 2, NewtonOptions{}, z).status, StepStatus::Converged);
  const auto dz = step_sensitivity(e, h, s, z);
  const double diff = (dz - Phi).lpNorm<Eigen::Infinity>(), scale = Phi.lpNorm<Eigen::Infinity>();
  std::printf("electron step map: against the hand-solved step %.1e, against the engine's sensitivity %.1e (max |Φ| %.1f)\n",
              (by_map - by_step).lpNorm<Eigen::Infinity>(), diff, scale);
  EXPECT_LT(diff, 1e-12 * scale);
}

namespace {
// The beanie control cases: both constraint sets, V = 0 and V = 1 - cos ψ, each a flow of `steps`
// steps (h = 0.02) from data with non-zero multipliers, handed to check(b, h, flow result).
template <class F>
void for_each_beanie_flow(int steps, const F& check) {
  for (auto variant : {BeanieConstraints::ExactRotation, BeanieConstraints::Paper}) {
    for (double amplitude : {0.0, 1.0}) {
      BeanieControl b;
      b.par = {1.2, 0.8, 0.6, amplitude};
      b.variant = variant;
      const double h = 0.02;
      auto s = test_support::beanie_control_initial(b, Eigen::Vector3d(0.4, 0.8, -0.5), Eigen::Vector3d(0.5, 0.2, -0.7),
                                               Eigen::Vector3d(0.2, -0.1, 0.3), Eigen::Vector3d(0.201, -0.098, 0.302),
                                               h);
      const auto res = DiscreteFlow<BeanieControl>(b, h).run(s, steps);
      ASSERT_TRUE(res.report.ok()) << res.report.message;
      check(b, h, res);
    }
  }
}
}  // namespace

TEST(AnalyticSteps, BeanieControlStepMatchesHandSolvedStep) {
  for_each_beanie_flow(200, [](const BeanieControl& b, double h, const FlowResult<BeanieControl>& res) {
    double dp = 0, dg = 0, dl = 0;
    for (int n = 2; n <= 200 - 2; ++n) {
      const auto st = res.trajectory.state(n);
      const auto z = oracles::beanie_control_analytic_step(b, st, h);
      dp = std::max(dp, std::abs(z.p(0) - res.trajectory.p[n + 2](0)));
      const auto& g = res.trajectory.g[n + 1];
      dg = std::max(dg, std::max(std::abs(z.g.angle - g.angle), (z.g.t - g.t).lpNorm<Eigen::Infinity>()));
      dl = std::max(dl, (z.lam - res.trajectory.lam[n]).lpNorm<Eigen::Infinity>() /
                            std::max(1.0, z.lam.lpNorm<Eigen::Infinity>()));
    }
    EXPECT_LT(dp, 1e-12) << "psi";
    EXPECT_LT(dg, 1e-14) << "increment";
    EXPECT_LT(dl, 1e-9) << "multipliers";
  });
}

// The engine's step sensitivity (implicit function theorem on derived Jacobians, step_solve.hpp) against
// the hand-written tangent-linear step, at states along a flow with non-zero multipliers. The
// oracle is first checked against central differences of the hand-solved step itself.
TEST(AnalyticSteps, BeanieControlSensitivityMatchesHandWrittenTangent) {
  using FS = FlowState<BeanieControl>;
  constexpr int ns = Dims<BeanieControl>::state;
  for_each_beanie_flow(60, [](const BeanieControl& b, double h, const FlowResult<BeanieControl>& res) {
    double oracle_fd = 0, engine = 0;
    for (int n : {2, 30, 58}) {
      const FS s = res.trajectory.state(n);
      oracles::BeanieStepSensitivity hand;
      const auto z = oracles::beanie_control_analytic_step(b, s, h, hand);
      const double scale = hand.lpNorm<Eigen::Infinity>();
      // Central differences of the hand-solved step along each tangent coordinate (the state
      // moved as the engine moves it, flow.hpp's retraction): error O(ε²) + roundoff / ε.
      const double eps = 1e-6;
      for (int col = 0; col < ns; ++col) {
        Vec<double, ns> e = Vec<double, ns>::Zero();
        e(col) = eps;
        const auto zp = oracles::beanie_control_analytic_step(b, retract(s, e), h);
        const auto zm = oracles::beanie_control_analytic_step(b, retract(s, Vec<double, ns>(-e)), h);
        Vec<double, 7> d;
        d(0) = zp.p(0) - zm.p(0);
        d.segment<3>(1) = SE2::log(SE2::compose(SE2::inverse(zm.g), zp.g));
        d.tail<3>() = zp.lam - zm.lam;
        oracle_fd = std::max(oracle_fd, (d / (2 * eps) - hand.col(col)).lpNorm<Eigen::Infinity>() / scale);
      }
      const auto derived = step_sensitivity(b, h, s, z);
      engine = std::max(engine, (derived - hand).lpNorm<Eigen::Infinity>() / scale);
    }
    std::printf("beanie step sensitivity (%s, amplitude %.0f): hand vs differences %.2e, engine vs hand %.2e\n",
                b.variant == BeanieConstraints::Paper ? "paper" : "exact", b.par.amplitude, oracle_fd, engine);
    // Differences: ε² times third derivatives plus roundoff over ε (~1e-10 relative here).
    EXPECT_LT(oracle_fd, 1e-8);
    // Both are exact derivatives of the same equations at the same solution: roundoff only,
    // amplified by the step matrix's condition (~1/h² for the ψ rows).
    EXPECT_LT(engine, 1e-12);
  });
}
