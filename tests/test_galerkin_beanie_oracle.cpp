// The engine's derived Galerkin 4 beanie step on SE(2) (group curve g_n exp(ξ), constraints at
// the Gauss points; nested duals, Hess arithmetic and the chain rule through the jet) against
// the same step derived by hand (oracles/galerkin_beanie.hpp): one interval's L~ derivatives,
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
using Sch = problems::BeanieGalerkin<3>;
using oracles::GalerkinBeanieInterval;

namespace {

static_assert(Sch::state == 19 && Sch::unknowns == 14, "the oracle's layout");

GalerkinBeanieInterval oracle_of(const Interval<Sch, double>& iv) {
  GalerkinBeanieInterval o;
  o.y << iv.x, iv.v, iv.Om, iv.X2, iv.V1, iv.O1;
  o.W_angle = iv.W.angle, o.W_t = iv.W.t;
  o.lambda = iv.w;
  return o;
}

Interval<Sch, double> engine_of(const GalerkinBeanieInterval& o) {
  Interval<Sch, double> iv;
  iv.x(0) = o.y(0), iv.v(0) = o.y(1), iv.Om = o.y.segment<3>(2);
  iv.X2(0) = o.y(5), iv.V1(0) = o.y(6), iv.O1 = o.y.segment<3>(7);
  iv.W = {o.W_angle, o.W_t};
  iv.w = o.lambda;
  return iv;
}

BeanieModel beanie(double amplitude) {
  BeanieModel b;
  b.par.m = 1.0, b.par.I1 = 1.3, b.par.I2 = 0.7, b.par.amplitude = amplitude;
  return b;
}

// An interval with every coordinate non-zero and a curved group increment (angle 0.9 h or, with
// `large`, 1.4: the closed forms' branch of the oracle's exp integrals).
GalerkinBeanieInterval generic_interval(double h, bool large = false) {
  GalerkinBeanieInterval o;
  o.y << 0.4, 0.7, 0.5, 0.2, 0.6, 0.3, -0.2, 0.1, -0.3, 0.2;
  const SE2::Element<double> W = SE2::exp<double>(Eigen::Vector3d(0.5 * h, 0.2 * h, large ? 1.4 : 0.9 * h));
  o.W_angle = W.angle, o.W_t = W.t;
  for (int i = 0; i < 6; ++i) o.lambda(i) = std::sin(1.0 + i);
  return o;
}

double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }
double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return max_abs(a - b) / std::max(max_abs(b), 1e-300);
}

// The interval moved by ε along coordinate j (δ: W -> W exp(h ε e_δ)).
GalerkinBeanieInterval moved(const GalerkinBeanieInterval& o, int j, double eps, double h) {
  GalerkinBeanieInterval m = o;
  if (j < 10) {
    m.y(j) += eps;
  } else if (j < 13) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d(j - 10) = h * eps;
    const SE2::Element<double> W = SE2::compose(SE2::Element<double>{o.W_angle, o.W_t}, SE2::exp<double>(d));
    m.W_angle = W.angle, m.W_t = W.t;
  } else {
    m.lambda(j - 13) += eps;
  }
  return m;
}

}  // namespace

// The hand gradient against central differences of the hand L~, the hand Hessian against central
// differences of the hand gradient (columns y and λ, and the mixed δ rows) and against second
// differences of L~ (δ–δ: the gradient at a moved W is in moved coordinates).
TEST(GalerkinBeanieOracle, DerivativesMatchFiniteDifferencesOfTheHandAction) {
  const double h = 0.05;
  for (bool large : {false, true}) {
    const auto par = beanie(0.8).par;
    const GalerkinBeanieInterval iv = generic_interval(h, large);
    const auto d = oracles::galerkin4_beanie_derivatives(par, h, iv);
    EXPECT_LT(relative_difference(oracles::galerkin4_beanie_gradient(par, h, iv), d.gradient), 1e-15);
    const double eps = 1e-5;
    oracles::GalerkinBeanieVector fd;
    for (int j = 0; j < 19; ++j) {
      if (j >= 10 && j < 13) {
        Eigen::Vector3d e = Eigen::Vector3d::Zero();
        e(j - 10) = eps;
        fd(j) = (oracles::galerkin4_beanie_action(par, h, iv, e) - oracles::galerkin4_beanie_action(par, h, iv, -e)) /
                (2 * eps);
      } else {
        fd(j) = (oracles::galerkin4_beanie_action(par, h, moved(iv, j, eps, h)) -
                 oracles::galerkin4_beanie_action(par, h, moved(iv, j, -eps, h))) /
                (2 * eps);
      }
    }
    EXPECT_LT(relative_difference(fd, d.gradient), 1e-9) << "large angle " << large;

    oracles::GalerkinBeanieMatrix Hfd;
    for (int j = 0; j < 19; ++j)
      Hfd.col(j) = (oracles::galerkin4_beanie_gradient(par, h, moved(iv, j, eps, h)) -
                    oracles::galerkin4_beanie_gradient(par, h, moved(iv, j, -eps, h))) /
                   (2 * eps);
    const double e2 = 1e-4;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        auto L = [&](double sa, double sb) {
          Eigen::Vector3d e = Eigen::Vector3d::Zero();
          e(a) += sa * e2, e(b) += sb * e2;
          return oracles::galerkin4_beanie_action(par, h, iv, e);
        };
        Hfd(10 + a, 10 + b) = (L(1, 1) - L(1, -1) - L(-1, 1) + L(-1, -1)) / (4 * e2 * e2);
      }
    // Rows δ of the moved-W columns are in moved coordinates: compare them from the symmetric side.
    for (int j = 0; j < 19; ++j)
      if (j < 10 || j >= 13) Hfd.block<3, 1>(10, j) = Hfd.block<1, 3>(j, 10).transpose();
    EXPECT_LT(relative_difference(Hfd, d.hessian), 1e-6) << "large angle " << large;
    EXPECT_LT(relative_difference(d.hessian.transpose(), d.hessian), 1e-15);
  }
}

