// Galerkin steps with a group from each interval's gradient and Hessian (core/galerkin_group.hpp):
// the second-order scalar Hess against nested duals, and the step's equations and derivatives
// (with the group's bracket terms) against the nested-dual evaluation at generic points, and the
// end nodes' rows from the action (core/galerkin_end_rows.hpp) likewise; the connection
// velocity's jet (core/galerkin.hpp) against finite differences and its generic route.
#include <lpshoot/core/galerkin_end_rows.hpp>
#include <lpshoot/core/hessian_scalar.hpp>
#include <lpshoot/problems/electron_bvp.hpp>

#include "beanie_galerkin_start.hpp"

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

// An interval with every coordinate generic: W away from the identity, non-zero increments,
// bubbles and multipliers.
template <class Sch>
Interval<Sch, double> generic_interval(const BeanieModel& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Interval<Sch, double> iv = test_support::beanie_interval_with_multipliers<Sch::degree>(model, 2.0, 40);
  for (int a = 0; a < Sch::r; ++a) iv.x(a) += u(rng), iv.v(a) += u(rng), iv.X2(a) = u(rng), iv.V1(a) = u(rng);
  for (int a = 0; a < Sch::d; ++a) iv.Om(a) += u(rng), iv.O1(a) = u(rng);
  iv.W = SE2::exp<double>(Eigen::Vector3d(u(rng), u(rng), u(rng)));
  for (int a = 0; a < Sch::aux; ++a) iv.w(a) = 0.5 * u(rng);
  return iv;
}

// F and J with the state's columns from interval Hessians (with and without a carried state)
// against nested duals: equal to roundoff. A sign error in a bracket term or in A_r's group block
// shows as an O(1) relative difference.
template <int S>
void expect_same_step(double h) {
  using Sch = BeanieGalerkin<S>;
  constexpr int nz = Sch::unknowns, ns = Sch::state;
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  std::mt19937 rng(11);
  double worst = 0, bracket_part = 0;
  for (int trial = 0; trial < 5; ++trial) {
    const auto state = generic_interval<Sch>(model, rng), z = generic_interval<Sch>(model, rng);
    Vec<double, nz> F1, F2, F3;
    Eigen::Matrix<double, nz, nz + ns> J1, J2, J3;
    evaluate_galerkin_step_nested<Sch, nz + ns>(model, h, state, z, true, nullptr, F1, J1);
    evaluate_galerkin_step_group<Sch, nz + ns>(model, h, state, z, nullptr, F2, J2, nullptr);
    StepCarry<Sch> carry;
    carry.interval = group_interval_derivatives<Sch>(model, state, h);
    carry.valid = true;
    // The state's part of E_n from its gradient (group_left_rows) equals node_residual's.
    const Vec<double, Sch::variation> fixed = node_residual<Sch, double>(model, &state, nullptr, h);
    const Vec<double, Sch::variation> left_rows = group_left_rows<Sch>(carry.interval.gradient, h);
    evaluate_galerkin_step_group<Sch, nz + ns>(model, h, state, z, nullptr, F3, J3, &carry);
    const double fs = F1.cwiseAbs().maxCoeff(), js = J1.cwiseAbs().maxCoeff();
    worst = std::max({worst, (F1 - F2).cwiseAbs().maxCoeff() / fs, (J1 - J2).cwiseAbs().maxCoeff() / js,
                      (F1 - F3).cwiseAbs().maxCoeff() / fs, (J1 - J3).cwiseAbs().maxCoeff() / js});
    worst = std::max(worst, (fixed - left_rows).cwiseAbs().maxCoeff() / fs);
    // The step matrix alone (a step's Newton), given the state's part of E_n.
    Vec<double, nz> G1, G2;
    Eigen::Matrix<double, nz, nz> K1, K2;
    evaluate_galerkin_step_nested<Sch, nz>(model, h, state, z, false, &fixed, G1, K1);
    evaluate_galerkin_step_group<Sch, nz>(model, h, state, z, &fixed, G2, K2, nullptr);
    worst = std::max({worst, (G1 - G2).cwiseAbs().maxCoeff() / G1.cwiseAbs().maxCoeff(),
                      (K1 - K2).cwiseAbs().maxCoeff() / K1.cwiseAbs().maxCoeff()});
    // The residual alone (chord iterations: node, bubble and multiplier rows in one pass).
    const Vec<double, nz> R = galerkin_step_residual<Sch>(model, h, state, z, fixed);
    worst = std::max(worst, (G1 - R).cwiseAbs().maxCoeff() / G1.cwiseAbs().maxCoeff());
    // The bracket terms are really exercised: without them the η rows would differ.
    const Eigen::Matrix<double, Sch::d, Sch::d> B =
        bracket_form<SE2>(carry.interval.gradient.template segment<Sch::d>(Sch::W_off));
    bracket_part = std::max(bracket_part, 0.5 * B.cwiseAbs().maxCoeff() / js);
    // The carry now holds interval n's derivatives.
    const auto dr_expected = [&] {
      Interval<Sch, double> right = z;
      const auto b = next_interval_base(state, h);
      right.x = b.x, right.v = b.v, right.Om = b.Om;
      return group_interval_derivatives<Sch>(model, right, h);
    }();
    EXPECT_EQ(carry.interval.gradient, dr_expected.gradient);
  }
  std::printf("beanie degree %d, h = %g: interval Hessians vs nested duals, max relative difference %.2e "
              "(bracket terms %.2e of |J|)\n",
              S, h, worst, bracket_part);
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(bracket_part, 1e-6);
}

