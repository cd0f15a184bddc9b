// How the paper scheme's flow starts and ends its steps (core/step_solve.hpp): the extrapolated
// predictor's order in h, and a step ended on a prediction, confirmed by one exact Newton
// correction from the window Hessians its sensitivity computes.
#include "helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace lpshoot;
using problems::BeanieControl;
using test_support::beanie_control_initial;

namespace {
BeanieControl beanie() {
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 1.0};
  return b;
}

// Smooth initial data at step h: ψ, Ω and λ from continuous-looking values (λ^1 = λ^0 + h λ').
FlowState<BeanieControl> smooth_start(const BeanieControl& b, double h) {
  const Eigen::Vector3d lam0(0.3, -0.2, 0.1), dlam(0.2, 0.1, 0.1);
  return beanie_control_initial(b, Eigen::Vector3d(0.5, 0.8, -0.5), Eigen::Vector3d(0.8, -0.3, 0.6), lam0,
                                lam0 + h * dlam, h);
}

// L_d = ½ p_0 (p_2 - c)² + ½ (p_1 - p_0)²: step n's matrix ∂E_n/∂p_{n+2} = p_{n+2} - c, singular
// where the new node is c.
struct SquareProblem {
  using Group = Trivial;
  static constexpr int shape_dim = 1, order = 2, num_constraints = 0;
  double c = 4.0;
  template <class T>
  T lagrangian(const Window<SquareProblem, T>& a, double) const {
    const T gap = a.p[2](0) - c, dp = a.p[1](0) - a.p[0](0);
    return 0.5 * a.p[0](0) * gap * gap + 0.5 * dp * dp;
  }
};

struct PredictorErrors {
  double p, g, lam;
};

// The predictor's distance from the solved unknowns of the last step of a flow to t = 0.4.
PredictorErrors predictor_errors(double h, bool extrapolated) {
  const BeanieControl b = beanie();
  const int N = static_cast<int>(std::lround(0.4 / h));
  const auto out = DiscreteFlow<BeanieControl>(b, h).run(smooth_start(b, h), N);
  EXPECT_TRUE(out.report.ok()) << out.report.message;
  const Trajectory<BeanieControl>& t = out.trajectory;
  const int n = N - BeanieControl::order;
  StepUnknowns<BeanieControl> predicted;
  step_predictor(t.state(n), extrapolated, predicted);
  return {std::abs(predicted.p(0) - t.p[n + 2](0)),
          SE2::log(SE2::compose(SE2::inverse(t.g[n + 1]), predicted.g)).norm(),
          (predicted.lam - t.lam[n]).lpNorm<Eigen::Infinity>()};
}
}  // namespace

// The extrapolated predictor (quadratic in the nodes, linear in the group for the increment,
// linear in λ) is O(h³) off in p and g~ and O(h²) in λ; the plain one (linear, last increment,
// last λ) O(h²), O(h²) and O(h). Observed from h = 0.01 to 0.005: the errors' ratios give the
// orders to within 0.15 (measured 2.95, 2.99, 1.99 and 1.99, 2.00, 1.00); at h = 0.01 the
// extrapolated p is 0.6% of the plain one's error.
TEST(PaperFlowSteps, ExtrapolatedPredictorIsThirdOrderInNodesAndIncrements) {
  const PredictorErrors a = predictor_errors(0.01, true), b = predictor_errors(0.005, true);
  EXPECT_NEAR(std::log2(a.p / b.p), 3.0, 0.15);
  EXPECT_NEAR(std::log2(a.g / b.g), 3.0, 0.15);
  EXPECT_NEAR(std::log2(a.lam / b.lam), 2.0, 0.15);
  const PredictorErrors c = predictor_errors(0.01, false), d = predictor_errors(0.005, false);
  EXPECT_NEAR(std::log2(c.p / d.p), 2.0, 0.15);
  EXPECT_NEAR(std::log2(c.g / d.g), 2.0, 0.15);
  EXPECT_NEAR(std::log2(c.lam / d.lam), 1.0, 0.15);
  EXPECT_LT(a.p, 0.02 * c.p);
}