// One interval's L~ gradient and Hessian: the engine's (chained and direct) against the hand's.
TEST(GalerkinBeanieOracle, EngineIntervalDerivativesMatchTheHandOnes) {
  for (double h : {0.05, 0.002})
    for (double amplitude : {0.0, 0.8}) {
      const BeanieModel model = beanie(amplitude);
      const GalerkinBeanieInterval o = generic_interval(h);
      const auto hand = oracles::galerkin4_beanie_derivatives(model.par, h, o);
      const auto chained = group_interval_derivatives<Sch>(model, engine_of(o), h);
      const auto direct = group_interval_derivatives_direct<Sch>(model, engine_of(o), h);
      EXPECT_LT(relative_difference(chained.gradient, hand.gradient), 1e-13) << "h " << h << " a " << amplitude;
      EXPECT_LT(relative_difference(direct.gradient, hand.gradient), 1e-13) << "h " << h << " a " << amplitude;
      EXPECT_LT(relative_difference(chained.hessian, hand.hessian), 1e-13) << "h " << h << " a " << amplitude;
      EXPECT_LT(relative_difference(direct.hessian, hand.hessian), 1e-13) << "h " << h << " a " << amplitude;
    }
}

namespace {
Eigen::Matrix<double, 14, 1> unknowns_of(const Interval<Sch, double>& z) {
  Eigen::Matrix<double, 14, 1> u;
  u << z.X2, z.V1, z.O1, SE2::log(z.W), z.w;
  return u;
}
}  // namespace

// One step and its sensitivity dz/d(state), engine against hand, at two step sizes.
TEST(GalerkinBeanieOracle, EngineStepAndSensitivityMatchTheHandOnes) {
  const BeanieModel model = beanie(0.8);
  for (int N : {50, 1000}) {
    const double h = 2.0 / N;
    const Interval<Sch, double> state = test_support::beanie_interval_with_multipliers(model, 2.0, N);
    Interval<Sch, double> z;
    const StepReport r = solve_galerkin_step<Sch>(model, h, state, 1, NewtonOptions{}, z);
    ASSERT_EQ(r.status, StepStatus::Converged) << r.message;
    const auto dz = galerkin_step_sensitivity<Sch>(model, h, state, z);

    oracles::GalerkinBeanieSensitivity hand_dz;
    const auto hand = oracles::galerkin4_beanie_step(model.par, h, oracle_of(state), &hand_dz);
    ASSERT_TRUE(hand.converged);
    const Interval<Sch, double> hz = engine_of(hand.next);
    // Newton's tolerance is 1e-12 (1 + |z|) on each correction.
    EXPECT_LT(max_abs(unknowns_of(hz) - unknowns_of(z)), 1e-12) << "N " << N;
    EXPECT_LT(relative_difference(dz, hand_dz), 1e-11) << "N " << N;
  }
}

// 100 steps with the full state seeded: the engine's flow (extrapolated predictors, chord
// iterations, carried interval derivatives) against the hand flow taking its steps the same way
// and chaining the hand sensitivities.
TEST(GalerkinBeanieOracle, FlowAndItsSensitivityMatchTheHandFlow) {
  const BeanieModel model = beanie(0.8);
  constexpr int N = 200, steps = 100;
  const double h = 2.0 / N;
  const Interval<Sch, double> start = test_support::beanie_interval_with_multipliers(model, 2.0, N);
  const GalerkinFlow<Sch> flow(model, h);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Sch::state, Sch::state);
  const auto run = flow.run(start, steps, &seed);
  ASSERT_TRUE(run.report.ok()) << run.report.message;

  const auto hand = oracles::galerkin4_beanie_flow(model.par, h, oracle_of(start), steps);
  ASSERT_TRUE(hand.converged) << "hand flow stopped at step " << hand.steps + 1;
  const GalerkinBeanieInterval& s = hand.last;
  const oracles::GalerkinBeanieMatrix& S = hand.sensitivity;
  const Interval<Sch, double>& last = run.trajectory.intervals.back();
  EXPECT_LT(max_abs(unknowns_of(engine_of(s)) - unknowns_of(last)), 1e-11);
  EXPECT_LT(std::abs(s.y(0) - last.x(0)) + std::abs(s.y(1) - last.v(0)) + (s.y.segment<3>(2) - last.Om).norm(), 1e-11);
  EXPECT_LT(relative_difference(run.sensitivity.topRows(Sch::state), S), 1e-10);
}
