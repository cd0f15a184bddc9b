// Exact sensitivities of the flow map (implicit function theorem) against central finite
// differences. With a step ε the central difference has error ~ ε^2 |f'''|/6 + u |f|/ε
// (u = 2.2e-16); for ε = 1e-5 that is ~1e-10 |f'''| + 2e-11 |f|, and we allow 1e-6 relative
// to the column's scale to cover third derivatives of size up to ~1e4 over long flows.
#include "helpers.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace lpshoot;
using problems::BeanieControl;
using problems::Electron;

namespace {
template <class P>
void check_flow_sensitivity(const P& problem, double h, const FlowState<P>& init, int N, double tol) {
  using D = Dims<P>;
  constexpr int ns = D::state;
  const DiscreteFlow<P> flow(problem, h);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(ns, ns);
  const auto res = flow.run(init, N, &seed);
  ASSERT_TRUE(res.report.ok()) << res.report.message;
  const FlowState<P> final_state = res.trajectory.state(N - D::k + 1);
  const double eps = 1e-5;
  for (int j = 0; j < ns; ++j) {
    Vec<double, ns> e = Vec<double, ns>::Zero();
    e(j) = eps;
    const auto plus = flow.run(retract(init, e), N);
    const auto minus = flow.run(retract(init, Vec<double, ns>(-e)), N);
    ASSERT_TRUE(plus.report.ok() && minus.report.ok());
    const Vec<double, ns> fd =
        (state_difference(plus.trajectory.state(N - D::k + 1), final_state) -
         state_difference(minus.trajectory.state(N - D::k + 1), final_state)) /
        (2 * eps);
    const double scale = std::max(1.0, fd.template lpNorm<Eigen::Infinity>());
    EXPECT_LT((res.sensitivity.col(j) - fd).template lpNorm<Eigen::Infinity>(), tol * scale) << "column " << j;
  }
}
}  // namespace

TEST(Sensitivity, ElectronFlowMatchesFiniteDifferences) {
  const Electron e{1.1, 0.8, Eigen::Vector3d(0.2, 0, 1.0), 1.0};
  const double h = 0.05;
  FlowState<Electron> s;
  for (int i = 0; i < 4; ++i) s.p[i] = Eigen::Vector3d(1 + 0.01 * i, 0.05 * i, -0.02 * i * i);
  check_flow_sensitivity(e, h, s, 40, 1e-6);
}

TEST(Sensitivity, BeanieControlFlowMatchesFiniteDifferences) {
  for (auto variant : {problems::BeanieConstraints::ExactRotation, problems::BeanieConstraints::Paper}) {
    BeanieControl b;
    b.par = {1.0, 1.0, 0.5, 1.0};
    b.variant = variant;
    const double h = 0.05;
    const auto init = test_support::beanie_control_initial(b, {0.5, 0.53, 0.57, 0.62}, Eigen::Vector3d(0.8, -0.3, 0.6),
                                                      Eigen::Vector3d(0.3, -0.2, 0.1),
                                                      Eigen::Vector3d(0.31, -0.19, 0.12), h);
    check_flow_sensitivity(b, h, init, 40, 1e-6);
  }
}

TEST(Sensitivity, FreeBeanieFlowMatchesFiniteDifferences) {
  const problems::BeanieParameters par{1.0, 1.0, 0.5, 1.0};
  const problems::BeanieFree b{par};
  const double h = 0.05;
  check_flow_sensitivity(b, h, test_support::beanie_free_initial(par, Eigen::Vector4d(0, 0, 0.1, 0.8),
                                                            Eigen::Vector4d(1, 0.5, 0.3, -0.2), h),
                         100, 1e-6);
}

TEST(Sensitivity, SeedColumnsAreDirectionalDerivatives) {
  // A seed of q columns gives the sensitivity along those directions: equal to the full
  // Jacobian times the seed.
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 0.0};
  const double h = 0.05;
  const auto init = test_support::beanie_control_initial(b, {0.5, 0.53, 0.57, 0.62}, Eigen::Vector3d(0.8, -0.3, 0.6),
                                                    Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(0.31, -0.19, 0.12),
                                                    h);
  constexpr int ns = Dims<BeanieControl>::state;
  const DiscreteFlow<BeanieControl> flow(b, h);
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(ns, ns);
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd seed(ns, 3);
  for (int i = 0; i < seed.size(); ++i) seed.data()[i] = n01(rng);
  const auto full = flow.run(init, 30, &I);
  const auto part = flow.run(init, 30, &seed);
  EXPECT_LT((full.sensitivity * seed - part.sensitivity).norm(), 1e-12 * part.sensitivity.norm());
}
