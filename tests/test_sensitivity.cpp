// Exact sensitivities of the flow map (implicit function theorem) against finite differences.
// The k = 2 flows amplify perturbations polynomially (d psi_N / d psi_0 ~ N^3), so their third
// derivatives are large and a plain central difference (error eps^2 |f'''|/6) is not accurate
// enough: we use Richardson-extrapolated central differences, (4 D(eps/2) - D(eps))/3, whose error
// is O(eps^4 |f^(5)|) + O(u |f| / eps) with u = 2.2e-16. With eps = 1e-5 both stay below 1e-9 of
// the column's scale for these flows; we assert 1e-7.
#include "curved_model.hpp"
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
  auto central = [&](int j, double step) {
    Vec<double, ns> e = Vec<double, ns>::Zero();
    e(j) = step;
    const auto plus = flow.run(retract(init, e), N);
    const auto minus = flow.run(retract(init, Vec<double, ns>(-e)), N);
    EXPECT_TRUE(plus.report.ok() && minus.report.ok());
    return Vec<double, ns>((state_difference(plus.trajectory.state(N - D::k + 1), final_state) -
                            state_difference(minus.trajectory.state(N - D::k + 1), final_state)) /
                           (2 * step));
  };
  for (int j = 0; j < ns; ++j) {
    const Vec<double, ns> fd = (4 * central(j, eps / 2) - central(j, eps)) / 3;
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
  check_flow_sensitivity(e, h, s, 40, 1e-7);
}

TEST(Sensitivity, BeanieControlFlowMatchesFiniteDifferences) {
  for (auto variant : {problems::BeanieConstraints::ExactRotation, problems::BeanieConstraints::Paper}) {
    BeanieControl b;
    b.par = {1.0, 1.0, 0.5, 1.0};
    b.variant = variant;
    const double h = 0.05;
    const auto init = test_support::beanie_control_initial(b, Eigen::Vector3d(0.5, 0.8, -0.5), Eigen::Vector3d(0.8, -0.3, 0.6),
                                                      Eigen::Vector3d(0.3, -0.2, 0.1),
                                                      Eigen::Vector3d(0.302, -0.199, 0.101), h);
    check_flow_sensitivity(b, h, init, 40, 1e-7);
  }
}

TEST(Sensitivity, FreeBeanieFlowMatchesFiniteDifferences) {
  const problems::BeanieParameters par{1.0, 1.0, 0.5, 1.0};
  const problems::BeanieFree b{par};
  const double h = 0.05;
  check_flow_sensitivity(b, h, test_support::beanie_free_initial(par, Eigen::Vector4d(0, 0, 0.1, 0.8),
                                                            Eigen::Vector4d(1, 0.5, 0.3, -0.2), h),
                         100, 1e-7);
}

