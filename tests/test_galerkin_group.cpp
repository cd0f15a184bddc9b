// Galerkin steps with a group from each interval's gradient and Hessian (core/galerkin_group.hpp):
// the second-order scalar Hess against nested duals, and the step's equations and derivatives
// (with the group's bracket terms) against the nested-dual evaluation at generic points, and the
// end nodes' rows from the action (core/galerkin_end_rows.hpp) likewise; the connection
// velocity's jet (core/galerkin.hpp) against finite differences and its generic route.
#include <lpshoot/core/galerkin_end_rows.hpp>
#include <lpshoot/core/hessian_scalar.hpp>
#include <lpshoot/problems/electron_bvp.hpp>

#include "beanie_galerkin_start.hpp"
#include "curved_model.hpp"
#include "galerkin_group_checks.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {

// Every operation Hess implements, mixed so that each second derivative is non-zero.
template <class T>
T mixed_function(const std::array<T, 4>& x) {
  using std::atan2, std::cos, std::exp, std::log, std::pow, std::sin, std::sqrt, std::tanh;
  const T a = sin(x[0]) * cos(x[1]) / (2.0 + x[2] * x[2]);
  const T b = exp(0.3 * x[3]) * log(1.5 + x[0] * x[1]) - sqrt(1.0 + x[2] * x[3] * x[3]);
  const T c = tanh(x[1] - x[3]) * pow(1.2 + x[0] * x[0], 1.5) + atan2(x[2] + 0.1, 1.0 + x[3] - x[1]);
  return a * b + c - 3.0 / (4.0 + x[1]) + abs(x[0] - 2.0);
}

TEST(HessScalar, ValueGradientAndHessianMatchNestedDuals) {
  constexpr int n = 4;
  using H = Hess<n>;
  using D2 = Dual<Dual<double, n>, n>;
  const double at[n] = {0.3, -0.7, 0.45, 1.1};
  std::array<H, n> xh;
  std::array<D2, n> xd;
  for (int i = 0; i < n; ++i) {
    xh[i] = H::variable(at[i], i);
    xd[i] = D2::variable(Dual<double, n>::variable(at[i], i), i);
  }
  const H fh = mixed_function(xh);
  const D2 fd = mixed_function(xd);
  EXPECT_NEAR(fh.v, fd.v.v, 1e-15);
  double worst = 0;
  for (int i = 0; i < n; ++i) {
    worst = std::max(worst, std::abs(fh.g[i] - fd.v.d[i]));
    for (int j = 0; j < n; ++j) {
      EXPECT_NEAR(fd.d[i].d[j], fd.d[j].d[i], 1e-13);  // the reference itself is symmetric
      worst = std::max(worst, std::abs(fh.hessian(i, j) - fd.d[i].d[j]));
    }
  }
  std::printf("Hess<4> against Dual<Dual<4>,4>: max difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-13);
  EXPECT_NE(fh.hessian(0, 3), 0.0);
}

}  // namespace

// The step and the end rows against nested duals: galerkin_group_checks.hpp (degree 5 in
// test_galerkin_order8.cpp).
using test_support::end_rows_difference;
using test_support::expect_same_beanie_end_rows;
using test_support::expect_same_step;
using test_support::generic_interval;

TEST(GalerkinGroupStep, CubicMatchesNestedDuals) { expect_same_step<3>(0.05); }
TEST(GalerkinGroupStep, QuarticWithBubblesMatchesNestedDuals) { expect_same_step<4>(0.05); }
TEST(GalerkinGroupStep, LargeStepMatchesNestedDuals) { expect_same_step<3>(0.5); }

