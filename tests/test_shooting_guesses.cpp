// Initial guesses: warm start from a coarser solution, and continuation in a scalar parameter.
#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>
#include <lpshoot/shooting/continuation.hpp>

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
