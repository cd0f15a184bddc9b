// The engine's derived Galerkin beanie steps on SE(2), orders 4 and 6 (group curve g_n exp(ξ),
// constraints at the Gauss points; Hess arithmetic and the chain rule through the jet) against
// the same steps derived by hand (oracles/galerkin_beanie.hpp): one interval's L~ derivatives,
// one step with its sensitivity, and a 100-step flow with the sensitivity of its last interval
// to its first. The hand derivatives are first checked against finite differences of the hand
// L~ itself.
#include "beanie_galerkin_start.hpp"
#include "oracles/galerkin_beanie.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace lpshoot;
using problems::BeanieModel;
using oracles::GalerkinBeanieInterval;
using oracles::GalerkinBeanieLayout;

namespace {

template <int S>
using Sch = problems::BeanieGalerkin<S>;

static_assert(Sch<3>::state == GalerkinBeanieLayout<3>::n && Sch<3>::unknowns == GalerkinBeanieLayout<3>::unknowns);
static_assert(Sch<4>::state == GalerkinBeanieLayout<4>::n && Sch<4>::unknowns == GalerkinBeanieLayout<4>::unknowns);

template <int S>
GalerkinBeanieInterval<S> oracle_of(const Interval<Sch<S>, double>& iv) {
  GalerkinBeanieInterval<S> o;
  o.y << iv.x, iv.v, iv.Om, iv.X2, iv.V1, iv.O1;
  o.W_angle = iv.W.angle, o.W_t = iv.W.t;
  o.aux = iv.w;
  return o;
}

template <int S>
Interval<Sch<S>, double> engine_of(const GalerkinBeanieInterval<S>& o) {
  Interval<Sch<S>, double> iv;
  iv.x(0) = o.y(0), iv.v(0) = o.y(1), iv.Om = o.y.template segment<3>(2);
  iv.X2(0) = o.y(5), iv.V1(0) = o.y(6), iv.O1 = o.y.template segment<3>(7);
  iv.W = {o.W_angle, o.W_t};
  iv.w = o.aux;
  return iv;
}

BeanieModel beanie(double amplitude) {
  BeanieModel b;
  b.par.m = 1.0, b.par.I1 = 1.3, b.par.I2 = 0.7, b.par.amplitude = amplitude;
  return b;
}

// An interval with every coordinate non-zero and a curved group increment (angle 0.9 h or, with
// `large`, 1.4: the closed forms' branch of the oracle's exp integrals).
template <int S>
GalerkinBeanieInterval<S> generic_interval(double h, bool large = false) {
  GalerkinBeanieInterval<S> o;
  o.y << 0.4, 0.7, 0.5, 0.2, 0.6, 0.3, -0.2, 0.1, -0.3, 0.2;
  const SE2::Element<double> W = SE2::exp<double>(Eigen::Vector3d(0.5 * h, 0.2 * h, large ? 1.4 : 0.9 * h));
  o.W_angle = W.angle, o.W_t = W.t;
  for (int i = 0; i < GalerkinBeanieLayout<S>::aux; ++i) o.aux(i) = 0.3 * std::sin(1.0 + i);
  return o;
}

double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }
double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return max_abs(a - b) / std::max(max_abs(b), 1e-300);
}

// The interval moved by ε along coordinate j (δ: W -> W exp(h ε e_δ)).
template <int S>
GalerkinBeanieInterval<S> moved(const GalerkinBeanieInterval<S>& o, int j, double eps, double h) {
  GalerkinBeanieInterval<S> m = o;
  if (j < 10) {
    m.y(j) += eps;
  } else if (j < 13) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d(j - 10) = h * eps;
    const SE2::Element<double> W = SE2::compose(SE2::Element<double>{o.W_angle, o.W_t}, SE2::exp<double>(d));
    m.W_angle = W.angle, m.W_t = W.t;
  } else {
    m.aux(j - 13) += eps;
  }
  return m;
}