TEST(GalerkinEndRows, BeanieCubicMatchesNestedDuals) { expect_same_beanie_end_rows<3>(0.05); }
TEST(GalerkinEndRows, BeanieQuarticWithBubblesMatchesNestedDuals) { expect_same_beanie_end_rows<4>(0.5); }
TEST(GalerkinEndRows, ElectronWithBubblesMatchesNestedDuals) {  // no group: galerkin_flat.hpp's maps
  using Sch = Galerkin<ElectronModel, 4, 3>;
  const auto model = model_of(Electron{});
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  for (int trial = 0; trial < 5; ++trial) {
    Interval<Sch, double> iv;
    for (int a = 0; a < Sch::r; ++a) iv.x(a) = u(rng), iv.v(a) = u(rng), iv.X2(a) = u(rng), iv.V1(a) = u(rng);
    for (int a = 0; a < Sch::aux; ++a) iv.w(a) = u(rng);
    worst = std::max(worst, end_rows_difference<Sch>(model, iv, 0.1));
  }
  std::printf("electron degree 4: end rows vs nested duals, max relative difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-12);
}

namespace {
// Connection forms for connection_jet (core/galerkin.hpp): one that varies with the shape, and
// one whose derivatives vanish at p = 0 to second order but not to third.
struct CurvedConnection {
  using Group = SE2;
  static constexpr int shape_dim = 2;
  template <class T>
  Eigen::Matrix<T, 3, 2> connection_form(const Vec<T, 2>& p) const {
    using std::cos, std::sin;
    Eigen::Matrix<T, 3, 2> A;
    A << sin(p(0)), p(1) * p(1), T(0.3), cos(p(1)) * p(0), p(0) * p(0) * p(0), T(0.5);
    return A;
  }
};
struct CubicConnection {
  using Group = SO2;
  static constexpr int shape_dim = 1;
  template <class T>
  Eigen::Matrix<T, 1, 1> connection_form(const Vec<T, 1>& p) const {
    return Eigen::Matrix<T, 1, 1>(p(0) * p(0) * p(0));
  }
};
using CD = Dual<Dual<double, 2>, 2>;  // two directions, second derivatives
CD cd_variable(double x, int i) { return CD::variable(Dual<double, 2>::variable(x, i), i); }

// Every component (value, gradient, Hessian) of a and b agrees to tol.
void expect_same_cd(const CD& a, const CD& b, double tol) {
  EXPECT_NEAR(a.v.v, b.v.v, tol);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(a.v.d[i], b.v.d[i], tol);
    EXPECT_NEAR(a.d[i].v, b.d[i].v, tol);
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(a.d[i].d[j], b.d[i].d[j], tol);
  }
}
}  // namespace

TEST(ConnectionJet, TimeDerivativeMatchesFiniteDifferencesAlongACurve) {
  // p(t) = p0 + p1 t + p2 t²/2 + p3 t³/6: cv(t) = 𝒜(p(t)) p'(t), dcv = cv'(0).
  const CurvedConnection model;
  const Vec<double, 2> p0(0.4, -0.8), p1(0.9, 0.3), p2(-0.5, 1.2), p3(0.7, -0.2);
  auto cv_at = [&](double t) {
    const Vec<double, 2> p = p0 + t * p1 + (0.5 * t * t) * p2 + (t * t * t / 6) * p3;
    const Vec<double, 2> dp = p1 + t * p2 + (0.5 * t * t) * p3;
    return Vec<double, 3>(model.connection_form<double>(p) * dp);
  };
  Vec<double, 3> cv, dcv;
  connection_jet(model, p0, p1, p2, cv, dcv);
  const double eps = 1e-5;
  const Vec<double, 3> fd = (cv_at(eps) - cv_at(-eps)) / (2 * eps);
  EXPECT_LT((cv - cv_at(0)).norm(), 1e-15);
  EXPECT_LT((dcv - fd).norm(), 1e-9);
  EXPECT_GT(dcv.norm(), 0.1);
}

