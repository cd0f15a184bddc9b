// The shooting machinery itself: the exact Jacobian (flow sensitivities, group element included,
// difference basis) against finite differences, and an unstable problem on which single shooting
// breaks down while multiple shooting converges (METHOD.md §5).
#include "jacobian_check.hpp"
#include "oracles/continuous.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>

#include <gtest/gtest.h>

using namespace lpshoot;
using namespace lpshoot::problems;
using lpshoot::test_support::richardson_jacobian_error;

TEST(ShootingSystem, JacobianMatchesFiniteDifferencesWithGroupsAndSegments) {
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 1.0};
  BeanieBoundary s, e;
  s.psi = 0.1, s.psi_dot = 0.3, s.theta = 0.2, s.x = 0.5, s.y = -0.3, s.Omega1 = 0.5, s.Omega2 = 0.2;
  e.psi = 1.0, e.psi_dot = -0.2, e.theta = 1.4, e.x = 1.0;  // x(T) fixed too: group natural + fixed mix
  e.y = 0.4;
  const auto bvp = beanie_bvp(b, 1.5, 60, s, e, Closure::SecondOrder);
  const auto guess = beanie_guess(bvp, s, e);
  const auto g = reconstruct_group(b, guess.trajectory, guess.g0);
  for (int S : {1, 3}) {
    std::vector<int> starts;
    for (int i = 0; i <= S; ++i) starts.push_back(2 + (60 - 3 + 1 - 2) * i / S);
    std::vector<BoundaryState<BeanieControl>> refs;
    for (int i = 0; i < S; ++i) refs.push_back({guess.trajectory.state(starts[i]), g[starts[i] - 2]});
    detail::ShootingSystem<BeanieControl> sys(bvp, refs, starts, NewtonOptions{}, 1);
    const Eigen::VectorXd x = lpshoot::test_support::random_point(sys.size());
    SparseJacobian Js;
    ASSERT_TRUE(sys.jacobian(x, Js));
    const Eigen::MatrixXd J(Js);
    // Richardson-extrapolated central differences (error O(eps^4)) at two step sizes: either they
    // already agree with J to 1e-6 (the noise floor: the flow's Newton tolerance, ~1e-12/eps), or their error shrinks like eps^4 towards J. A wrong J would
    // leave an error that does not shrink. (The third-difference directions of the unknowns have
    // leverage ~1e4 on the terminal rows, so single shooting's differences are truncation-limited.)
    const double coarse = richardson_jacobian_error(sys, x, J, 4e-5), worst = richardson_jacobian_error(sys, x, J, 2e-5);
    std::printf("segments %d: %d unknowns, max relative Jacobian error %.2e (at twice the step %.2e)\n", S,
                sys.size(), worst, coarse);
    EXPECT_TRUE(worst < 1e-6 || worst < coarse / 8) << "errors " << coarse << " -> " << worst;
  }
}

