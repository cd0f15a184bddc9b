// Extremes (issue 14): Galerkin steps at tiny h, where each step's Newton correction cannot get
// below its rounding; rank diagnostics of Jacobians from an overflowing flow.
#include "beanie_galerkin_start.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/shooting/diagnostics.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {

// 300 steps at h = 2/N with the default step tolerance (1e-12, below what a step can resolve at
// these h: terms of size 1/h cancel in its equations). Each step must be accepted at its rounding
// and still solve its equations: the momentum map (conserved exactly by solutions of the step
// equations, METHOD.md §4) drifts only by rounding: measured at most 1.2e-11 relative here. The
// bound, 1e-10, is far below what a wrongly accepted step would leave: the stagnation rule may
// accept corrections of up to 1e-8 relative, and a step stopped there drifts J by about that.
template <int S>
void tiny_steps(int N) {
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  const double T = 2.0, h = T / N;
  const int steps = 300;
  const SE2::Element<double> g0{0.3, Eigen::Vector2d(0.5, -0.2)};
  const auto start = test_support::beanie_interval_with_multipliers<S>(model, T, N);
  // With sensitivities (as shooting runs flows) each step starts with chord steps on the step
  // before's matrix, and a fresh-Jacobian step can land below a noisy residual that the next
  // chord step returns to: the stagnation must be seen in the corrections too.
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(BeanieGalerkin<S>::state, BeanieGalerkin<S>::state);
  const auto seeded = GalerkinFlow<BeanieGalerkin<S>>(model, h, NewtonOptions{}).run(start, steps, &seed, g0);
  ASSERT_TRUE(seeded.report.ok()) << "h = " << h << ", with sensitivities: " << seeded.report.message;
  ASSERT_TRUE(seeded.sensitivity.allFinite());
  const auto run = GalerkinFlow<BeanieGalerkin<S>>(model, h, NewtonOptions{}).run(start, steps, nullptr, g0);
  ASSERT_TRUE(run.report.ok()) << "h = " << h << ": " << run.report.message;
  const auto J = galerkin_spatial_momentum<BeanieGalerkin<S>>(model, run.trajectory);
  double drift = 0, lam = 0;
  for (const auto& Jn : J) drift = std::max(drift, (Jn - J.front()).template lpNorm<Eigen::Infinity>());
  for (const auto& iv : run.trajectory.intervals) lam = std::max(lam, iv.w.template lpNorm<Eigen::Infinity>());
  const double relative = drift / std::max(1.0, J.front().template lpNorm<Eigen::Infinity>());
  const double bound = 1e-10;
  std::printf("degree %d, h = %.0e: %d steps, max Newton iterations %d, max step condition %.2e, max |lambda| %.2g, relative "
              "momentum drift %.2e\n",
              S, h, steps, run.report.max_iterations, run.report.max_condition, lam, relative);
  EXPECT_LT(relative, bound);
}

}  // namespace

TEST(TinySteps, GalerkinOrderFourStepsConvergeDownToHEqualsOneMillionth) {
  for (int N : {20000, 200000, 2000000}) tiny_steps<3>(N);
}

TEST(TinySteps, GalerkinOrderSixStepsConvergeDownToHEqualsOneMillionth) {
  for (int N : {20000, 200000, 2000000}) tiny_steps<4>(N);
}

namespace {

// Flows with sensitivities at fine steps take each step's prediction (extrapolated, O(h³) off:
// 2e-11 to 4e-11 relative here, within the confirmation's bound, which the residual's noise sets
// at ~1e-8) and evaluate the step only where its sensitivity does, confirming it there with one
// exact Newton correction (galerkin_flow.hpp). The steps must still solve their equations:
// - the Newton iterations are those of the first steps only (a step iterated on takes >= 2);
// - the momentum map drifts by rounding: measured <= 3.6e-13 relative (plain flows: 7e-12); a
//   step left at its prediction, its correction not applied, drifts it by 7e-10;
// - the nodes (x, v, Ω) agree with the plain flow's: measured <= 2.8e-13 (7.7e-12 to 1.4e-10 with
//   the correction not applied);
// - the sensitivity agrees with central differences of plain flows (measured <= 2.3e-9 relative).
// The plain flow's chord steps end once well within the noise its earlier steps measured
// (NewtonOptions::noise_floor): 2.0-2.1 iterations per step here, 2.6-2.7 when they sampled the
// noise until it stalled (767-807 iterations for the 300 steps); its momentum drift is
// tiny_steps' (unchanged: 6.9e-12 against 7.0e-12 at h = 2e-5).
template <int S>
void predictions_taken(int N) {
  using BG = BeanieGalerkin<S>;
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  const double T = 2.0, h = T / N;
  const int steps = 300;
  constexpr int ns = BG::state;
  const SE2::Element<double> g0{0.3, Eigen::Vector2d(0.5, -0.2)};
  const auto start = test_support::beanie_interval_with_multipliers<S>(model, T, N);
  const GalerkinFlow<BG> flow(model, h);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(ns, ns);
  const auto seeded = flow.run(start, steps, &seed, g0);
  const auto plain = flow.run(start, steps, nullptr, g0);
  ASSERT_TRUE(seeded.report.ok()) << seeded.report.message;
  ASSERT_TRUE(plain.report.ok()) << plain.report.message;
  double nodes = 0;
  for (int n = 0; n <= steps; ++n) {
    const auto& a = seeded.trajectory.intervals[n];
    const auto& b = plain.trajectory.intervals[n];
    nodes = std::max(nodes, (a.x - b.x).norm() + (a.v - b.v).norm() + (a.Om - b.Om).norm());
  }
  const auto J = galerkin_spatial_momentum<BG>(model, seeded.trajectory);
  double drift = 0;
  for (const auto& Jn : J) drift = std::max(drift, (Jn - J.front()).template lpNorm<Eigen::Infinity>());
  drift /= std::max(1.0, J.front().template lpNorm<Eigen::Infinity>());
  double fd = 0;
  const double eps = 1e-6, size = seeded.sensitivity.cwiseAbs().maxCoeff();
  for (int j : {0, 2, 5, 9}) {
    Vec<double, ns> delta = Vec<double, ns>::Zero();
    delta(j) = eps;
    const auto up = flow.run(retract<BG>(start, delta, h), steps, nullptr, g0, 0, false);
    const auto down = flow.run(retract<BG>(start, Vec<double, ns>(-delta), h), steps, nullptr, g0, 0, false);
    ASSERT_TRUE(up.report.ok() && down.report.ok());
    const Vec<double, ns> column =
        state_difference<BG>(up.trajectory.intervals.back(), down.trajectory.intervals.back(), h) / (2 * eps);
    fd = std::max(fd, (column - seeded.sensitivity.col(j)).template lpNorm<Eigen::Infinity>() / size);
  }
  std::printf("degree %d, h = %.0e, %d steps with sensitivities: %d Newton iterations (plain: %d); momentum drift %.2e, "
              "nodes against the plain flow %.2e, sensitivity against differences %.2e\n",
              S, h, steps, seeded.report.total_iterations, plain.report.total_iterations, drift, nodes, fd);
  EXPECT_LE(seeded.report.total_iterations, steps / 10);
  EXPECT_LE(plain.report.total_iterations, 5 * steps / 2);
  EXPECT_LT(drift, 1e-11);
  EXPECT_LT(nodes, 2e-12);
  EXPECT_LT(fd, 1e-7);
}

}  // namespace