// A solved step moved by ε = 1e-5 in every unknown (the group part too) and evaluated there as a
// flow's sensitivity does: the default step tolerance refuses the confirming correction and
// nothing moves; a loose one accepts it. The step is then O(ε²) off the solution, and window
// a_n's carried gradient O(ε²) off the gradient evaluated afresh at the corrected step (measured
// 2.3e-11 and 4.2e-9 against |g| = 30). Without the bracket term of the re-centred increment the
// gradient is 9.6e-5 off; without the move, 1.6.
TEST(PaperFlowSteps, PredictedStepIsConfirmedByOneNewtonCorrection) {
  const BeanieControl b = beanie();
  const double h = 0.01, eps = 1e-5;
  const int n = 2;
  const FlowState<BeanieControl> s = smooth_start(b, h);
  const NewtonOptions opt;
  StepUnknowns<BeanieControl> z;
  ASSERT_EQ(solve_step(b, h, s, n, opt, z).status, StepStatus::Converged);
  WindowHessianCarry<BeanieControl> carry;  // windows a_0, a_1 as the flow's earlier steps left them
  step_sensitivity(b, h, s, z, nullptr, nullptr, &carry, n);

  Vec<double, 7> direction;
  direction << 0.7, -0.4, 0.9, 0.5, -0.8, 0.3, 0.6;
  StepUnknowns<BeanieControl> moved = z;
  apply_correction(moved, Vec<double, 7>(eps * direction));
  ChordMatrix<7> factored;
  step_sensitivity(b, h, s, moved, &factored, nullptr, &carry, n);
  const Vec<double, 12> gradient_at_moved = carry.of(n).gradient;

  StepUnknowns<BeanieControl> strict = moved;
  EXPECT_FALSE(confirm_predicted_step(b, opt, s, factored, carry, n, strict));
  EXPECT_EQ(strict.p, moved.p);
  EXPECT_EQ(strict.lam, moved.lam);
  EXPECT_EQ(carry.of(n).gradient, gradient_at_moved);

  NewtonOptions loose = opt;
  loose.step_tolerance = 1e-3;
  StepUnknowns<BeanieControl> corrected = moved;
  ASSERT_TRUE(confirm_predicted_step(b, loose, s, factored, carry, n, corrected));
  Vec<double, 7> off;
  off << corrected.p - z.p, SE2::log(SE2::compose(SE2::inverse(z.g), corrected.g)), corrected.lam - z.lam;
  EXPECT_LT(off.lpNorm<Eigen::Infinity>(), 1e-9);  // ε² = 1e-10; ε itself was 1e-5

  WindowHessian<BeanieControl> fresh;
  const NodeBlock<BeanieControl, double> block = step_block<BeanieControl, double>(s, corrected, false);
  window_hessian(b, block.window(n), block.lam[n], h, fresh);
  EXPECT_LT((carry.of(n).gradient - fresh.gradient).lpNorm<Eigen::Infinity>(), 1e-7);
}

// A flow with sensitivities ends its steps on predictions confirmed at the sensitivity; every
// step still solves its equations (evaluated afresh, forward mode through every window) to the
// rounding level of the flow without sensitivities, whose steps are Newton-solved from a fresh
// Jacobian: within 10x its worst residual (measured 3.0x at h = 0.01, 1.0x at h = 0.001). And
// the steps take two residuals each (three before the predicted ends; measured two).
TEST(PaperFlowSteps, ConfirmedStepsSolveTheirEquationsToTheRoundingLevel) {
  const BeanieControl b = beanie();
  for (double h : {0.01, 0.001}) {
    const int N = static_cast<int>(std::lround(0.5 / h));
    const DiscreteFlow<BeanieControl> flow(b, h);
    const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Dims<BeanieControl>::state, Dims<BeanieControl>::state);
    const auto seeded = flow.run(smooth_start(b, h), N, &seed);
    const auto plain = flow.run(smooth_start(b, h), N);
    ASSERT_TRUE(seeded.report.ok() && plain.report.ok()) << seeded.report.message << plain.report.message;
    auto worst_residual = [&](const Trajectory<BeanieControl>& t) {
      double worst = 0;
      for (int n = 2; n <= N - 2; ++n) {
        const FlowState<BeanieControl> s = t.state(n);
        StepUnknowns<BeanieControl> z;
        z.p = t.p[n + 2];
        z.g = t.g[n + 1];
        z.lam = t.lam[n];
        const auto F = step_residual(b, h, s, z, step_fixed_part(b, h, s, z));
        worst = std::max(worst, F.lpNorm<Eigen::Infinity>());
      }
      return worst;
    };
    EXPECT_LT(worst_residual(seeded.trajectory), 10 * worst_residual(plain.trajectory)) << "h = " << h;
    EXPECT_LE(seeded.report.total_iterations, 2 * seeded.report.steps) << "h = " << h;
  }
}

