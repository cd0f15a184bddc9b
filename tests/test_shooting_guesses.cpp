// Initial guesses: warm start from a coarser solution, and continuation in a scalar parameter.
#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>
#include <lpshoot/shooting/continuation.hpp>

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {
BeanieBoundary start_data() {
  BeanieBoundary s;
  s.psi = 0.0, s.psi_dot = 0.0, s.theta = 0.0, s.x = 0.0, s.y = 0.0, s.Omega1 = 0.5, s.Omega2 = 0.2;
  return s;
}
BeanieBoundary end_data() {
  BeanieBoundary e;
  e.psi = 2.5, e.psi_dot = 0.0, e.theta = 1.0;
  return e;
}

// The largest difference of the shape positions x_n between two Galerkin solutions on N steps.
template <class R>
double position_difference(const R& a, const R& b, int N) {
  double diff = 0;
  for (int n = 0; n <= N; ++n) diff = std::max(diff, (a.trajectory.x(n) - b.trajectory.x(n)).cwiseAbs().maxCoeff());
  return diff;
}

// The beanie with V = amplitude (1 - cos ψ), and the end data with ψ(T) = 1.
BeanieModel beanie_model(double amplitude) {
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, amplitude};
  return model;
}
BeanieBoundary end_at_psi_one() {
  BeanieBoundary e = end_data();
  e.psi = 1.0;
  return e;
}

// Multiple shooting with the start from coarser grids from N >= from at the given ratio.
ShootingOptions coarse_start_options(int from, int ratio) {
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;
  opt.coarse_start_from = from;
  opt.coarse_ratio = ratio;
  return opt;
}
}  // namespace

TEST(ShootingGuesses, WarmStartFromACoarserGridGivesTheSameSolution) {
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 1.0};  // V = 1 - cos ψ, ψ swung through 2.5 rad
  const double T = 2.0;
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;
  opt.segments = 8;
  const auto coarse_bvp = beanie_bvp(b, T, 100, start_data(), end_data(), Closure::SecondOrder);
  const auto coarse = solve_bvp(coarse_bvp, beanie_guess(coarse_bvp, start_data(), end_data()), opt);
  ASSERT_TRUE(coarse.ok()) << coarse.message;
  const auto fine_bvp = beanie_bvp(b, T, 200, start_data(), end_data(), Closure::SecondOrder);
  const auto cold = solve_bvp(fine_bvp, beanie_guess(fine_bvp, start_data(), end_data()), opt);
  const auto warm = solve_bvp(fine_bvp, resample(coarse, 200), opt);
  ASSERT_TRUE(cold.ok()) << cold.message;
  ASSERT_TRUE(warm.ok()) << warm.message;
  double diff = 0;
  for (int n = 0; n <= 200; ++n) diff = std::max(diff, std::abs(cold.trajectory.p[n](0) - warm.trajectory.p[n](0)));
  std::printf("cold start %d iterations, warm start %d iterations, difference %.2e\n", cold.iterations,
              warm.iterations, diff);
  EXPECT_LT(diff, 1e-9);
  // Not asserted: fewer iterations. The resampled increments do not satisfy the constraints
  // exactly (the interpolated guess is built to), and here the warm start needs more iterations.
}

TEST(ShootingGuesses, ContinuationInThePotentialScaleReachesTheTarget) {
  const double T = 2.0;
  const int N = 100;
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;
  opt.segments = 4;
  auto make = [&](double amplitude) {
    BeanieControl b;
    b.par = {1.0, 1.0, 0.5, amplitude};
    return beanie_bvp(b, T, N, start_data(), end_data(), Closure::SecondOrder);
  };
  const auto bvp0 = make(0.0);
  const auto cont = continuation<BeanieControl>(make, 0.0, 6.0, beanie_guess(bvp0, start_data(), end_data()), opt);
  ASSERT_TRUE(cont.reached) << cont.result.message;
  ASSERT_TRUE(cont.result.ok()) << cont.result.message;
  std::printf("continuation 0 -> 6 in %d solves (%zu accepted)\n", cont.solves, cont.path.size());
  // The continued solution satisfies the target problem: a fresh solve from it takes one step.
  const auto again = solve_bvp(make(6.0), as_guess(cont.result), opt);
  ASSERT_TRUE(again.ok()) << again.message;
  double diff = 0;
  for (int n = 0; n <= N; ++n) diff = std::max(diff, std::abs(again.trajectory.p[n](0) - cont.result.trajectory.p[n](0)));
  EXPECT_LT(diff, 1e-9);
  EXPECT_LE(again.iterations, 2);
}

