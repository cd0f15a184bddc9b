// Galerkin steps without a group by the chain rule through the jet (core/galerkin_flat.hpp):
// the same step equations and derivatives as the nested-dual evaluation, and flows whose
// sensitivities (with interval derivatives carried from step to step) match central differences.
#include <lpshoot/problems/electron_bvp.hpp>

#include <gtest/gtest.h>

#include <random>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {

// A planar particle at unit speed: ℓ = ½ |p''|² + ½ k p₁², χ = ½ (|p'|² - 1) (one multiplier per
// Gauss point), and a coupling term so that ℓ has mixed second derivatives in every jet slot.
struct UnitSpeed {
  using Group = Trivial;
  static constexpr int shape_dim = 2;
  static constexpr int num_constraints = 1;
  double k = 1.0, coupling = 0.1;
  template <class T>
  T lagrangian(const Jet<UnitSpeed, T>& q) const {
    return 0.5 * q.ddp.squaredNorm() + (0.5 * k) * q.p(0) * q.p(0) + coupling * sin(q.p(1)) * q.ddp(0) * q.dp(1);
  }
  template <class T>
  Vec<T, 1> constraints(const Jet<UnitSpeed, T>& q) const {
    Vec<T, 1> c;
    c(0) = 0.5 * (q.dp.squaredNorm() - 1.0);
    return c;
  }
};

template <class Sch>
Interval<Sch, double> random_interval(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Interval<Sch, double> iv;
  for (int a = 0; a < Sch::r; ++a) iv.x(a) = u(rng), iv.v(a) = u(rng), iv.X2(a) = u(rng), iv.V1(a) = u(rng);
  for (int a = 0; a < Sch::aux; ++a) iv.w(a) = u(rng);
  return iv;
}

// Both evaluations of one step, with and without the state's columns, at random intervals
// (bubbles and multipliers non-zero): F and J agree to roundoff.
template <class Sch>
void expect_same_step(const typename Sch::Model& model, double h) {
  constexpr int nz = Sch::unknowns, ns = Sch::state;
  std::mt19937 rng(7);
  double worst = 0;
  for (int trial = 0; trial < 5; ++trial) {
    const auto state = random_interval<Sch>(rng), z = random_interval<Sch>(rng);
    Vec<double, nz> F1, F2;
    Eigen::Matrix<double, nz, nz + ns> J1, J2;
    evaluate_galerkin_step_nested<Sch, nz + ns>(model, h, state, z, true, nullptr, F1, J1);
    evaluate_galerkin_step_flat<Sch, nz + ns>(model, h, state, z, true, nullptr, F2, J2);
    worst = std::max(worst, (F1 - F2).cwiseAbs().maxCoeff() / F1.cwiseAbs().maxCoeff());
    worst = std::max(worst, (J1 - J2).cwiseAbs().maxCoeff() / J1.cwiseAbs().maxCoeff());
    const Vec<double, Sch::variation> fixed = node_residual<Sch, double>(model, &state, nullptr, h);
    Eigen::Matrix<double, nz, nz> K1, K2;
    evaluate_galerkin_step_nested<Sch, nz>(model, h, state, z, false, &fixed, F1, K1);
    evaluate_galerkin_step_flat<Sch, nz>(model, h, state, z, false, &fixed, F2, K2);
    worst = std::max(worst, (F1 - F2).cwiseAbs().maxCoeff() / F1.cwiseAbs().maxCoeff());
    worst = std::max(worst, (K1 - K2).cwiseAbs().maxCoeff() / K1.cwiseAbs().maxCoeff());
  }
  std::printf("degree %d, %d Gauss points, h = %g: chain rule vs nested duals, max relative difference %.2e\n",
              Sch::degree, Sch::gauss, h, worst);
  EXPECT_LT(worst, 1e-12);
}

