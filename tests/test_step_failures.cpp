// A flow that cannot go on stops with a status that names the step and the reason, and
// returns only the steps it completed (no NaN enters the trajectory).
#include "helpers.hpp"

#include <gtest/gtest.h>

using namespace lpshoot;

namespace {
// L_d = sqrt(p_0 p_1) + (p_1 - p_0)^2/(2h): the square root goes non-finite once p < 0.
struct SqrtProblem {
  using Group = Trivial;
  static constexpr int shape_dim = 1, order = 1, num_constraints = 0;
  template <class T>
  T lagrangian(const Window<SqrtProblem, T>& a, double h) const {
    using std::sqrt;
    const T dp = a.p[1](0) - a.p[0](0);
    return 0.5 * dp * dp / h + h * sqrt(a.p[1](0));
  }
};

// L_d = (p_1 - p_0)^4/h: the step matrix is 12 (Δp_n)^2/h^3, singular where the motion stops.
struct QuarticProblem {
  using Group = Trivial;
  static constexpr int shape_dim = 1, order = 1, num_constraints = 0;
  template <class T>
  T lagrangian(const Window<QuarticProblem, T>& a, double h) const {
    const T dp = a.p[1](0) - a.p[0](0);
    return dp * dp * dp * dp / h;
  }
};

template <class P>
void expect_clean_trajectory(const FlowResult<P>& res) {
  for (const auto& p : res.trajectory.p) EXPECT_TRUE(p.allFinite());
  EXPECT_EQ(res.trajectory.N(), 2 * P::order - 1 + res.report.steps);
}
}  // namespace

TEST(StepFailures, MasslessElectronHasASingularStepMatrix) {
  // m = 0 removes x_{n+2} from the equations: ∂F/∂z = 0.
  const problems::Electron e{0.0, 1.0, Eigen::Vector3d(0, 0, 1), 1.0};
  FlowState<problems::Electron> s;
  for (int i = 0; i < 4; ++i) s.p[i] = Eigen::Vector3d(1, 0.1 * i, 0);
  const auto res = DiscreteFlow<problems::Electron>(e, 0.1).run(s, 20);
  EXPECT_EQ(res.report.status, FlowStatus::Singular);
  EXPECT_EQ(res.report.failed_step, 2);
  EXPECT_NE(res.report.message.find("step n=2"), std::string::npos) << res.report.message;
  EXPECT_NE(res.report.message.find("singular"), std::string::npos) << res.report.message;
  expect_clean_trajectory(res);
}

TEST(StepFailures, BeanieWithoutShapeInertiaIsSingular) {
  // I2 = 0: μ = c = 0 and V = 0, so nothing in L_d depends on ψ: E_ψ ≡ 0.
  const problems::BeanieParameters par{1.0, 1.0, 0.0, 0.0};
  const problems::BeanieFree b{par};
  const double h = 0.01;
  const auto res = DiscreteFlow<problems::BeanieFree>(b, h).run(
      test_support::beanie_free_initial(par, Eigen::Vector4d(0, 0, 0, 0.5), Eigen::Vector4d(1, 0, 0.2, 0.3), h), 100);
  EXPECT_EQ(res.report.status, FlowStatus::Singular);
  EXPECT_EQ(res.report.failed_step, 1);
  expect_clean_trajectory(res);
}

TEST(StepFailures, MatrixBecomingSingularAlongTheFlowIsCaughtAtThatStep) {
  // Starting at rest, Δp_0 = 0: the very first step matrix 12 Δp^2/h^3 vanishes.
  FlowState<QuarticProblem> s;
  s.p = {Vec<double, 1>(1.0), Vec<double, 1>(1.0)};
  const auto res = DiscreteFlow<QuarticProblem>(QuarticProblem{}, 0.1).run(s, 10);
  EXPECT_EQ(res.report.status, FlowStatus::Singular);
  EXPECT_EQ(res.report.failed_step, 1);
  // Moving, the same problem steps fine (Δp is conserved) with a finite condition number.
  s.p = {Vec<double, 1>(1.0), Vec<double, 1>(1.1)};
  const auto ok = DiscreteFlow<QuarticProblem>(QuarticProblem{}, 0.1).run(s, 10);
  ASSERT_TRUE(ok.report.ok()) << ok.report.message;
  EXPECT_NEAR(ok.trajectory.p.back()(0), 1.0 + 10 * 0.1, 1e-12);
}

TEST(StepFailures, NonFiniteEquationsStopTheFlowAtTheStep) {
  // p'' = -h-scaled force 1/(2 sqrt p) pulls p below zero; the step where sqrt(p_{n+1}) fails
  // is reported, not a NaN trajectory.
  FlowState<SqrtProblem> s;
  s.p = {Vec<double, 1>(0.3), Vec<double, 1>(0.2)};
  const auto res = DiscreteFlow<SqrtProblem>(SqrtProblem{}, 0.1).run(s, 50);
  EXPECT_EQ(res.report.status, FlowStatus::NonFinite);
  EXPECT_GT(res.report.failed_step, 0);
  EXPECT_NE(res.report.message.find("step n=" + std::to_string(res.report.failed_step)), std::string::npos)
      << res.report.message;
  expect_clean_trajectory(res);
}

TEST(StepFailures, TooFewNewtonIterationsIsReportedAsNotConverged) {
  lpshoot::problems::BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 1.0};
  const double h = 0.05;
  const auto init = test_support::beanie_control_initial(b, Eigen::Vector3d(0.5, 0.8, -0.5), Eigen::Vector3d(0.8, -0.3, 0.6),
                                                    Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(0.302, -0.199, 0.101),
                                                    h);
  NewtonOptions opt;
  opt.max_iterations = 1;
  const auto res = DiscreteFlow<problems::BeanieControl>(b, h, opt).run(init, 20);
  EXPECT_EQ(res.report.status, FlowStatus::NotConverged);
  EXPECT_EQ(res.report.failed_step, 2);
  EXPECT_NE(res.report.message.find("did not converge"), std::string::npos) << res.report.message;
}

TEST(StepFailures, InvalidInputIsRejected) {
  FlowState<QuarticProblem> s;
  s.p = {Vec<double, 1>(1.0), Vec<double, 1>(1.1)};
  EXPECT_EQ(DiscreteFlow<QuarticProblem>(QuarticProblem{}, -0.1).run(s, 10).report.status, FlowStatus::InvalidInput);
  EXPECT_EQ(DiscreteFlow<QuarticProblem>(QuarticProblem{}, 0.1).run(s, 0).report.status, FlowStatus::InvalidInput);
}