// A step's residual from window a_n's gradient and increment n's perturbation (Newton's
// residual with a group, step_residual_from_window) against the residual of the perturbed windows
// (step_residual, forward mode through node n's moves): the same F to rounding, at solved steps
// and away from them (z moved), for both constraint sets and for the derived beanie windows
// (PaperWindows, with the nodes' low parts).
TEST(PaperFlowSteps, ResidualFromTheWindowGradientIsThePerturbedWindowsResidual) {
  auto expect_same = [](const auto& problem, const auto& start, double h, const char* name) {
    using P = std::decay_t<decltype(problem)>;
    const int N = 40;
    const auto out = DiscreteFlow<P>(problem, h).run(start, N);
    ASSERT_TRUE(out.report.ok()) << out.report.message;
    double worst = 0, scale = 0;
    for (int n = 2; n <= N - 2; n += 5) {
      const FlowState<P> s = out.trajectory.state(n);
      for (double move : {0.0, 1e-3, -0.05}) {
        StepUnknowns<P> z;
        z.p = out.trajectory.p[n + 2] + Vec<double, P::shape_dim>::Constant(move);
        z.g = P::Group::compose(out.trajectory.g[n + 1],
                                P::Group::template exp<double>(P::Group::template Tangent<double>::Constant(move)));
        z.lam = out.trajectory.lam[n] + Vec<double, P::num_constraints>::Constant(10 * move);
        const NodeBlock<P, double> b = step_block<P, double>(s, z, false);
        const auto right = increment_perturbation(problem, b.p[2], b.p[3], b.g[2], false);
        const auto fixed = step_fixed_part(problem, h, s, z);
        const auto F = step_residual(problem, h, s, z, fixed);
        const auto G = step_residual_from_window(problem, h, s, z, fixed, right);
        worst = std::max(worst, (F - G).template lpNorm<Eigen::Infinity>());
        scale = std::max(scale, F.template lpNorm<Eigen::Infinity>() + fixed.template lpNorm<Eigen::Infinity>());
      }
    }
    std::printf("%s: residuals differ by %.1e (scale %.1e)\n", name, worst, scale);
    EXPECT_LT(worst, 1e-12 * scale) << name;
  };
  const double h = 0.02;
  for (auto variant : {problems::BeanieConstraints::ExactRotation, problems::BeanieConstraints::Paper}) {
    BeanieControl b = beanie();
    b.variant = variant;
    expect_same(b, smooth_start(b, h), h, variant == problems::BeanieConstraints::Paper ? "paper constraints" : "exact rotation");
  }
  using Derived = PaperWindows<problems::BeanieModel>;
  Derived derived;
  derived.model.par = beanie().par;
  FlowState<Derived> s;
  const FlowState<BeanieControl> c = smooth_start(beanie(), h);
  s.p = c.p, s.g = c.g, s.lam = c.lam;
  expect_same(derived, s, h, "derived beanie windows");
}

// Nodes 3, 1, 3, 4: the extrapolated predictor of the next node is 4 (quadratic), the plain one 5
// (linear), and E_n = ½ (z - 4)² - 2 (windows n, n-1, n-2: ½ (z - 4)² - 1, 2, 3 (3 - 4)), whose
// root beyond the plain predictor is z = 6. With c = 4 the step matrix vanishes at the
// extrapolated predictor, so Newton from there stops as singular; the step is then solved from the
// plain predictor, and the report counts both attempts' iterations.
TEST(PaperFlowSteps, AStepSingularAtTheExtrapolatedPredictorIsSolvedFromThePlainOne) {
  const SquareProblem problem;
  const double h = 0.1;
  FlowState<SquareProblem> s;
  s.p = {Vec<double, 1>(3.0), Vec<double, 1>(1.0), Vec<double, 1>(3.0), Vec<double, 1>(4.0)};
  StepUnknowns<SquareProblem> z;
  step_predictor(s, true, z);
  ASSERT_EQ(z.p(0), problem.c);
  Vec<double, 1> F;
  Eigen::Matrix<double, 1, 1> J;
  const Vec<double, 1> fixed = step_fixed_part(problem, h, s, z);
  evaluate_step<SquareProblem, 1>(problem, h, s, z, false, &fixed, F, J);
  EXPECT_EQ(J(0, 0), 0.0);  // singular there

  const StepReport rep = solve_step(problem, h, s, 2, NewtonOptions{}, z);
  ASSERT_EQ(rep.status, StepStatus::Converged) << rep.message;
  EXPECT_GE(rep.iterations, 2);
  EXPECT_LT(std::abs(step_residual(problem, h, s, z, fixed)(0)), 1e-12);
  EXPECT_NEAR(z.p(0), 6.0, 1e-12);
}
