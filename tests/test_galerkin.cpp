// The Galerkin schemes (METHOD.md §9): observed orders against exact and independent continuous
// references, the discrete momentum map, the flow's sensitivities, the regularity check, the
// shooting Jacobian, and no roundoff floor on fine grids.
#include "beanie_galerkin_start.hpp"
#include "galerkin_beanie_checks.hpp"
#include "oracles/continuous.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>

#include <gtest/gtest.h>

#include <random>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {
const ElectronBoundary kStart{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
const ElectronBoundary kEnd{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};

struct Errors {
  double x = 0, u = 0, cost = 0;
};

// Max errors over the nodes of positions and node controls (discrete Legendre transform), and
// the cost error, against the exact optimum.
template <int S>
Errors electron_errors(const Electron& e, double T, int N, const ShootingOptions& opt) {
  const auto exact = electron_exact_optimum(e, T, kStart.position, kStart.velocity, kEnd.position, kEnd.velocity);
  const auto bvp = electron_galerkin_bvp<S>(model_of(e), T, N, kStart, kEnd);
  const auto r = solve_bvp(bvp, electron_galerkin_guess<S>(bvp, kStart, kEnd), opt);
  EXPECT_TRUE(r.ok()) << r.message;
  Errors err;
  for (int n = 0; n <= N; ++n) {
    const double t = n * bvp.h();
    err.x = std::max(err.x, (r.trajectory.x(n) - exact.position(t)).template lpNorm<Eigen::Infinity>());
    Jet<ElectronModel, double> q;
    EXPECT_TRUE(node_jet(bvp.model, r.trajectory, n, q));
    err.u = std::max(err.u, (bvp.model.control(q) - exact.control(t)).template lpNorm<Eigen::Infinity>());
  }
  err.cost = std::abs(r.cost - exact.cost);
  return err;
}

template <int S>
void expect_orders(const Electron& e, double T, std::vector<int> grids, double order, double tol) {
  std::vector<Errors> err;
  for (int N : grids) {
    ShootingOptions opt;
    opt.method = ShootingMethod::Multiple;
    opt.segments = std::max(1, N / 12);
    err.push_back(electron_errors<S>(e, T, N, opt));
  }
  for (size_t i = 1; i < err.size(); ++i) {
    const double ox = std::log2(err[i - 1].x / err[i].x), ou = std::log2(err[i - 1].u / err[i].u),
                 oc = std::log2(err[i - 1].cost / err[i].cost);
    std::printf("degree %d, N = %d: x %.3e (order %.2f), u %.3e (%.2f), cost %.3e (%.2f)\n", S, grids[i], err[i].x, ox,
                err[i].u, ou, err[i].cost, oc);
    EXPECT_NEAR(ox, order, tol) << "positions, N = " << grids[i];
    EXPECT_NEAR(ou, order, tol) << "controls, N = " << grids[i];
    EXPECT_NEAR(oc, order, tol) << "cost, N = " << grids[i];
  }
}
}  // namespace

TEST(GalerkinElectron, CubicIsOrderFourAgainstTheExactOptimum) {
  expect_orders<3>(Electron{}, 2.0, {10, 20, 40, 80}, 4.0, 0.15);
}

TEST(GalerkinElectron, QuarticIsOrderSixAgainstTheExactOptimum) {
  // A stronger field (B = 3 e_z) keeps three halvings above the exact oracle's ~1e-12 accuracy.
  const Electron e{1.0, 1.0, Eigen::Vector3d(0, 0, 3.0), 1.0};
  expect_orders<4>(e, 2.0, {6, 12, 24, 48}, 6.0, 0.2);
}

TEST(GalerkinElectron, QuinticIsOrderEight) {
  const Electron e{1.0, 1.0, Eigen::Vector3d(0, 0, 3.0), 1.0};
  expect_orders<5>(e, 2.0, {6, 12, 24}, 8.0, 0.3);
}