TEST(ConnectionJet, ConstantFormsTakeTheDoublePathOnlyWhenExact) {
  // In second-order duals the cubic's time derivative 3 p² p'² + p³ p'' has a non-zero second
  // derivative at p = 0: its third derivative there is needed, so no constant shortcut. The
  // beanie's constant form takes it and must give the generic route's numbers.
  const CD x = cd_variable(0.0, 0), y = cd_variable(0.3, 1);
  {
    const CubicConnection model;
    const Vec<CD, 1> p(x), dp(CD(1.5) + y), ddp(CD(-0.4) + x * y);
    Vec<CD, 1> cv, dcv, cv_ref, dcv_ref;
    connection_jet(model, p, dp, ddp, cv, dcv);
    connection_jet_generic(model, p, dp, ddp, cv_ref, dcv_ref);
    expect_same_cd(cv(0), cv_ref(0), 1e-15);
    expect_same_cd(dcv(0), dcv_ref(0), 1e-15);
    EXPECT_NEAR(dcv(0).d[0].d[0], 6.0 * (1.5 + 0.3) * (1.5 + 0.3), 1e-12);  // 3 · 2 δ² p'²
  }
  {
    BeanieModel model;
    model.par = {1.0, 1.0, 0.5, 1.0};
    const Vec<CD, 1> p(CD(0.2) + x * y), dp(CD(0.7) + y * y), ddp(CD(-1.1) + x);
    Vec<CD, 3> cv, dcv, cv_ref, dcv_ref;
    connection_jet(model, p, dp, ddp, cv, dcv);
    connection_jet_generic(model, p, dp, ddp, cv_ref, dcv_ref);
    for (int a = 0; a < 3; ++a) {
      expect_same_cd(cv(a), cv_ref(a), 1e-15);
      expect_same_cd(dcv(a), dcv_ref(a), 1e-15);
    }
    EXPECT_NE(dcv(2).d[0].v, 0.0);
  }
}

namespace {
using test_support::CurvedModel;

// The chain rule through the jet inputs against Hess<ny> through everything: gradient and
// Hessian (multiplier rows included) to roundoff. Dropping the μ term (the ends' curvature) or
// a column of J_i shows as an O(1) relative difference. So does the gradient alone, the Newton
// residuals' chain rule (galerkin_group_gradient.hpp), with a column of the ends' Jacobian dropped.
template <class Sch>
double chained_vs_direct(const typename Sch::Model& model, const Interval<Sch, double>& iv, double h) {
  const auto a = group_interval_derivatives_chained<Sch>(model, iv, h);
  const auto b = group_interval_derivatives_direct<Sch>(model, iv, h);
  const auto g = group_interval_gradient_chained<Sch>(model, iv, h);
  const double gs = b.gradient.cwiseAbs().maxCoeff();
  return std::max({(a.gradient - b.gradient).cwiseAbs().maxCoeff() / gs, (g - b.gradient).cwiseAbs().maxCoeff() / gs,
                   (a.hessian - b.hessian).cwiseAbs().maxCoeff() / b.hessian.cwiseAbs().maxCoeff()});
}

template <int S>
double curved_chained_vs_direct(double h, std::mt19937& rng) {
  using Sch = Galerkin<CurvedModel, S>;
  std::uniform_real_distribution<double> u(-1, 1);
  Interval<Sch, double> iv;
  for (int a = 0; a < Sch::r; ++a) iv.x(a) = u(rng), iv.v(a) = u(rng), iv.X2(a) = u(rng), iv.V1(a) = u(rng);
  for (int a = 0; a < Sch::d; ++a) iv.Om(a) = u(rng), iv.O1(a) = u(rng);
  iv.W = Sch::Group::template exp<double>(Vec<double, Sch::d>(u(rng), u(rng), u(rng), u(rng)));
  for (int a = 0; a < Sch::aux; ++a) iv.w(a) = u(rng);
  return chained_vs_direct<Sch>(CurvedModel{}, iv, h);
}
}  // namespace