TEST(Sensitivity, SeedColumnsAreDirectionalDerivatives) {
  // A seed of q columns gives the sensitivity along those directions: equal to the full
  // Jacobian times the seed.
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 0.0};
  const double h = 0.05;
  const auto init = test_support::beanie_control_initial(b, Eigen::Vector3d(0.5, 0.8, -0.5), Eigen::Vector3d(0.8, -0.3, 0.6),
                                                    Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(0.302, -0.199, 0.101),
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

namespace {
// The step's derivatives in (z, state), window by window (step_sensitivity's path) against one
// pass of nested duals in all nz + state directions (evaluate_step with the state seeded).
// The derivatives hold at any point, solved or not: `res` is a flow's, or nodes made up.
template <class P>
void check_step_derivatives_at(const P& problem, double h, const FlowResult<P>& res) {
  using D = Dims<P>;
  constexpr int nz = D::unknowns, ns = D::state;
  const int n = 2 * D::k;
  const FlowState<P> s = res.trajectory.state(n);
  StepUnknowns<P> z;
  z.p = res.trajectory.p[n + D::k];
  z.g = res.trajectory.g[n + D::k - 1];
  if constexpr (D::m > 0) z.lam = res.trajectory.lam[n];
  if (res.trajectory.has_low_parts()) z.p_low = res.trajectory.p_low[n + D::k];
  Vec<double, nz> F1, F2;
  Eigen::Matrix<double, nz, nz + ns> J1, J2;
  evaluate_step<P, nz + ns>(problem, h, s, z, true, nullptr, F1, J1);
  evaluate_step_by_window(problem, h, s, z, F2, J2);
  EXPECT_LT((F1 - F2).template lpNorm<Eigen::Infinity>(), 1e-13 * std::max(1.0, F1.template lpNorm<Eigen::Infinity>()));
  EXPECT_LT((J1 - J2).template lpNorm<Eigen::Infinity>(), 1e-13 * J1.template lpNorm<Eigen::Infinity>());
  // The same matrix from the windows' Hessians (step_window_hessian.hpp): no carry, then a carry
  // filled by steps n-k .. n-1 of the same flow (their windows reused, so the same bits).
  if constexpr (uses_window_hessians<P>()) {
    Eigen::Matrix<double, nz, nz + ns> J3, J4;
    WindowHessianCarry<P> fresh, carried;
    step_jacobian_from_windows(problem, h, s, z, fresh, n, J3);
    EXPECT_LT((J1 - J3).template lpNorm<Eigen::Infinity>(), 1e-13 * J1.template lpNorm<Eigen::Infinity>());
    for (int i = n - D::k; i <= n; ++i) {
      StepUnknowns<P> zi;
      zi.p = res.trajectory.p[i + D::k];
      zi.g = res.trajectory.g[i + D::k - 1];
      if constexpr (D::m > 0) zi.lam = res.trajectory.lam[i];
      if (res.trajectory.has_low_parts()) zi.p_low = res.trajectory.p_low[i + D::k];
      step_jacobian_from_windows(problem, h, res.trajectory.state(i), zi, carried, i, J4);
    }
    for (int j = 0; j < D::k; ++j) EXPECT_EQ(carried.of(n - D::k + j).index, n - D::k + j);
    EXPECT_EQ((J3 - J4).template lpNorm<Eigen::Infinity>(), 0.0);
    // E_n itself from the windows' gradients (solve_step's fixed part, here every window).
    const NodeBlock<P, double> b = step_block<P, double>(s, z, false);
    const Vec<double, D::node> E = node_gradient_from_windows<P>(
        [&](int j) -> const auto& { return carried.of(n - D::k + j).gradient; }, 0, D::k,
        step_increment_perturbation(problem, b, carried, n, false), step_increment_perturbation(problem, b, carried, n, true));
    const double scale = std::max(1.0, F1.template lpNorm<Eigen::Infinity>());
    EXPECT_LT((E - F1.template head<D::node>()).template lpNorm<Eigen::Infinity>(), 1e-13 * scale);
    // Window a_n's gradient alone, in first-order duals (Newton's residual with a group), is the
    // gradient of its Hessian pass.
    const auto& an = carried.of(n).gradient;
    EXPECT_LT((window_gradient(problem, b.window(D::k), b.lam[D::k], h) - an).template lpNorm<Eigen::Infinity>(),
              1e-14 * std::max(1.0, an.template lpNorm<Eigen::Infinity>()));
    // Newton's F and ∂F/∂z alone (solve_step), from window a_n's Hessian against nested duals.
    const Vec<double, D::node> fixed = step_fixed_part(problem, h, s, z);
    Vec<double, nz> F5, F6;
    Eigen::Matrix<double, nz, nz> J5, J6;
    evaluate_step<P, nz>(problem, h, s, z, false, &fixed, F5, J5);
    step_matrix_from_window(problem, h, s, z, fixed, F6, J6);
    EXPECT_LT((F5 - F6).template lpNorm<Eigen::Infinity>(), 1e-13 * scale);
    EXPECT_LT((J5 - J6).template lpNorm<Eigen::Infinity>(), 1e-13 * J5.template lpNorm<Eigen::Infinity>());
  }
}

template <class P>
void check_step_derivatives_by_window(const P& problem, double h, const FlowState<P>& init) {
  const auto res = DiscreteFlow<P>(problem, h).run(init, 3 * P::order);
  ASSERT_TRUE(res.report.ok()) << res.report.message;
  check_step_derivatives_at(problem, h, res);
}
}  // namespace

TEST(Sensitivity, StepDerivativesWindowByWindowMatchOnePass) {
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 1.0};
  const double h = 0.05;
  check_step_derivatives_by_window(
      b, h,
      test_support::beanie_control_initial(b, Eigen::Vector3d(0.5, 0.8, -0.5), Eigen::Vector3d(0.8, -0.3, 0.6),
                                           Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(0.302, -0.199, 0.101), h));
  const problems::BeanieFree free{b.par};
  check_step_derivatives_by_window(free, h,
                                   test_support::beanie_free_initial(b.par, Eigen::Vector4d(0, 0, 0.1, 0.8),
                                                                     Eigen::Vector4d(1, 0.5, 0.3, -0.2), h));
  const Electron e{1.1, 0.8, Eigen::Vector3d(0.2, 0, 1.0), 1.0};
  FlowState<Electron> s;
  for (int i = 0; i < 4; ++i) s.p[i] = Eigen::Vector3d(1 + 0.01 * i, 0.05 * i, -0.02 * i * i);
  check_step_derivatives_by_window(e, h, s);
  // The paper's windows derived from the continuous beanie: a connection form, low node parts.
  using Derived = PaperWindows<problems::BeanieModel>;
  const Derived derived{problems::BeanieModel{b.par}};
  const auto control = test_support::beanie_control_initial(b, Eigen::Vector3d(0.5, 0.8, -0.5), Eigen::Vector3d(0.8, -0.3, 0.6),
                                                            Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(0.302, -0.199, 0.101), h);
  FlowState<Derived> ds;
  ds.p = control.p, ds.g = control.g, ds.lam = control.lam;
  check_step_derivatives_by_window(derived, h, ds);
  // A product group, a shape-dependent connection, a constraint: every derivative of the
  // increments' perturbation and every element scalar is non-zero.
  // (Made-up nodes: the derivatives hold at any point.)
  using Curved = PaperWindows<test_support::CurvedModel>;
  FlowResult<Curved> made_up;
  Trajectory<Curved>& tr = made_up.trajectory;
  tr.h = h;
  for (int i = 0; i <= 6; ++i) {
    tr.p.push_back(Vec<double, 2>(0.4 + 0.3 * i * h, -0.7 + 0.2 * i * h - 0.1 * i * i * h * h));
    tr.p_low.push_back(Vec<double, 2>(1e-17 * i, -2e-17 * i));
  }
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d se2(h * (0.8 + 0.1 * i * h), h * (-0.5 + 0.05 * i * h), h * (0.6 - 0.2 * i * h));
    tr.g.push_back({SE2::exp<double>(se2), SO2::Element<double>{h * (0.9 + 0.3 * i * h)}});
  }
  for (int i = 0; i <= 4; ++i) tr.lam.push_back(Vec<double, 1>(0.2 + 0.01 * i));
  check_step_derivatives_at(Curved{}, h, made_up);
}