TEST(GalerkinElectron, NonlinearPotentialAgainstAnOdeintReference) {
  // METHOD.md §9's check: φ = ½|x|² + ⅛ x1⁴, T = 2, x(0) = (1, 0, 0), x'(0) = (0, 1, 0.5),
  // x(T) = (0, 1, 1), x'(T) = (-1, 0, 0). The prototype measured 1.5e-6, 9.7e-8, 6.1e-9, 3.8e-10
  // (cubic, N = 10..80) and 3.7e-9, 5.8e-11 (quartic, N = 10, 20).
  ElectronModel model;
  model.potential = 0.5;
  model.quartic = 0.125;
  const ElectronBoundary a{Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0.5)};
  const ElectronBoundary b{Eigen::Vector3d(0, 1, 1), Eigen::Vector3d(-1, 0, 0)};
  const double T = 2.0;
  auto errors = [&](auto degree, const std::vector<int>& grids) {
    constexpr int S = decltype(degree)::value;
    std::vector<double> ex, eu;
    for (int N : grids) {
      std::vector<double> times;
      for (int n = 0; n <= N; ++n) times.push_back(n * T / N);
      const auto ref = oracles::electron_nonlinear_optimum(model, T, a.position, a.velocity, b.position, b.velocity, times);
      EXPECT_TRUE(ref.converged);
      const auto bvp = electron_galerkin_bvp<S>(model, T, N, a, b);
      const auto r = solve_bvp(bvp, electron_galerkin_guess<S>(bvp, a, b));
      EXPECT_TRUE(r.ok()) << r.message;
      double x = 0, u = 0;
      for (int n = 0; n <= N; ++n) {
        x = std::max(x, (r.trajectory.x(n) - ref.x[n]).template lpNorm<Eigen::Infinity>());
        Jet<ElectronModel, double> q;
        EXPECT_TRUE(node_jet(model, r.trajectory, n, q));
        u = std::max(u, (model.control(q) - ref.u[n]).template lpNorm<Eigen::Infinity>());
      }
      ex.push_back(x);
      eu.push_back(u);
      std::printf("nonlinear, degree %d, N = %d: x %.3e, u %.3e\n", S, N, x, u);
    }
    return std::make_pair(ex, eu);
  };
  const auto [x4, u4] = errors(std::integral_constant<int, 3>{}, {10, 20, 40, 80});
  EXPECT_LT(x4[0], 3e-6);
  for (size_t i = 1; i < x4.size(); ++i) {
    EXPECT_NEAR(std::log2(x4[i - 1] / x4[i]), 4.0, 0.15);
    EXPECT_NEAR(std::log2(u4[i - 1] / u4[i]), 4.0, 0.15);
  }
  const auto [x6, u6] = errors(std::integral_constant<int, 4>{}, {5, 10, 20});
  EXPECT_LT(x6[1], 1e-8);
  for (size_t i = 1; i < x6.size(); ++i) {
    EXPECT_NEAR(std::log2(x6[i - 1] / x6[i]), 6.0, 0.3);
    EXPECT_NEAR(std::log2(u6[i - 1] / u6[i]), 6.0, 0.3);
  }
}

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
    double psi, u, cost, xy, Om;
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
    E x{0, 0, std::abs(r.cost - ref.cost), 0, 0};
    for (int n = 0; n <= N; ++n) {
      x.psi = std::max(x.psi, std::abs(r.trajectory.x(n)(0) - ref.psi[n]));
      Jet<BeanieModel, double> q;
      ASSERT_TRUE(node_jet(model, r.trajectory, n, q));
      x.u = std::max(x.u, std::abs(model.control(q) - ref.u[n]));
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
    std::printf("beanie N = %d: psi %.2e (%.2f) u %.2e (%.2f) cost %.2e (%.2f) x,y(T) %.2e (%.2f) Omega(T) %.2e (%.2f)\n",
                grids[i], b.psi, o[0], b.u, o[1], b.cost, o[2], b.xy, o[3], b.Om, o[4]);
    const char* what[5] = {"psi", "u", "cost", "x,y(T)", "Omega(T)"};
    for (int k = 0; k < 5; ++k) EXPECT_GE(o[k], 3.85) << what[k] << ", N = " << grids[i];
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

// A run guided by an earlier run from a nearby start (GalerkinFlow::run's `guide`: step k starts
// from the guide's interval k moved by the guide's dz times the change of interval k-1, with the
// guide's step matrix) lands on the same solution as an unguided run, with the same sensitivity.
// Its predictions are O(ε²) off for a start moved by ε and its chord steps contract by O(ε), so a
// step needs two iterations at ε = 1e-5 (1e-10, then below the step tolerance 1e-12) and three
// at ε = 1e-3; without dz's term (O(ε) off) it would need three at ε = 1e-5. A start moved by
// O(1) is not guided: the same Newton iterations as without a guide.
template <int S>
void check_guided_flow() {
  using BG = BeanieGalerkin<S>;
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  const double h = 0.25;
  const int steps = 7;
  const auto start = beanie_interval_with_multipliers<S>(model, 2.0, 8);
  const SE2::Element<double> g0{0.3, Eigen::Vector2d(0.5, -0.2)};
  const GalerkinFlow<BG> flow(model, h);
  constexpr int ns = BG::state, n = ns + BG::d;
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(n, n);
  const auto guide = flow.run(start, steps, &seed, g0, 0, true, nullptr, true);
  ASSERT_TRUE(guide.report.ok()) << guide.report.message;
  ASSERT_EQ(guide.memo.size(), static_cast<size_t>(steps));
  for (const double eps : {1e-5, 1e-3, 0.5}) {
    Vec<double, ns> delta;
    for (int i = 0; i < ns; ++i) delta(i) = eps * std::sin(2.0 + i);
    const auto moved = retract<BG>(start, delta, h);
    for (const Eigen::MatrixXd* sd : {&seed, static_cast<const Eigen::MatrixXd*>(nullptr)}) {
      const auto plain = flow.run(moved, steps, sd, g0);
      const auto guided = flow.run(moved, steps, sd, g0, 0, true, &guide);
      ASSERT_TRUE(plain.report.ok()) << plain.report.message;
      ASSERT_TRUE(guided.report.ok()) << guided.report.message;
      double worst = 0;
      for (int k = 0; k <= steps; ++k)
        worst = std::max(worst, state_difference(guided.trajectory.intervals[k], plain.trajectory.intervals[k], h)
                                    .template lpNorm<Eigen::Infinity>());
      const double sens = sd ? (guided.sensitivity - plain.sensitivity).template lpNorm<Eigen::Infinity>() /
                                   plain.sensitivity.template lpNorm<Eigen::Infinity>()
                             : 0.0;
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

TEST(GalerkinFlow, TooFewGaussPointsMakeTheStepSingular) {
  // A cubic with one Gauss point (and a quartic with two) cannot see every direction of the
  // interval: the step matrix is singular, and the regularity check names the step.
  const Electron e{};
  // Also with sensitivities (their flow checks the step matrix at each solution as well).
  auto first_failure = [&](auto scheme, bool seeded = false) {
    using Sch = decltype(scheme);
    const auto bvp3 = electron_galerkin_bvp<3>(model_of(e), 2.0, 20, kStart, kEnd);
    const auto guess = electron_galerkin_guess<3>(bvp3, kStart, kEnd).trajectory.intervals[3];
    Interval<Sch, double> iv;
    iv.x = guess.x, iv.v = guess.v, iv.X2 = guess.X2, iv.V1 = guess.V1;
    iv.w.setZero();
    const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Sch::state, Sch::state);
    return GalerkinFlow<Sch>(model_of(e), 0.1).run(iv, 5, seeded ? &seed : nullptr, {}, 3).report;
  };
  for (const FlowReport& rep : {first_failure(Galerkin<ElectronModel, 3, 1>{}), first_failure(Galerkin<ElectronModel, 4, 2>{}),
                                first_failure(Galerkin<ElectronModel, 3, 1>{}, true)}) {
    EXPECT_EQ(rep.status, FlowStatus::Singular) << rep.message;
    EXPECT_EQ(rep.failed_step, 4);
    EXPECT_NE(rep.message.find("step n=4"), std::string::npos) << rep.message;
    EXPECT_NE(rep.message.find("singular"), std::string::npos) << rep.message;
  }
  // With enough points the same data steps fine.
  EXPECT_TRUE(first_failure(Galerkin<ElectronModel, 3, 2>{}).ok());
}

TEST(GalerkinShooting, JacobianMatchesFiniteDifferences) { check_shooting_jacobian<3>(); }
TEST(GalerkinShooting, JacobianWithBubblesMatchesFiniteDifferences) { check_shooting_jacobian<4>(); }

TEST(GalerkinShooting, NoRoundoffFloorOnFineGrids) {
  // Order 6 on increments: the error keeps falling to ~1e-13 and stays near roundoff on grids
  // two orders finer, at tolerance 1e-12 (multiple shooting, segments of 100 steps). What remains
  // at N = 10^4 is the rounding of each step's solve, ~u |p''|/h in p''' per step (2e-4 here):
  // about 1e-10 after 10^4 steps, against 3e-8 for the nodal windows' floor.
  const Electron e{};
  for (int N : {1000, 3000, 10000}) {
    ShootingOptions opt;
    opt.method = ShootingMethod::Multiple;
    opt.segments = (N + 99) / 100;
    opt.solver.tolerance = 1e-12;
    const Errors err = electron_errors<4>(e, 2.0, N, opt);
    std::printf("degree 4, N = %d: x %.3e, u %.3e, cost %.3e\n", N, err.x, err.u, err.cost);
    EXPECT_LT(err.x, N <= 3000 ? 1e-11 : 3e-10);
    EXPECT_LT(err.cost, 1e-12);
  }
}
