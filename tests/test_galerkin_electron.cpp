// The Galerkin schemes (METHOD.md §9) on the electron: observed orders against the exact optimum
// and against an odeint reference for a nonlinear potential, the regularity check (too few Gauss
// points), and no roundoff floor on fine grids. The beanie's checks: test_galerkin.cpp.
#include "oracles/continuous.hpp"

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