TEST(GalerkinGroupStep, CubicMatchesNestedDuals) { expect_same_step<3>(0.05); }
TEST(GalerkinGroupStep, QuarticWithBubblesMatchesNestedDuals) { expect_same_step<4>(0.05); }
TEST(GalerkinGroupStep, LargeStepMatchesNestedDuals) { expect_same_step<3>(0.5); }

}  // namespace

namespace {

// galerkin_end_rows (natural conditions and the first interval's own rows, with derivatives in
// the interval's tangent coordinates) against nested duals over the whole tangent: node_residual
// and aux_residual of the interval seeded in every coordinate, multipliers included.
template <class Sch>
double end_rows_difference(const typename Sch::Model& model, const Interval<Sch, double>& iv, double h) {
  constexpr int nz = Sch::unknowns, ns = Sch::state, nv = Sch::variation, nm = multiplier_count<Sch>;
  using TD = Dual<double, ns>;
  Interval<Sch, TD> s = seeded_state<Sch, TD>(iv, h, 0);
  for (int c = 0; c < nm; ++c) s.w(Sch::multipliers(0) + c) = TD::variable(iv.w(Sch::multipliers(0) + c), ns - nm + c);
  double worst = 0;
  for (bool initial : {true, false}) {
    Vec<double, nz> R;
    Eigen::Matrix<double, nz, ns> J;
    const int rows = galerkin_end_rows<Sch>(model, iv, h, initial, R, J);
    EXPECT_EQ(rows, initial ? nz : nv);
    Vec<TD, nz> ref;
    ref.template head<nv>() = initial ? node_residual<Sch, TD>(model, nullptr, &s, h) : node_residual<Sch, TD>(model, &s, nullptr, h);
    if (initial) ref.template tail<Sch::aux>() = aux_residual<Sch, TD>(model, s, h);
    double rs = 0, js = 0, dr = 0, dj = 0;
    for (int i = 0; i < rows; ++i) {
      rs = std::max(rs, std::abs(ref(i).v)), dr = std::max(dr, std::abs(ref(i).v - R(i)));
      for (int c = 0; c < ns; ++c) js = std::max(js, std::abs(ref(i).d[c])), dj = std::max(dj, std::abs(ref(i).d[c] - J(i, c)));
    }
    if (rows < nz) {
      EXPECT_EQ(J.bottomRows(nz - rows).cwiseAbs().maxCoeff(), 0.0);
    }
    worst = std::max({worst, dr / rs, dj / js});
  }
  return worst;
}

template <int S>
void expect_same_beanie_end_rows(double h) {
  using Sch = BeanieGalerkin<S>;
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  std::mt19937 rng(17);
  double worst = 0;
  for (int trial = 0; trial < 5; ++trial) worst = std::max(worst, end_rows_difference<Sch>(model, generic_interval<Sch>(model, rng), h));
  std::printf("beanie degree %d, h = %g: end rows from the interval's Hessian vs nested duals, max relative difference %.2e\n",
              S, h, worst);
  EXPECT_LT(worst, 1e-12);
}

}  // namespace

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
// A model with every part of the jet nonlinear: a shape-dependent connection on SE(2) × SO(2),
// a Lagrangian mixing p, p', p'', Ω and Ω', one constraint.
struct CurvedModel {
  using Group = Product<SE2, SO2>;
  static constexpr int shape_dim = 2;
  static constexpr int num_constraints = 1;
  template <class T>
  T lagrangian(const Jet<CurvedModel, T>& q) const {
    using std::cos, std::sin;
    return 0.5 * q.ddp.squaredNorm() + cos(q.p(0)) * q.Omega.squaredNorm() + q.dOmega(0) * q.dp(1) +
           0.3 * sin(q.Omega(2) * q.p(1)) + 0.2 * q.dOmega(3) * q.dOmega(1);
  }
  template <class T>
  Vec<T, 1> constraints(const Jet<CurvedModel, T>& q) const {
    using std::sin;
    return Vec<T, 1>(q.Omega(3) - q.dp(0) * sin(q.p(1)) + q.dOmega(2) * q.Omega(0));
  }
  template <class T>
  Eigen::Matrix<T, 4, 2> connection_form(const Vec<T, 2>& p) const {
    using std::cos, std::sin;
    Eigen::Matrix<T, 4, 2> A;
    A << sin(p(0)), p(1) * p(1), T(0.3), cos(p(1)) * p(0), p(0) * p(0) * p(0), T(0.5), T(0.1) * p(1), T(-0.2);
    return A;
  }
};

// The chain rule through the jet inputs against Hess<ny> through everything: gradient and
// Hessian (multiplier rows included) to roundoff. Dropping the μ term (the ends' curvature) or
// a column of J_i shows as an O(1) relative difference.
template <class Sch>
double chained_vs_direct(const typename Sch::Model& model, const Interval<Sch, double>& iv, double h) {
  const auto a = group_interval_derivatives_chained<Sch>(model, iv, h);
  const auto b = group_interval_derivatives_direct<Sch>(model, iv, h);
  return std::max((a.gradient - b.gradient).cwiseAbs().maxCoeff() / b.gradient.cwiseAbs().maxCoeff(),
                  (a.hessian - b.hessian).cwiseAbs().maxCoeff() / b.hessian.cwiseAbs().maxCoeff());
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