// The hand gradient against central differences of the hand L~, the hand Hessian against central
// differences of the hand gradient (columns y and aux, and the mixed δ rows) and against second
// differences of L~ (δ–δ: the gradient at a moved W is in moved coordinates).
template <int S>
void check_against_finite_differences() {
  constexpr int n = GalerkinBeanieLayout<S>::n;
  const double h = 0.05;
  for (bool large : {false, true}) {
    const auto par = beanie(0.8).par;
    const GalerkinBeanieInterval<S> iv = generic_interval<S>(h, large);
    const auto d = oracles::galerkin_beanie_derivatives<S>(par, h, iv);
    EXPECT_LT(relative_difference(oracles::galerkin_beanie_gradient<S>(par, h, iv), d.gradient), 1e-15);
    const double eps = 1e-5;
    oracles::GalerkinBeanieVector<S> fd;
    for (int j = 0; j < n; ++j) {
      if (j >= 10 && j < 13) {
        Eigen::Vector3d e = Eigen::Vector3d::Zero();
        e(j - 10) = eps;
        fd(j) = (oracles::galerkin_beanie_action<S>(par, h, iv, e) - oracles::galerkin_beanie_action<S>(par, h, iv, -e)) /
                (2 * eps);
      } else {
        fd(j) = (oracles::galerkin_beanie_action<S>(par, h, moved<S>(iv, j, eps, h)) -
                 oracles::galerkin_beanie_action<S>(par, h, moved<S>(iv, j, -eps, h))) /
                (2 * eps);
      }
    }
    EXPECT_LT(relative_difference(fd, d.gradient), 1e-9) << "S " << S << " large angle " << large;

    oracles::GalerkinBeanieMatrix<S> Hfd;
    for (int j = 0; j < n; ++j)
      Hfd.col(j) = (oracles::galerkin_beanie_gradient<S>(par, h, moved<S>(iv, j, eps, h)) -
                    oracles::galerkin_beanie_gradient<S>(par, h, moved<S>(iv, j, -eps, h))) /
                   (2 * eps);
    const double e2 = 1e-4;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        auto L = [&](double sa, double sb) {
          Eigen::Vector3d e = Eigen::Vector3d::Zero();
          e(a) += sa * e2, e(b) += sb * e2;
          return oracles::galerkin_beanie_action<S>(par, h, iv, e);
        };
        Hfd(10 + a, 10 + b) = (L(1, 1) - L(1, -1) - L(-1, 1) + L(-1, -1)) / (4 * e2 * e2);
      }
    // Rows δ of the moved-W columns are in moved coordinates: compare them from the symmetric side.
    for (int j = 0; j < n; ++j)
      if (j < 10 || j >= 13) Hfd.template block<3, 1>(10, j) = Hfd.template block<1, 3>(j, 10).transpose();
    EXPECT_LT(relative_difference(Hfd, d.hessian), 1e-6) << "S " << S << " large angle " << large;
    EXPECT_LT(relative_difference(d.hessian.transpose(), d.hessian), 1e-15);
  }
}

// One interval's L~ gradient and Hessian: the engine's (chained; for order 4 also direct, the
// engine's own reference) against the hand's.
template <int S>
void check_interval_derivatives() {
  for (double h : {0.05, 0.002})
    for (double amplitude : {0.0, 0.8}) {
      const BeanieModel model = beanie(amplitude);
      const GalerkinBeanieInterval<S> o = generic_interval<S>(h);
      const auto hand = oracles::galerkin_beanie_derivatives<S>(model.par, h, o);
      const auto chained = group_interval_derivatives<Sch<S>>(model, engine_of<S>(o), h);
      EXPECT_LT(relative_difference(chained.gradient, hand.gradient), 1e-13) << "S " << S << " h " << h << " a " << amplitude;
      EXPECT_LT(relative_difference(chained.hessian, hand.hessian), 1e-13) << "S " << S << " h " << h << " a " << amplitude;
      if constexpr (S == 3) {
        const auto direct = group_interval_derivatives_direct<Sch<S>>(model, engine_of<S>(o), h);
        EXPECT_LT(relative_difference(direct.gradient, hand.gradient), 1e-13) << "h " << h << " a " << amplitude;
        EXPECT_LT(relative_difference(direct.hessian, hand.hessian), 1e-13) << "h " << h << " a " << amplitude;
      }
    }
}

