// The Galerkin schemes (METHOD.md §9) on the beanie: observed orders in every output against the
// continuous reference, the discrete momentum map, the flow's sensitivities, reused and guided
// step solves, and the shooting Jacobian. The electron's checks: test_galerkin_electron.cpp.
#include "beanie_galerkin_start.hpp"
#include "galerkin_beanie_checks.hpp"
#include "oracles/continuous.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>

#include <gtest/gtest.h>

#include <random>

using namespace lpshoot;
using namespace lpshoot::problems;

TEST(GalerkinBeanie, CubicIsOrderFourInEveryOutput) {
  // V = 1 - cos ψ, the well-posed data of test_shooting_beanie: ψ, ψ' at both ends, g(0), Ω12(0),
  // θ(T); Ω3(0), Ω(T), x(T), y(T) free. The continuous answer: ψ, u from the odeint oracle; the
  // group part in closed form (θ(T) given, Ω3 constant, the centre moving uniformly with the
  // spatial velocity Ω12(0): x(T) = 0.5 T, y(T) = 0.2 T, Ω12(T) = R(-1) Ω12(0)).
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  BeanieBoundary s, e;
  test_support::beanie_scene_boundary(s, e);
  const double T = 2.0;
  const Eigen::Vector2d Om12T = SO2::rotation(-1.0) * Eigen::Vector2d(0.5, 0.2);
  struct E {
    double psi, u, cost, xy, Om, chi;  // chi: the constraints on the node jets (their Ω' from node differences)
  };
  std::vector<E> err;
  const std::vector<int> grids{10, 20, 40, 80};
  for (int N : grids) {
    std::vector<double> times;
    for (int n = 0; n <= N; ++n) times.push_back(n * T / N);
    const auto ref = oracles::beanie_continuous_optimum(model.par, T, 0, 0, 1, 0, times);
    ASSERT_TRUE(ref.converged);
    const auto bvp = beanie_galerkin_bvp<3>(model, T, N, s, e);
    const auto r = solve_bvp(bvp, beanie_galerkin_guess<3>(bvp, s, e));
    ASSERT_TRUE(r.ok()) << r.message;
    E x{0, 0, std::abs(r.cost - ref.cost), 0, 0, 0};
    for (int n = 0; n <= N; ++n) {
      x.psi = std::max(x.psi, std::abs(r.trajectory.x(n)(0) - ref.psi[n]));
      Jet<BeanieModel, double> q;
      NodeJetSource source = NodeJetSource::LegendreTransform;
      ASSERT_TRUE(node_jet(model, r.trajectory, n, q, source));
      EXPECT_EQ(source, NodeJetSource::LegendreTransform);  // χ has no ψ'', ℓ no Ω'
      x.u = std::max(x.u, std::abs(model.control(q) - ref.u[n]));
      // The continuous Ω' = (w Ω2, -w Ω1, 0) makes χ vanish; Ω' = 0 would leave |w Ω12| ≈ 0.2–0.4 at every N.
      x.chi = std::max(x.chi, model.constraints(q).lpNorm<Eigen::Infinity>());
    }
    x.xy = std::max(std::abs(r.g.back().t(0) - 0.5 * T), std::abs(r.g.back().t(1) - 0.2 * T));
    const Eigen::Vector3d Om = r.trajectory.Omega(N);
    x.Om = std::max((Om.head<2>() - Om12T).lpNorm<Eigen::Infinity>(), std::abs(Om(2) - (1.0 + model.par.c()) / T));
    EXPECT_NEAR(r.g.back().angle, 1.0, 1e-12) << "theta(T)";
    err.push_back(x);
  }
  for (size_t i = 1; i < err.size(); ++i) {
    const E& a = err[i - 1];
    const E& b = err[i];
    const double o[5] = {std::log2(a.psi / b.psi), std::log2(a.u / b.u), std::log2(a.cost / b.cost), std::log2(a.xy / b.xy),
                         std::log2(a.Om / b.Om)};
    std::printf("beanie N = %d: psi %.2e (%.2f) u %.2e (%.2f) cost %.2e (%.2f) x,y(T) %.2e (%.2f) Omega(T) %.2e (%.2f) "
                "chi at nodes %.2e (%.2f)\n",
                grids[i], b.psi, o[0], b.u, o[1], b.cost, o[2], b.xy, o[3], b.Om, o[4], b.chi, std::log2(a.chi / b.chi));
    const char* what[5] = {"psi", "u", "cost", "x,y(T)", "Omega(T)"};
    for (int k = 0; k < 5; ++k) EXPECT_GE(o[k], 3.85) << what[k] << ", N = " << grids[i];
    EXPECT_GE(std::log2(a.chi / b.chi), 3.6) << "Omega' at the nodes, N = " << grids[i];
  }
}

namespace {
using BG = BeanieGalerkin<3>;
using test_support::beanie_interval_with_multipliers;
using test_support::check_flow_sensitivity;
using test_support::check_momentum_conserved;
using test_support::check_shooting_jacobian;
}  // namespace