TEST(TinySteps, FlowsWithSensitivitiesTakeTheirPredictionsAndStillSolveTheirEquations) {
  predictions_taken<3>(20000);
  predictions_taken<3>(100000);
  predictions_taken<4>(100000);
}

// The beanie scene's problem at N = 10⁵ (h = 2e-5), shooting's segment 289 from its guess, with
// sensitivities: at step 28955 the fresh-Jacobian step reached a residual of 1.5e-12, the chord
// step after it went back to 7e-12 (rounding), and the two alternated for 20 iterations with
// corrections of 3e-12 relative, above the step tolerance and within rounding. Found by
// bench_scaling (BM_BeanieGalerkin4/100000), which then reported a failed flow from the guess.
TEST(TinySteps, AlternatingNoisyResidualsAreRecognisedAsTheRoundoffFloor) {
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  BeanieBoundary s, e;
  test_support::beanie_scene_boundary(s, e);
  const int N = 100000, first = 28900, steps = 100;
  const auto bvp = beanie_galerkin_bvp<3>(model, 2.0, N, s, e);
  const auto guess = beanie_galerkin_guess<3>(bvp, s, e);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(BeanieGalerkin<3>::state, BeanieGalerkin<3>::state);
  const GalerkinFlow<BeanieGalerkin<3>> flow(model, bvp.h());
  const auto run = flow.run(guess.trajectory.intervals[first], steps, &seed, SE2::identity<double>(), first, false);
  ASSERT_TRUE(run.report.ok()) << run.report.message;
  EXPECT_LE(run.report.max_iterations, 8);
  // The steps still solve their equations: the plain flow (Newton-solved steps) ends at the same
  // interval to well within the step tolerance's accumulation (100 steps x 1e-12 relative).
  const auto plain = flow.run(guess.trajectory.intervals[first], steps, nullptr, SE2::identity<double>(), first, false);
  ASSERT_TRUE(plain.report.ok()) << plain.report.message;
  const auto& a = run.trajectory.intervals.back();
  const auto& b = plain.trajectory.intervals.back();
  EXPECT_LT((a.x - b.x).norm() + (a.v - b.v).norm() + (a.Om - b.Om).norm(), 1e-9);
}

TEST(RankDiagnosis, ANonFiniteJacobianHasNoRank) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(4, 4);
  J(2, 1) = INFINITY;
  const RankDiagnosis d = diagnose_rank(J, {"a", "b", "c", "d"}, 1e-10);
  EXPECT_EQ(d.rank, -1);
  EXPECT_FALSE(std::isfinite(d.condition));
}

TEST(RankDiagnosis, SubnormalRoundingDoesNotHideADependentRow) {
  // Rows 0 and 3 are equal up to entries far below rounding (subnormal after equilibration):
  // rank 39 of 40, and the dependent pair is named.
  const int n = 40;
  Eigen::MatrixXd J = Eigen::MatrixXd::Random(n, n);
  J.row(n - 1) = J.row(0);
  for (int c = 0; c < n; c += 3) J(n - 1, c) += 1e-310;
  J.row(5) *= 1e250;
  std::vector<std::string> names;
  for (int i = 0; i < n; ++i) names.push_back("row " + std::to_string(i));
  const RankDiagnosis d = diagnose_rank(J, names, 1e-10);
  EXPECT_EQ(d.rank, n - 1);
  ASSERT_EQ(d.dependent_conditions.size(), 1u);
  EXPECT_NE(d.dependent_conditions[0].find("[row 0]"), std::string::npos) << d.dependent_conditions[0];
  EXPECT_NE(d.dependent_conditions[0].find("[row 39]"), std::string::npos) << d.dependent_conditions[0];
}