TEST(ShootingSystem, UnstableElectronNeedsMultipleShooting) {
  // A repulsive potential (φ = -|x|^2) over a long horizon: perturbations grow like e^{1.4 t}.
  const Electron e{1.0, 1.0, Eigen::Vector3d(0, 0, 1.0), -1.0};
  const double T = 12.0;
  const int N = 1200;
  const ElectronBoundary start{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
  const ElectronBoundary end{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};
  const auto exact = oracles::electron_exact_optimum(e, T, start.position, start.velocity, end.position, end.velocity);
  const auto bvp = electron_bvp(e, T, N, start, end, Closure::SecondOrder);
  const auto guess = electron_guess(bvp, start, end);
  auto error = [&](const ShootingResult<Electron>& r) {
    double err = 0;
    for (int n = 0; n <= N; ++n)
      err = std::max(err, (r.trajectory.p[n] - exact.position(r.trajectory.time(n))).lpNorm<Eigen::Infinity>());
    return err;
  };
  ShootingOptions single;
  const auto a = solve_bvp(bvp, guess, single);
  ShootingOptions multiple;
  multiple.method = ShootingMethod::Multiple;
  multiple.segments = 24;
  const auto b = solve_bvp(bvp, guess, multiple);
  std::printf("unstable electron: single %s (%s), error %.2e, condition %.2e; multiple %s, error %.2e, condition %.2e\n",
              status_name(a.status), a.message.c_str(), a.trajectory.N() == N ? error(a) : INFINITY, a.condition,
              status_name(b.status), error(b), b.condition);
  ASSERT_TRUE(b.ok()) << b.message;
  EXPECT_LT(error(b), 1e-3);  // second-order discretization error at h = 0.01
  // Single shooting either fails or is far less accurate than multiple shooting.
  EXPECT_TRUE(!a.ok() || error(a) > 10 * error(b));
}

TEST(ShootingSystem, LinearProblemJacobianStaysExactOnFineGrids) {
  // The electron's discrete flow is linear, so the shooting residual is affine in the unknowns:
  // F(x + e_j) - F(x) = J e_j exactly, up to roundoff, for a unit step. On a fine grid the
  // difference-basis unknowns are recombinations of nodal directions of size h^{-3}; propagating
  // nodal directions and recombining afterwards (as the engine once did) left entries wrong by
  // O(1) at N = 1000 (worst relative error 45) and Newton stalled on this linear problem.
  const Electron e{1.0, 1.0, Eigen::Vector3d(0, 0, 1.0), 1.0};
  const ElectronBoundary start{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
  const ElectronBoundary end{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};
  const int N = 1000;
  const auto bvp = electron_bvp(e, 2.0, N, start, end, Closure::SecondOrder);
  const auto guess = electron_guess(bvp, start, end);
  for (int S : {1, 2, 8}) {
    std::vector<int> starts;
    for (int i = 0; i <= S; ++i) starts.push_back(2 + static_cast<int>(std::lround(double(N - 3) * i / S)));
    std::vector<BoundaryState<Electron>> refs;
    for (int i = 0; i < S; ++i) refs.push_back({guess.trajectory.state(starts[i]), Trivial::identity<double>()});
    detail::ShootingSystem<Electron> sys(bvp, refs, starts, NewtonOptions{}, 1);
    const Eigen::VectorXd x = Eigen::VectorXd::Zero(sys.size());
    Eigen::VectorXd F, Fj;
    SparseJacobian Js;
    ASSERT_TRUE(sys.residual(x, F) && sys.jacobian(x, Js));
    const Eigen::MatrixXd J(Js);
    double worst = 0;
    for (int j = 0; j < sys.size(); ++j) {
      Eigen::VectorXd xj = x;
      xj(j) += 1.0;
      ASSERT_TRUE(sys.residual(xj, Fj));
      const Eigen::VectorXd diff = Fj - F;
      worst = std::max(worst, (J.col(j) - diff).lpNorm<Eigen::Infinity>() / std::max(1.0, diff.lpNorm<Eigen::Infinity>()));
    }
    std::printf("N = %d, %d segments: max relative error of the exact Jacobian on an affine residual %.2e\n", N, S, worst);
    EXPECT_LT(worst, 1e-4);  // measured ~1e-5: the flow's roundoff over ~1000 steps
  }
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;
  opt.segments = 2;
  const auto r = solve_bvp(bvp, guess, opt);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_LE(r.iterations, 3) << "a linear problem: one Newton step, plus roundoff";
}

namespace {
// The beanie scene's problem (examples/scenes/beanie.json, N = 200) with V = amplitude (1 - cos ψ).
std::pair<BoundaryValueProblem<BeanieControl>, ShootingGuess<BeanieControl>> scene_beanie(double amplitude) {
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, amplitude};
  BeanieBoundary s, e;
  s.psi = 0, s.psi_dot = 0, s.theta = 0, s.x = 0, s.y = 0, s.Omega1 = 0.5, s.Omega2 = 0.2;
  e.psi = 1.0, e.psi_dot = 0, e.theta = 1.0;
  auto bvp = beanie_bvp(b, 2.0, 200, s, e, Closure::SecondOrder);
  auto guess = beanie_guess(bvp, s, e);
  return {std::move(bvp), std::move(guess)};
}
}  // namespace

TEST(ShootingSystem, ManySegmentsConvergeLikeFewOnANonlinearProblem) {
  // Beanie with V = 1 - cos ψ (nonlinear): the Newton step does not depend on the row scaling,
  // but a line search's merit does; with rows scaled by tolerances spanning 1e4 the line search
  // once took 19 iterations at 50 segments against 3 at 4. Full steps come first now.
  const auto [bvp, guess] = scene_beanie(1.0);
  ShootingOptions few, many;
  few.method = many.method = ShootingMethod::Multiple;
  few.segments = 4;
  many.segments = 50;
  const auto a = solve_bvp(bvp, guess, few), c = solve_bvp(bvp, guess, many);
  ASSERT_TRUE(a.ok()) << a.message;
  ASSERT_TRUE(c.ok()) << c.message;
  std::printf("beanie N = 200: 4 segments %d iterations, 50 segments %d iterations\n", a.iterations, c.iterations);
  EXPECT_LE(c.iterations, a.iterations + 2);
  double diff = 0;
  for (int n = 0; n <= 200; ++n) diff = std::max(diff, std::abs(a.trajectory.p[n](0) - c.trajectory.p[n](0)));
  EXPECT_LT(diff, 1e-8);
}

TEST(ShootingSystem, SegmentStartsFromTheForwardSweepWhereTheGuessIsFarFromTheDynamics) {
  // V = 100 (1 - cos ψ): the interpolated guess's interior states are far from the optimal
  // (oscillatory, ω ≈ 17) dynamics; started there, multiple shooting fails. Started from the
  // forward sweep (segment i+1 begins where segment i, run from the guess's start, ends) the
  // first Newton step is single shooting's, and it converges to single shooting's optimum.
  const auto [bvp, guess] = scene_beanie(100.0);
  ShootingOptions single, opt;
  const auto ref = solve_bvp(bvp, guess, single);
  ASSERT_TRUE(ref.ok()) << ref.message;
  opt.method = ShootingMethod::Multiple;
  opt.segments = 4;
  opt.segment_starts = SegmentStarts::Guess;
  const auto from_guess = solve_bvp(bvp, guess, opt);
  EXPECT_FALSE(from_guess.ok());
  for (SegmentStarts starts : {SegmentStarts::Propagated, SegmentStarts::Auto}) {
    opt.segment_starts = starts;
    const auto r = solve_bvp(bvp, guess, opt);
    ASSERT_TRUE(r.ok()) << r.message;
    EXPECT_TRUE(r.propagated_starts);
    double diff = 0;
    for (int n = 0; n <= 200; ++n) diff = std::max(diff, std::abs(r.trajectory.p[n](0) - ref.trajectory.p[n](0)));
    std::printf("stiff beanie: %s starts, %d iterations (single shooting %d), max |Δψ| %.2e\n",
                starts == SegmentStarts::Auto ? "auto" : "propagated", r.iterations, ref.iterations, diff);
    EXPECT_LT(diff, 1e-8);
    EXPECT_NEAR(r.cost, ref.cost, 1e-9 * ref.cost);
  }
}

TEST(ShootingSystem, AutomaticSegmentStartsKeepTheGuessWhenTheFlowIsUnstable) {
  // φ = -|x|^2, T = 12: a forward sweep grows like e^{1.4 t}; the guess's states are kept.
  const Electron e{1.0, 1.0, Eigen::Vector3d(0, 0, 1.0), -1.0};
  const ElectronBoundary start{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
  const ElectronBoundary end{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};
  const auto bvp = electron_bvp(e, 12.0, 1200, start, end, Closure::SecondOrder);
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;
  opt.segments = 24;
  const auto r = solve_bvp(bvp, electron_guess(bvp, start, end), opt);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(r.propagated_starts);
}