// The momentum map, the flow's sensitivities and the shooting Jacobian: galerkin_beanie_checks.hpp
// (degree 5 in test_galerkin_order8.cpp).
TEST(GalerkinBeanie, MomentumIsConservedToRoundoffWithNonZeroMultipliers) { check_momentum_conserved<3>(); }
TEST(GalerkinFlow, SensitivityMatchesFiniteDifferences) { check_flow_sensitivity<3>(); }
TEST(GalerkinFlow, SensitivityWithBubblesMatchesFiniteDifferences) { check_flow_sensitivity<4>(); }

// With sensitivities each step's Newton starts with the previous step's matrix at its solution
// (chord iterations, newton_solve's `previous`); without, with its own exact Jacobian. Both must
// land on the same solution to the step tolerance, and report the same regularity.
template <int S>
void check_reused_step_matrices() {
  using BG = BeanieGalerkin<S>;
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  const double h = 0.02;
  const auto start = beanie_interval_with_multipliers<S>(model, 4.0, 200);
  const GalerkinFlow<BG> flow(model, h);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(BG::state, BG::state);
  const auto plain = flow.run(start, 150, nullptr);
  const auto seeded = flow.run(start, 150, &seed);
  ASSERT_TRUE(plain.report.ok()) << plain.report.message;
  ASSERT_TRUE(seeded.report.ok()) << seeded.report.message;
  double worst = 0;
  for (size_t n = 0; n < plain.trajectory.intervals.size(); ++n)
    worst = std::max(worst, state_difference(seeded.trajectory.intervals[n], plain.trajectory.intervals[n], h)
                                .template lpNorm<Eigen::Infinity>());
  std::printf("degree %d, 150 steps: seeded and plain flows differ by %.2e; max conditions %.4g and %.4g\n", S, worst,
              seeded.report.max_condition, plain.report.max_condition);
  EXPECT_LT(worst, 1e-10);
  // The seeded flow checks each step matrix at the solution; the plain one at its first iterate.
  EXPECT_NEAR(seeded.report.max_condition, plain.report.max_condition, 0.05 * plain.report.max_condition);
}

TEST(GalerkinFlow, ReusedStepMatricesLandOnTheSameSolution) { check_reused_step_matrices<3>(); }
TEST(GalerkinFlow, ReusedStepMatricesLandOnTheSameSolutionWithBubbles) { check_reused_step_matrices<4>(); }

// The guided-flow tests' setting: the beanie Galerkin flow with h = 0.25 over 7 steps from a
// start with multipliers and g0, the identity seed (state and group), and a guide run from that
// start with its memo recorded; `moved(eps)`: the start moved by eps sin(2 + i) in coordinate i.
template <int S>
struct GuidedFlowSetting {
  using BG = BeanieGalerkin<S>;
  static constexpr int steps = 7, ns = BG::state;
  static constexpr double h = 0.25;
  BeanieModel model = [] {
    BeanieModel m;
    m.par = {1.0, 1.0, 0.5, 1.0};
    return m;
  }();
  Interval<BG, double> start = beanie_interval_with_multipliers<S>(model, 2.0, 8);
  SE2::Element<double> g0{0.3, Eigen::Vector2d(0.5, -0.2)};
  GalerkinFlow<BG> flow{model, h};
  Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(ns + BG::d, ns + BG::d);
  GalerkinFlowResult<BG> guide = flow.run(start, steps, &seed, g0, 0, true, nullptr, true);

  Interval<BG, double> moved(double eps) const {
    Vec<double, ns> delta;
    for (int i = 0; i < ns; ++i) delta(i) = eps * std::sin(2.0 + i);
    return retract<BG>(start, delta, h);
  }
  // The largest node-state difference between two runs of the steps, and the relative
  // difference of their sensitivities.
  static double solution_difference(const GalerkinFlowResult<BG>& a, const GalerkinFlowResult<BG>& b) {
    double worst = 0;
    for (int k = 0; k <= steps; ++k)
      worst = std::max(worst, state_difference(a.trajectory.intervals[k], b.trajectory.intervals[k], h)
                                  .template lpNorm<Eigen::Infinity>());
    return worst;
  }
  static double sensitivity_difference(const GalerkinFlowResult<BG>& a, const GalerkinFlowResult<BG>& b) {
    return (a.sensitivity - b.sensitivity).template lpNorm<Eigen::Infinity>() /
           b.sensitivity.template lpNorm<Eigen::Infinity>();
  }
};

