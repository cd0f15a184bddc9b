// Shooting on Elroy's beanie optimal control (METHOD.md §5, §6.2): the well-posed problem
// (ψ, ψ' at both ends, g(0) and Ω12(0) given, θ(T) given; Ω3(0), Ω(T), x(T), y(T) free).
#include "oracles/continuous.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>

#include <gtest/gtest.h>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {
BeanieControl beanie(double amplitude) {
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, amplitude};
  b.variant = BeanieConstraints::ExactRotation;
  return b;
}

BeanieBoundary well_posed_start() {
  BeanieBoundary s;
  s.psi = 0.0;
  s.psi_dot = 0.0;
  s.theta = 0.0;
  s.x = 0.0;
  s.y = 0.0;
  s.Omega1 = 0.5;
  s.Omega2 = 0.2;
  return s;
}
BeanieBoundary well_posed_end() {
  BeanieBoundary e;
  e.psi = 1.0;
  e.psi_dot = 0.0;
  e.theta = 1.0;
  return e;
}

ShootingResult<BeanieControl> solve(const BeanieControl& b, double T, int N, const BeanieBoundary& s,
                                    const BeanieBoundary& e, Closure c, ShootingOptions opt = {}) {
  const auto bvp = beanie_bvp(b, T, N, s, e, c);
  return solve_bvp(bvp, beanie_guess(bvp, s, e), opt);
}
}  // namespace

TEST(ShootingBeanie, FreePotentialGivesTheCubicCostAndZeroMultipliers) {
  const BeanieControl b = beanie(0.0);
  const double T = 2.0, mu = b.par.mu();
  const double exact = 6 * mu * mu * 1.0 / (T * T * T);  // 6 μ² (Δψ)² / T³
  std::vector<double> err;
  for (int N : {50, 100, 200, 400}) {
    ShootingOptions opt;
    opt.method = ShootingMethod::Multiple;
    opt.segments = N / 25;
    // Start the multipliers away from zero: the natural conditions must bring them back.
    const auto bvp = beanie_bvp(b, T, N, well_posed_start(), well_posed_end(), Closure::SecondOrder);
    auto guess = beanie_guess(bvp, well_posed_start(), well_posed_end());
    for (auto& l : guess.trajectory.lam) l = Eigen::Vector3d(0.1, -0.05, 0.02);
    const auto r = solve_bvp(bvp, guess, opt);
    ASSERT_TRUE(r.ok()) << r.message;
    err.push_back(std::abs(r.cost - exact));
    double lam = 0;
    for (const auto& l : r.trajectory.lam) lam = std::max(lam, l.lpNorm<Eigen::Infinity>());
    std::printf("V = 0, N = %d: cost %.10f (exact %.10f), theta(T) error %.1e, max |lambda| %.1e, drift %.1e\n", N,
                r.cost, exact, std::abs(r.g.back().angle - 1.0), lam, r.momentum_drift);
    EXPECT_LT(std::abs(r.g.back().angle - 1.0), 1e-10);  // θ(T) hit
    EXPECT_LT(lam, 1e-9);                                 // free terminal Ω, x, y: multipliers vanish
    EXPECT_LE(r.momentum_drift, 1e-11);
  }
  for (size_t i = 1; i < err.size(); ++i) EXPECT_GT(std::log2(err[i - 1] / err[i]), 0.85);  // first-order quadrature
}