TEST(GalerkinGroupInterval, ChainRuleThroughTheJetInputsMatchesTheDirectHessian) {
  BeanieModel beanie;
  beanie.par = {1.0, 1.0, 0.5, 1.0};
  std::mt19937 rng(29);
  double worst = 0;
  for (double h : {0.05, 0.5}) {
    for (int trial = 0; trial < 4; ++trial) {
      worst = std::max(worst, chained_vs_direct<BeanieGalerkin<3>>(beanie, generic_interval<BeanieGalerkin<3>>(beanie, rng), h));
      worst = std::max(worst, chained_vs_direct<BeanieGalerkin<4>>(beanie, generic_interval<BeanieGalerkin<4>>(beanie, rng), h));
      worst = std::max(worst, curved_chained_vs_direct<3>(h, rng));
      worst = std::max(worst, curved_chained_vs_direct<4>(h, rng));
    }
  }
  std::printf("interval derivatives, chain rule through the jet vs Hess<ny>: max relative difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-13);
}

// A step whose chord iterations ended on a prediction is confirmed by one exact Newton
// correction at z (confirm_predicted_step, what a flow with sensitivities does): the corrected
// interval is the step's solution to O(ε²), and the carried gradient, moved to first order with
// the bracket term of re-centring δ, is the fresh gradient there to O(ε²). Without that term it
// is off by ~ (h/2) ε |∂L~/∂δ|; with the correction's sign flipped, by ε.
TEST(GalerkinGroupStep, PredictedStepIsConfirmedByOneNewtonCorrection) {
  using Sch = BeanieGalerkin<4>;
  constexpr int nz = Sch::unknowns;
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  const double h = 0.5;
  const auto state = test_support::beanie_interval_with_multipliers<4>(model, 2.0, 4);
  Interval<Sch, double> solved;
  const NewtonOptions opt;
  ASSERT_EQ(solve_galerkin_step<Sch>(model, h, state, 1, opt, solved).status, StepStatus::Converged);
  const double eps = 1e-5;
  Vec<double, nz> off;
  for (int i = 0; i < nz; ++i) off(i) = eps * std::cos(1.0 + 2 * i);
  Interval<Sch, double> z = solved;
  apply_galerkin_correction<Sch>(z, off, h);
  StepCarry<Sch> carry;
  carry.interval = group_interval_derivatives<Sch>(model, state, h);
  carry.valid = true;
  ChordMatrix<nz> chord;
  double condition = 0;
  Vec<double, nz> F;
  galerkin_step_sensitivity<Sch>(model, h, state, z, &chord, &condition, &carry, &F);
  // At the step's tolerance an ε-sized correction is refused, and nothing moves.
  Interval<Sch, double> refused = z;
  StepCarry<Sch> untouched = carry;
  EXPECT_FALSE(confirm_predicted_step<Sch>(h, opt, F, chord, refused, &untouched));
  EXPECT_EQ(untouched.interval.gradient, carry.interval.gradient);
  NewtonOptions loose;
  loose.step_tolerance = 1e-3;
  ASSERT_TRUE(confirm_predicted_step<Sch>(h, loose, F, chord, z, &carry));
  const auto fresh = group_interval_derivatives<Sch>(model, z, h);
  const double gradient_error =
      (carry.interval.gradient - fresh.gradient).cwiseAbs().maxCoeff() / fresh.gradient.cwiseAbs().maxCoeff();
  const double group_error = SE2::log(SE2::compose(SE2::inverse(solved.W), z.W)).cwiseAbs().maxCoeff();
  const double solution_error = std::max({(z.X2 - solved.X2).cwiseAbs().maxCoeff(), (z.V1 - solved.V1).cwiseAbs().maxCoeff(),
                                          (z.O1 - solved.O1).cwiseAbs().maxCoeff(), (z.w - solved.w).cwiseAbs().maxCoeff(),
                                          group_error});
  std::printf("predicted step moved by %.0e: carried gradient off by %.2e, solution off by %.2e after one correction\n",
              eps, gradient_error, solution_error);
  EXPECT_LT(gradient_error, 1e-8);
  EXPECT_LT(solution_error, 1e-8);
}