// A run guided by an earlier run from a nearby start (GalerkinFlow::run's `guide`: step k starts
// from the guide's interval k moved by the guide's dz times the change of interval k-1, with the
// guide's step matrix) lands on the same solution as an unguided run, with the same sensitivity.
// Its predictions are O(ε²) off for a start moved by ε and its chord steps contract by O(ε), so a
// step needs two iterations at ε = 1e-5 (1e-10, then below the step tolerance 1e-12) and three
// at ε = 1e-3; without dz's term (O(ε) off) it would need three at ε = 1e-5. A start moved by
// O(1) is not guided: the same Newton iterations as without a guide.
template <int S>
void check_guided_flow() {
  const GuidedFlowSetting<S> set;
  constexpr int steps = GuidedFlowSetting<S>::steps;
  ASSERT_TRUE(set.guide.report.ok()) << set.guide.report.message;
  ASSERT_EQ(set.guide.memo.size(), static_cast<size_t>(steps));
  for (const double eps : {1e-5, 1e-3, 0.5}) {
    const auto moved = set.moved(eps);
    for (const Eigen::MatrixXd* sd : {&set.seed, static_cast<const Eigen::MatrixXd*>(nullptr)}) {
      const auto plain = set.flow.run(moved, steps, sd, set.g0);
      const auto guided = set.flow.run(moved, steps, sd, set.g0, 0, true, &set.guide);
      ASSERT_TRUE(plain.report.ok()) << plain.report.message;
      ASSERT_TRUE(guided.report.ok()) << guided.report.message;
      const double worst = set.solution_difference(guided, plain);
      const double sens = sd ? set.sensitivity_difference(guided, plain) : 0.0;
      std::printf("degree %d, start moved by %g, %s: Newton iterations %d guided, %d plain; solutions differ by %.2e, "
                  "sensitivities by %.2e\n",
                  S, eps, sd ? "seeded" : "plain", guided.report.total_iterations, plain.report.total_iterations, worst,
                  sens);
      EXPECT_LT(worst, sd ? 1e-10 : 1e-13);  // chord-converged steps to the step tolerance; polished ones to roundoff
      EXPECT_LT(sens, 1e-8);
      if (eps < 0.1) {
        EXPECT_LE(guided.report.total_iterations, (eps < 1e-4 ? 2 : 3) * steps);
        EXPECT_LT(guided.report.total_iterations, plain.report.total_iterations);
      } else {
        EXPECT_EQ(guided.report.total_iterations, plain.report.total_iterations);
      }
    }
  }
}

TEST(GalerkinFlow, GuidedRunsLandOnTheSameSolutionInFewerIterations) { check_guided_flow<3>(); }
TEST(GalerkinFlow, GuidedRunsLandOnTheSameSolutionInFewerIterationsWithBubbles) { check_guided_flow<4>(); }

// A flow with sensitivities takes a step's prediction when the step before landed well within
// the confirmation's bound of its own (galerkin_flow.hpp), and solves the step by Newton when
// the exact correction at the prediction refuses it. Here the guide is a run from a start 1e-7
// away, so its predictions are ~1e-14 off and steps 2 to 5 are taken, but its intervals from
// step 5 on are corrupted (X2 by 1e-6, relative): step 5's prediction is refused and solved again
// (seen with a counter in a patched copy). The run must land on the unguided run's solution and
// sensitivity (measured: 2.2e-15 and 5.8e-15, sensitivities 2.9e-13 and 2.0e-13); a refused
// prediction kept would leave step 5 ~1e-6 off.
template <int S>
void check_refused_prediction() {
  GuidedFlowSetting<S> set;
  constexpr int steps = GuidedFlowSetting<S>::steps;
  ASSERT_TRUE(set.guide.report.ok()) << set.guide.report.message;
  for (int k = 5; k <= steps; ++k) set.guide.trajectory.intervals[k].X2 *= 1.0 + 1e-6;
  const auto moved = set.moved(1e-7);
  const auto plain = set.flow.run(moved, steps, &set.seed, set.g0);
  const auto guided = set.flow.run(moved, steps, &set.seed, set.g0, 0, true, &set.guide);
  ASSERT_TRUE(plain.report.ok()) << plain.report.message;
  ASSERT_TRUE(guided.report.ok()) << guided.report.message;
  const double worst = set.solution_difference(guided, plain);
  const double sens = set.sensitivity_difference(guided, plain);
  std::printf("degree %d, a guide corrupted from step 5: Newton iterations %d guided, %d plain; solutions differ by "
              "%.2e, sensitivities by %.2e\n",
              S, guided.report.total_iterations, plain.report.total_iterations, worst, sens);
  EXPECT_LT(worst, 1e-10);
  EXPECT_LT(sens, 1e-8);
  EXPECT_LT(2 * guided.report.total_iterations, plain.report.total_iterations);  // predictions were taken
}

TEST(GalerkinFlow, ARefusedPredictionIsSolvedByNewton) { check_refused_prediction<3>(); }
TEST(GalerkinFlow, ARefusedPredictionIsSolvedByNewtonWithBubbles) { check_refused_prediction<4>(); }

TEST(GalerkinShooting, JacobianMatchesFiniteDifferences) { check_shooting_jacobian<3>(); }
TEST(GalerkinShooting, JacobianWithBubblesMatchesFiniteDifferences) { check_shooting_jacobian<4>(); }
