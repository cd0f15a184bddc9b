// Hessians by reverse over forward (core/taped_hessian.hpp) against the forward Hess arithmetic
// (core/hessian_scalar.hpp), an independent rule for every operation: scalar functions using each
// operation the problems may use, and the paper windows' Hessians (step_window_hessian.hpp) of
// hand-written and derived problems, with and without a group and constraints. The two differ in
// the order of their roundings only: agreement to a few units of roundoff relative to the
// largest entry, at random points, with one tape reused call after call (as a flow reuses it).
#include <lpshoot/core/lpshoot.hpp>
#include <lpshoot/core/paper_windows.hpp>
#include <lpshoot/problems/beanie.hpp>
#include <lpshoot/problems/electron.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {

// Every operation Taped records: both operand kinds, division both ways, the elementary
// functions, atan2, pow, abs, and a function lifted from its series (SO(2)'s sinc through
// apply_univariate), composed so that each enters the Hessian through the chain rule.
template <class T>
T battery(const T& x, const T& y, const T& z) {
  using std::abs;
  using std::atan2;
  using std::cos;
  using std::exp;
  using std::log;
  using std::pow;
  using std::sin;
  using std::sqrt;
  using std::tanh;
  const T a = x * y - 2.0 * z + 0.5;
  const T b = sin(a) * cos(y - x) + exp(0.3 * z) / (1.5 + x * x);
  const T c = log(2.0 + y * y) * sqrt(1.0 + z * z) - tanh(x * z);
  const T d = atan2(y + 0.2, x - 1.7) * pow(1.2 + x * x, 1.5) + abs(x - y) - 3.0 / (2.0 + z * y * y);
  const T e = detail::sinc(a) + (1.0 - b) * (c - 0.5) + d * d;
  T f = e;
  f += b;
  f -= 0.25 * c;
  f *= (1.0 + 0.1 * x);
  f /= (2.0 + cos(z));
  return -f + 4.0;
}

TEST(TapedHessian, EveryOperationAgreesWithForwardHessianArithmetic) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Tape<3> tape;
  for (int trial = 0; trial < 200; ++trial) {
    const double X = U(rng), Y = U(rng), Z = U(rng);
    const Hess<3> f = battery(Hess<3>::variable(X, 0), Hess<3>::variable(Y, 1), Hess<3>::variable(Z, 2));
    tape.clear();
    const Taped<3> t = battery(tape.variable(X, 0), tape.variable(Y, 1), tape.variable(Z, 2));
    tape.seed(t, 1.0);
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    tape.sweep(H);
    const Eigen::Vector3d g = tape.gradient(t);
    double scale = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) scale = std::max(scale, std::abs(f.hessian(i, j)));
    ASSERT_EQ(t.v, f.v);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(g(i), f.g[i], 1e-14 * std::max(1.0, std::abs(f.g[i]))) << "trial " << trial;
      for (int j = 0; j < 3; ++j) EXPECT_NEAR(H(i, j), f.hessian(i, j), 1e-13 * scale) << "trial " << trial;
    }
  }
}

// Weighted outputs: one sweep gives ∇²(Σ w_o y_o), seeds given before or after more nodes are
// recorded (a seed taken early must not leave the later nodes' adjoints stale).
TEST(TapedHessian, WeightedOutputsInOneSweep) {
  Tape<2> tape;
  for (int round = 0; round < 3; ++round) {
    tape.clear();
    const Taped<2> x = tape.variable(0.3 + round, 0), y = tape.variable(-0.7, 1);
    const Taped<2> p = x * x * y;
    tape.seed(p, 2.0);
    const Taped<2> q = sin(x * y);
    tape.seed(q, -3.0);
    Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
    tape.sweep(H);
    const double X = 0.3 + round, Y = -0.7, s = std::sin(X * Y), c = std::cos(X * Y);
    // 2 x² y − 3 sin(x y)
    EXPECT_NEAR(H(0, 0), 4.0 * Y + 3.0 * s * Y * Y, 1e-14 * 10);
    EXPECT_NEAR(H(0, 1), 4.0 * X - 3.0 * (c - s * X * Y), 1e-14 * 10);
    EXPECT_NEAR(H(1, 0), H(0, 1), 0.0);
    EXPECT_NEAR(H(1, 1), 3.0 * s * X * X, 1e-14 * 10);
  }
}

template <class P>
void expect_window_hessians_agree(const P& problem, double h, int trials) {
  using G = typename P::Group;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < trials; ++trial) {
    Window<P, double> a;
    for (int i = 0; i <= P::order; ++i)
      for (int c = 0; c < P::shape_dim; ++c) a.p[i](c) = U(rng);
    for (int i = 0; i < P::order; ++i)
      for (double* x : ElementScalars<G>::of(a.g[i])) *x = U(rng);
    Vec<double, P::num_constraints> lam;
    for (int c = 0; c < P::num_constraints; ++c) lam(c) = U(rng);
    WindowHessian<P> forward, taped;
    window_hessian_forward(problem, a, lam, h, forward);
    window_hessian_taped(problem, a, lam, h, taped);
    const double hs = forward.hessian.cwiseAbs().maxCoeff(), gs = forward.gradient.cwiseAbs().maxCoeff();
    ASSERT_GT(hs, 0.0);
    EXPECT_LE((taped.hessian - forward.hessian).cwiseAbs().maxCoeff(), 1e-14 * hs) << "trial " << trial;
    EXPECT_LE((taped.gradient - forward.gradient).cwiseAbs().maxCoeff(), 1e-14 * gs) << "trial " << trial;
    EXPECT_TRUE(taped.hessian.isApprox(taped.hessian.transpose(), 0.0)) << "trial " << trial;
  }
}

TEST(TapedHessian, PaperWindowsOfHandWrittenProblems) {
  BeanieControl control;
  control.par.amplitude = 0.7;
  expect_window_hessians_agree(control, 0.01, 50);
  control.variant = BeanieConstraints::Paper;
  expect_window_hessians_agree(control, 0.2, 50);
  BeanieFree free;
  free.par.amplitude = 0.4;
  expect_window_hessians_agree(free, 0.05, 50);
}

TEST(TapedHessian, PaperWindowsOfDerivedProblems) {
  PaperWindows<BeanieModel, WindowJet::Central> beanie;
  beanie.model.par.amplitude = 0.6;
  expect_window_hessians_agree(beanie, 0.02, 30);
  PaperWindows<ElectronModel, WindowJet::Forward> electron;
  electron.model.quartic = 0.3;
  expect_window_hessians_agree(electron, 0.05, 30);
}

}  // namespace