// The flow's end interval against central differences in every state direction.
template <class Sch>
void expect_flow_sensitivity(const typename Sch::Model& model, const Interval<Sch, double>& start, double h, int steps,
                             double eps = 1e-4) {
  constexpr int ns = Sch::state;
  NewtonOptions tight;
  tight.step_tolerance = 1e-13;
  const GalerkinFlow<Sch> flow(model, h, tight);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(ns, ns);
  const auto base = flow.run(start, steps, &seed);
  ASSERT_TRUE(base.report.ok()) << base.report.message;
  // Fourth-order central differences (truncation ~ eps⁴; noise ~ 1e-13 x amplification / eps):
  // the constrained flows grow fast (|sensitivity| ~ 1e5 after 8 steps), and a second-order
  // stencil's eps² term would dominate.
  double worst = 0;
  for (int j = 0; j < ns; ++j) {
    auto end_after = [&](double s) {
      Vec<double, ns> delta = Vec<double, ns>::Zero();
      delta(j) = s;
      const auto r = flow.run(retract<Sch>(start, delta, h), steps, nullptr);
      EXPECT_TRUE(r.report.ok()) << r.report.message;
      return Vec<double, ns>(state_difference(r.trajectory.intervals.back(), base.trajectory.intervals.back(), h));
    };
    const Vec<double, ns> fd =
        (8.0 * (end_after(eps) - end_after(-eps)) - (end_after(2 * eps) - end_after(-2 * eps))) / (12 * eps);
    worst = std::max(worst, (base.sensitivity.col(j) - fd).template lpNorm<Eigen::Infinity>() /
                                std::max(1.0, fd.template lpNorm<Eigen::Infinity>()));
  }
  std::printf("degree %d, %d steps: max relative sensitivity error %.2e\n", Sch::degree, steps, worst);
  EXPECT_LT(worst, 1e-6);
}

ElectronModel nonlinear_electron() {
  ElectronModel e;
  e.potential = 0.5, e.quartic = 0.125;  // METHOD.md §9's nonlinear electron-type problem
  return e;
}

template <int S>
Interval<Galerkin<UnitSpeed, S>, double> unit_speed_start() {
  Interval<Galerkin<UnitSpeed, S>, double> iv;
  iv.x << 0.3, -0.2;
  iv.v << std::cos(0.4), std::sin(0.4);
  iv.X2 << -0.1, 0.2;
  iv.V1 << -0.3, 0.4;
  for (int a = 0; a < Galerkin<UnitSpeed, S>::aux; ++a) iv.w(a) = 0.05 * std::sin(2.0 + a);
  return iv;
}

}  // namespace

TEST(GalerkinFlat, ChainRuleEqualsNestedDualsOnTheElectron) {
  expect_same_step<Galerkin<ElectronModel, 3>>(nonlinear_electron(), 0.01);
  expect_same_step<Galerkin<ElectronModel, 4>>(nonlinear_electron(), 0.05);
  expect_same_step<Galerkin<ElectronModel, 5>>(nonlinear_electron(), 0.2);
}

TEST(GalerkinFlat, ChainRuleEqualsNestedDualsWithConstraintsAndBubbles) {
  expect_same_step<Galerkin<UnitSpeed, 3>>(UnitSpeed{}, 0.01);
  expect_same_step<Galerkin<UnitSpeed, 4>>(UnitSpeed{}, 0.1);
}

TEST(GalerkinFlat, ElectronFlowSensitivityMatchesFiniteDifferences) {
  const ElectronModel e = nonlinear_electron();
  Interval<Galerkin<ElectronModel, 3>, double> c;
  c.x << 1.0, 0.0, 0.5, c.v << 0.0, 1.0, 0.0, c.X2 << -0.2, 0.1, 0.05, c.V1 << -0.4, 0.3, 0.1;
  expect_flow_sensitivity<Galerkin<ElectronModel, 3>>(e, c, 0.05, 30);
  Interval<Galerkin<ElectronModel, 4>, double> q;
  q.x = c.x, q.v = c.v, q.X2 = c.X2, q.V1 = c.V1, q.w << 0.01, -0.02, 0.03;
  expect_flow_sensitivity<Galerkin<ElectronModel, 4>>(e, q, 0.05, 30);
}

TEST(GalerkinFlat, ConstrainedFlowSensitivityMatchesFiniteDifferences) {
  expect_flow_sensitivity<Galerkin<UnitSpeed, 3>>(UnitSpeed{}, unit_speed_start<3>(), 0.05, 6, 3e-4);
  expect_flow_sensitivity<Galerkin<UnitSpeed, 4>>(UnitSpeed{}, unit_speed_start<4>(), 0.05, 6, 3e-4);
}