template <int S>
Eigen::Matrix<double, GalerkinBeanieLayout<S>::unknowns, 1> unknowns_of(const Interval<Sch<S>, double>& z) {
  Eigen::Matrix<double, GalerkinBeanieLayout<S>::unknowns, 1> u;
  u << z.X2, z.V1, z.O1, SE2::log(z.W), z.w;
  return u;
}

// One step and its sensitivity dz/d(state), engine against hand, at two step sizes.
template <int S>
void check_step() {
  const BeanieModel model = beanie(0.8);
  for (int N : {50, 1000}) {
    const double h = 2.0 / N;
    const Interval<Sch<S>, double> state = test_support::beanie_interval_with_multipliers<S>(model, 2.0, N);
    Interval<Sch<S>, double> z;
    const StepReport r = solve_galerkin_step<Sch<S>>(model, h, state, 1, NewtonOptions{}, z);
    ASSERT_EQ(r.status, StepStatus::Converged) << r.message;
    const auto dz = galerkin_step_sensitivity<Sch<S>>(model, h, state, z);

    oracles::GalerkinBeanieSensitivity<S> hand_dz;
    const auto hand = oracles::galerkin_beanie_step<S>(model.par, h, oracle_of<S>(state), &hand_dz);
    ASSERT_TRUE(hand.converged);
    // Newton's tolerance is 1e-12 (1 + |z|) on each correction.
    EXPECT_LT(max_abs(unknowns_of<S>(engine_of<S>(hand.next)) - unknowns_of<S>(z)), 1e-12) << "S " << S << " N " << N;
    EXPECT_LT(relative_difference(dz, hand_dz), 1e-11) << "S " << S << " N " << N;
  }
}

// 100 steps with the full state seeded: the engine's flow (extrapolated predictors, chord
// iterations, carried interval derivatives) against the hand flow taking its steps the same way
// and chaining the hand sensitivities.
template <int S>
void check_flow() {
  const BeanieModel model = beanie(0.8);
  constexpr int N = 200, steps = 100;
  const double h = 2.0 / N;
  const Interval<Sch<S>, double> start = test_support::beanie_interval_with_multipliers<S>(model, 2.0, N);
  const GalerkinFlow<Sch<S>> flow(model, h);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Sch<S>::state, Sch<S>::state);
  const auto run = flow.run(start, steps, &seed);
  ASSERT_TRUE(run.report.ok()) << run.report.message;

  const auto hand = oracles::galerkin_beanie_flow<S>(model.par, h, oracle_of<S>(start), steps);
  ASSERT_TRUE(hand.converged) << "hand flow stopped at step " << hand.steps + 1;
  const GalerkinBeanieInterval<S>& s = hand.last;
  const Interval<Sch<S>, double>& last = run.trajectory.intervals.back();
  EXPECT_LT(max_abs(unknowns_of<S>(engine_of<S>(s)) - unknowns_of<S>(last)), 1e-11) << "S " << S;
  EXPECT_LT(std::abs(s.y(0) - last.x(0)) + std::abs(s.y(1) - last.v(0)) + (s.y.template segment<3>(2) - last.Om).norm(),
            1e-11) << "S " << S;
  EXPECT_LT(relative_difference(run.sensitivity.topRows(Sch<S>::state), hand.sensitivity), 1e-10) << "S " << S;
}

}  // namespace

TEST(GalerkinBeanieOracle, DerivativesMatchFiniteDifferencesOfTheHandAction) {
  check_against_finite_differences<3>();
  check_against_finite_differences<4>();
}

TEST(GalerkinBeanieOracle, EngineIntervalDerivativesMatchTheHandOnes) {
  check_interval_derivatives<3>();
  check_interval_derivatives<4>();
}

TEST(GalerkinBeanieOracle, EngineStepAndSensitivityMatchTheHandOnes) {
  check_step<3>();
  check_step<4>();
}

TEST(GalerkinBeanieOracle, FlowAndItsSensitivityMatchTheHandFlow) {
  check_flow<3>();
  check_flow<4>();
}