// A failed step is halved from the step it tried, also when that one was cut short to reach the
// target: the electron whose potential is not finite above 0.9 (every solve there fails), from 0
// to 1 with a first step of 0.75. 1 fails after 0.75; halving the uncut step (1.125) would try 1
// again, twice. Each failed value is tried once, and the continuation closes in on 0.9.
TEST(ShootingGuesses, ContinuationHalvesTheStepItTriedAtTheTarget) {
  const ElectronBoundary start{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
  const ElectronBoundary end{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};
  auto make = [&](double s) {
    Electron e;
    e.potential = s <= 0.9 ? s : std::nan("");
    return electron_bvp(e, 2.0, 50, start, end, Closure::SecondOrder);
  };
  std::vector<std::pair<double, bool>> tried;
  ContinuationOptions copt;
  copt.initial_step = 0.75;
  copt.on_solve = [&](double s, bool ok, int) { tried.emplace_back(s, ok); };
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;
  opt.segments = 2;
  const auto cont = continuation<Electron>(make, 0.0, 1.0, electron_guess(make(0.0), start, end), opt, copt);
  EXPECT_FALSE(cont.reached);
  ASSERT_GE(tried.size(), 4u);
  EXPECT_EQ(tried[1].first, 0.75);
  EXPECT_EQ(tried[2].first, 1.0);
  EXPECT_FALSE(tried[2].second);
  EXPECT_EQ(tried[3].first, 0.875);  // 0.75 + (1 - 0.75) / 2
  for (size_t i = 1; i < tried.size(); ++i)
    EXPECT_FALSE(!tried[i - 1].second && tried[i].first == tried[i - 1].first) << "value " << tried[i].first << " tried twice";
  // Stalled with a step below min_step (1e-4): the last failure was within 2e-4 above the last success.
  EXPECT_LE(cont.parameter, 0.9);
  EXPECT_GT(cont.parameter, 0.9 - 2e-4);
}

// A flow that fails from the guess leaves nothing evaluated: the result says so with NaN (not 0,
// which reads as a perfect solve), and no rank.
TEST(ShootingGuesses, AFlowThatFailsFromTheGuessReportsNothingAsEvaluated) {
  const ElectronBoundary start{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
  const ElectronBoundary end{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};
  Electron e;
  e.potential = std::nan("");
  const auto bvp = electron_bvp(e, 2.0, 50, start, end, Closure::SecondOrder);
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;
  opt.segments = 2;
  const auto r = solve_bvp(bvp, electron_guess(bvp, start, end), opt);
  ASSERT_EQ(r.status, ShootingStatus::FlowFailed) << r.message;
  EXPECT_NE(r.message.find("from the initial guess"), std::string::npos) << r.message;
  EXPECT_TRUE(std::isnan(r.residual_norm)) << r.residual_norm;
  EXPECT_TRUE(std::isnan(r.raw_residual_norm)) << r.raw_residual_norm;
  EXPECT_TRUE(std::isnan(r.condition)) << r.condition;
  EXPECT_TRUE(std::isnan(r.cost)) << r.cost;
  EXPECT_EQ(r.rank, -1);
}

namespace {
// The interval data of the curve p(t) = Σ_k c_k t^k (degree ≤ 5) on [t, t + h], by Taylor:
// X2 = Σ_{k≥2} p^(k) h^(k-2)/k!, V1 = Σ_{k≥2} p^(k) h^(k-2)/(k-1)!; the bubbles from the curve's
// τ⁴ and τ⁵ coefficients C4 = h⁴ p/24, C5 = h⁵ p'/120 on the bubbles h² a_j β_j,
// β_0 = τ²(1-τ)² = τ² - 2τ³ + τ⁴ and β_1 = β_0 (2τ - 1) = -τ² + 4τ³ - 5τ⁴ + 2τ⁵ (the rest is the
// Hermite cubic): a_1 = C5 / (2h²), a_0 = (C4 + 5 C5 / 2) / h².
struct Quintic {
  double c[6];
  double d(int k, double t) const {  // k-th derivative
    double s = 0;
    for (int j = k; j <= 5; ++j) {
      double f = 1;
      for (int i = 0; i < k; ++i) f *= j - i;
      s += f * c[j] * std::pow(t, j - k);
    }
    return s;
  }
  void interval(double t, double h, double& x, double& v, double& X2, double& V1, double a[2]) const {
    x = d(0, t), v = d(1, t), X2 = V1 = 0;
    double hk = 1, fact = 1;
    for (int k = 2; k <= 5; ++k) {
      fact *= k;
      X2 += d(k, t) * hk / fact;
      V1 += d(k, t) * hk * k / fact;
      hk *= h;
    }
    const double C4 = std::pow(h, 4) * d(4, t) / 24, C5 = std::pow(h, 5) * d(5, t) / 120;
    a[0] = (C4 + 2.5 * C5) / (h * h);
    a[1] = C5 / (2 * h * h);
  }
};

// Galerkin of degree S carries polynomials of degree S exactly: refined, every new interval's
// increments and bubbles are those of the same curve on the new step (the bubbles scale like h²,
// the increments are not the old interval's); coarsened, the nodes are the curve's.
template <int S>
void check_resample_carries_polynomials() {
  using Sch = ElectronGalerkin<S>;
  const double top = S == 5 ? 1.0 : 0.0;  // the degree-5 coefficients
  const Quintic curve[3] = {{{0.3, -1.0, 0.7, 2.0, -1.5, 0.8 * top}},
                            {{-0.2, 0.5, -2.0, 0.4, 0.9, -1.1 * top}},
                            {{1.0, 0.0, 0.3, -0.8, 0.25, 0.6 * top}}};
  const double T = 1.2;
  auto trajectory = [&](int N) {
    GalerkinTrajectory<Sch> tr;
    tr.h = T / N;
    tr.intervals.resize(N);
    for (int n = 0; n < N; ++n) {
      auto& iv = tr.intervals[n];
      iv.w.setZero();
      for (int a = 0; a < 3; ++a) {
        double bubble[2];
        curve[a].interval(n * tr.h, tr.h, iv.x(a), iv.v(a), iv.X2(a), iv.V1(a), bubble);
        for (int j = 0; j < Sch::bubbles; ++j) iv.w(Sch::shape_bubble(j) + a) = bubble[j];
      }
    }
    return tr;
  };
  const ElectronModel model;
  const auto old = trajectory(6);
  for (int N : {6, 18, 13}) {  // the same grid, three times finer, a non-nested finer grid
    const auto fine = resample_trajectory(model, old, N);
    const auto want = trajectory(N);
    ASSERT_EQ(fine.N(), N);
    double err = 0;
    for (int n = 0; n < N; ++n) {
      const auto &a = fine.intervals[n], &b = want.intervals[n];
      err = std::max({err, (a.x - b.x).cwiseAbs().maxCoeff(), (a.v - b.v).cwiseAbs().maxCoeff(),
                      (a.X2 - b.X2).cwiseAbs().maxCoeff(), (a.V1 - b.V1).cwiseAbs().maxCoeff(),
                      (a.w - b.w).cwiseAbs().maxCoeff()});
    }
    EXPECT_LT(err, 1e-13) << "degree " << S << ", N = " << N;
  }
  EXPECT_THROW(resample_trajectory(model, old, 0), std::invalid_argument);
  EXPECT_THROW(resample_trajectory(model, GalerkinTrajectory<Sch>{}, 4), std::invalid_argument);
  const auto coarse = resample_trajectory(model, old, 4);  // h' = 1.5 h
  const auto want = trajectory(4);
  for (int n = 0; n <= 4; ++n) {
    EXPECT_LT((coarse.x(n) - want.x(n)).cwiseAbs().maxCoeff(), 1e-13) << "node " << n;
    EXPECT_LT((coarse.v(n) - want.v(n)).cwiseAbs().maxCoeff(), 1e-13) << "node " << n;
  }
}
}  // namespace

TEST(ShootingGuesses, GalerkinResampleCarriesAQuarticToAnyGrid) { check_resample_carries_polynomials<4>(); }
TEST(ShootingGuesses, GalerkinResampleCarriesAQuinticToAnyGridWithTwoBubbles) { check_resample_carries_polynomials<5>(); }

// Multipliers are densities: through the Gauss values, a polynomial of degree Q - 1 is exact.
TEST(ShootingGuesses, GaussInterpolationIsExactOnPolynomialsOfDegreeQMinusOne) {
  const auto& c = GalerkinTable<4, 3>::get().c;
  double values[3];
  auto f = [](double t) { return 0.4 - 1.3 * t + 2.2 * t * t; };
  for (int i = 0; i < 3; ++i) values[i] = f(c[i]);
  for (double t : {0.0, 0.25, 1.0, 1.7}) EXPECT_NEAR((detail::gauss_interpolate<4, 3>(values, 1, t)), f(t), 1e-13);
}

// A warm start from a coarser Galerkin 6 solve of the beanie: the group part is carried too
// (g at the common nodes unchanged), the guess starts closer to the solution than the
// interpolated one (measured: 68 times), saves a Newton iteration, and both reach the same solution.
TEST(ShootingGuesses, GalerkinWarmStartOfTheBeanieStartsCloseAndReachesTheSameSolution) {
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  BeanieBoundary s = start_data(), e = end_data();
  e.psi = 1.0;
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;
  opt.segments = 4;
  const auto coarse_bvp = beanie_galerkin_bvp<4>(model, 2.0, 8, s, e);
  const auto coarse = solve_bvp(coarse_bvp, beanie_galerkin_guess<4>(coarse_bvp, s, e), opt);
  ASSERT_TRUE(coarse.ok()) << coarse.message;
  const int N = 24;
  const auto warm_guess = resample(model, coarse, N);
  const auto g_old = coarse.trajectory.group(), g_new = warm_guess.trajectory.group();
  for (int n = 0; n <= 8; ++n)
    EXPECT_LT(SE2::log(SE2::compose(SE2::inverse(g_old[n]), g_new[3 * n])).cwiseAbs().maxCoeff(), 1e-12) << "node " << n;
  const auto bvp = beanie_galerkin_bvp<4>(model, 2.0, N, s, e);
  const auto cold = solve_bvp(bvp, beanie_galerkin_guess<4>(bvp, s, e), opt);
  const auto warm = solve_bvp(bvp, warm_guess, opt);
  ASSERT_TRUE(cold.ok()) << cold.message;
  ASSERT_TRUE(warm.ok()) << warm.message;
  std::printf("initial residual: interpolated guess %.3g, warm start %.3g (x tolerance); iterations %d, %d\n",
              cold.residual_history.front(), warm.residual_history.front(), cold.iterations, warm.iterations);
  EXPECT_LT(warm.residual_history.front(), 0.05 * cold.residual_history.front());
  EXPECT_LT(warm.iterations, cold.iterations);
  EXPECT_LT(position_difference(cold, warm, N), 1e-9);
}

// A Galerkin solve on a fine grid starts from coarser grids' solutions (ShootingOptions::
// coarse_start_from, coarse_start.hpp): the beanie on Galerkin 6 at N = 2000 with the start from
// N >= 400 and ratio 4 goes through N = 125 and 500. It must reach the solution the guess
// reaches, starting far closer to it and in fewer iterations on the fine grid.
TEST(CoarseStart, AFineGalerkinSolveStartsFromCoarserGridsAndReachesTheSameSolution) {
  const BeanieModel model = beanie_model(1.0);
  const BeanieBoundary s = start_data(), e = end_at_psi_one();
  const ShootingOptions opt = coarse_start_options(400, 4), direct = coarse_start_options(0, 4);
  const int N = 2000;
  const auto bvp = beanie_galerkin_bvp<4>(model, 2.0, N, s, e);
  const auto guess = beanie_galerkin_guess<4>(bvp, s, e);
  const auto warm = solve_bvp(bvp, guess, opt);
  const auto cold = solve_bvp(bvp, guess, direct);
  ASSERT_TRUE(warm.ok()) << warm.message;
  ASSERT_TRUE(cold.ok()) << cold.message;
  std::printf("initial residual: guess %.3g, from the coarser grids %.3g (x tolerance); iterations %d, %d (and %d on "
              "the coarser grids)\n",
              cold.residual_history.front(), warm.residual_history.front(), cold.iterations, warm.iterations,
              warm.coarse_iterations);
  EXPECT_EQ(warm.coarse_grids, (std::vector<int>{125, 500}));
  EXPECT_TRUE(cold.coarse_grids.empty());
  EXPECT_GT(warm.coarse_iterations, 0);
  EXPECT_LT(warm.residual_history.front(), 1e-3 * cold.residual_history.front());
  EXPECT_LT(warm.iterations, cold.iterations);
  const double diff = position_difference(cold, warm, N);
  std::printf("solutions differ by %.2e\n", diff);
  EXPECT_LT(diff, 1e-9);
}

// When the coarse grid cannot be solved, the fine grid is solved from the guess as without the
// coarse start, and the detail says why. The beanie on Galerkin 6 with a stiff potential
// (V = 100 (1 - cos ψ)): at N = 20 its flow fails from the guess (a step's Newton does not
// converge), at N = 40 it converges; a start from N = 20 (ratio 2) falls back to the guess.
TEST(CoarseStart, ACoarseGridThatFailsFallsBackToTheGuess) {
  const BeanieModel model = beanie_model(100.0);
  const BeanieBoundary s = start_data(), e = end_at_psi_one();
  const ShootingOptions opt = coarse_start_options(40, 2), direct = coarse_start_options(0, 2);
  const auto bvp = beanie_galerkin_bvp<4>(model, 2.0, 40, s, e);
  const auto guess = beanie_galerkin_guess<4>(bvp, s, e);
  // The coarse solve as the fine one makes it: from the guess carried to N = 20.
  const auto coarse_bvp = beanie_galerkin_bvp<4>(model, 2.0, 20, s, e);
  const auto coarse =
      solve_bvp(coarse_bvp, GalerkinGuess<BeanieGalerkin<4>>{resample_trajectory(model, guess.trajectory, 20)}, direct);
  ASSERT_FALSE(coarse.ok()) << "the coarse grid was expected to fail here";
  const auto fell_back = solve_bvp(bvp, guess, opt);
  const auto from_guess = solve_bvp(bvp, guess, direct);
  ASSERT_TRUE(from_guess.ok()) << from_guess.message;
  ASSERT_TRUE(fell_back.ok()) << fell_back.message;
  std::printf("detail: %s\n", fell_back.detail.c_str());
  EXPECT_TRUE(fell_back.coarse_grids.empty());
  EXPECT_EQ(fell_back.coarse_iterations, coarse.iterations);
  EXPECT_NE(fell_back.detail.find("coarser grid failed (the solve on N = 20 first: "), std::string::npos) << fell_back.detail;
  EXPECT_EQ(fell_back.iterations, from_guess.iterations);
  EXPECT_EQ(position_difference(fell_back, from_guess, 40), 0.0);  // the same solve from the same guess
}