TEST(ShootingBeanie, CosinePotentialConvergesToTheContinuousOptimum) {
  const BeanieControl b = beanie(1.0);
  const double T = 2.0;
  std::vector<double> psi_err, u_err, cost_err;
  std::vector<int> Ns{50, 100, 200, 400};
  for (int N : Ns) {
    ShootingOptions opt;
    opt.method = ShootingMethod::Multiple;
    opt.segments = N / 25;
    const auto r = solve(b, T, N, well_posed_start(), well_posed_end(), Closure::SecondOrder, opt);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_LE(r.momentum_drift, 1e-11);
    std::vector<double> times;
    for (int n = 0; n <= N; ++n) times.push_back(r.trajectory.time(n));
    const auto ref = oracles::beanie_continuous_optimum(b.par, T, 0.0, 0.0, 1.0, 0.0, times);
    ASSERT_TRUE(ref.converged) << ref.message;
    double ep = 0, eu = 0;
    for (int n = 0; n <= N; ++n) ep = std::max(ep, std::abs(r.trajectory.p[n](0) - ref.psi[n]));
    for (int n = 0; n + 2 <= N; ++n) {  // u_n = μ Δ²ψ_n / h² + V'(ψ_{n+1}) approximates u(t_{n+1})
      const auto a = r.trajectory.window_at(n);
      eu = std::max(eu, std::abs(b.control(a, r.trajectory.h) - ref.u[n + 1]));
    }
    psi_err.push_back(ep);
    u_err.push_back(eu);
    cost_err.push_back(std::abs(r.cost - ref.cost));
    std::printf("V = 1 - cos psi, N = %d: psi error %.3e, u error %.3e, cost error %.3e, drift %.1e\n", N, ep, eu,
                cost_err.back(), r.momentum_drift);
  }
  for (size_t i = 1; i < Ns.size(); ++i) {
    EXPECT_NEAR(std::log2(psi_err[i - 1] / psi_err[i]), 2.0, 0.15) << "psi, halving " << i;
    EXPECT_NEAR(std::log2(u_err[i - 1] / u_err[i]), 2.0, 0.2) << "u, halving " << i;
    EXPECT_GT(std::log2(cost_err[i - 1] / cost_err[i]), 0.85) << "cost, halving " << i;
  }
}

TEST(ShootingBeanie, RedundantTerminalDataIsReportedAsRankDeficient) {
  // Ω3 is conserved and θ(T) = θ(0) + Ω3 T - c (ψ(T) - ψ(0)): giving Ω3(0) as well as θ(T)
  // (consistently) over-determines the problem by one.
  const BeanieControl b = beanie(0.0);
  const double T = 2.0;
  BeanieBoundary s = well_posed_start();
  s.Omega3 = (1.0 - 0.0 + b.par.c() * (1.0 - 0.0)) / T;
  const auto r = solve(b, T, 60, s, well_posed_end(), Closure::Paper);
  std::printf("%s\n", r.message.c_str());
  EXPECT_EQ(r.status, ShootingStatus::RankDeficient);
  EXPECT_EQ(r.rank, r.unknowns - 1);
  ASSERT_EQ(r.dependent_conditions.size(), 1u);
  // The left null vector: ψ(T) and θ(T) cannot be set independently once Ω3 is fixed.
  EXPECT_NE(r.dependent_conditions[0].find("terminal theta"), std::string::npos);
  EXPECT_NE(r.dependent_conditions[0].find("terminal psi"), std::string::npos);
  // The gap to the next singular value is many orders of magnitude: not mere ill-conditioning.
  const auto& sv = r.singular_values;
  EXPECT_LT(sv.back(), 1e-14 * sv.front());
  EXPECT_GT(sv[sv.size() - 2], 1e-6 * sv.front());
}

TEST(ShootingBeanie, CountingErrorsNameTheComponent) {
  const BeanieControl b = beanie(0.0);
  auto bvp = beanie_bvp(b, 2.0, 40, well_posed_start(), well_posed_end(), Closure::Paper);
  bvp.conditions.pop_back();  // drop the last terminal condition
  const auto why = check_counting(bvp);
  EXPECT_NE(why.find("terminal node N-1, group component 2 has no condition (under-determined)"), std::string::npos)
      << why;
  bvp.fix_shape(End::Initial, 0, 0, 0.0, "duplicate psi");
  EXPECT_NE(check_counting(bvp).find("initial node 0, shape component 0 has 2 conditions (over-determined)"),
            std::string::npos);
  const auto r = solve_bvp(bvp, beanie_guess(bvp, well_posed_start(), well_posed_end()));
  EXPECT_EQ(r.status, ShootingStatus::InvalidProblem);
}
