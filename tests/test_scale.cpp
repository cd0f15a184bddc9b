// At scale (issue 9), with the structured linear algebra: a rank-deficient shooting Jacobian at
// N = 10^4 with 100 segments is diagnosed and its dependent conditions named as by the dense SVD,
// and the electron at N = 10^5 converges to the exact optimum. Label "scale": seconds to minutes
// each in Release; not in the checked (sanitized) build.
#include "oracles/continuous.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>

#include <gtest/gtest.h>

#include <set>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {
// The row names a diagnosis's dependent conditions mention ("0.53·[terminal x (natural)] + ...").
std::set<std::string> named_rows(const RankDiagnosis& d) {
  std::set<std::string> rows;
  for (const auto& dep : d.dependent_conditions)
    for (size_t at = dep.find('['); at != std::string::npos; at = dep.find('[', at + 1)) rows.insert(dep.substr(at + 1, dep.find(']', at) - at - 1));
  return rows;
}
}  // namespace

TEST(Scale, StructuredRankDiagnosisMatchesTheDenseSVDAtTenThousandStepsAndOneHundredSegments) {
  // The beanie of ShootingBeanie.RedundantTerminalDataIsReportedAsRankDeficient at N = 10^4 with
  // 100 segments (2200 unknowns), its shooting Jacobian at the guess: there it is two short of
  // full rank (dense SVD: singular values 7e-3, 2e-6, then two exact zeros), the left null space
  // spanned by the terminal natural conditions of x, Ω1 and of y, Ω2. The structured diagnosis
  // must find the same rank and name the same conditions as the dense one.
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 0.0};
  b.variant = BeanieConstraints::ExactRotation;
  const double T = 2.0;
  const int N = 10000, S = 100;
  BeanieBoundary s, e;
  s.Omega1 = 0.5, s.Omega2 = 0.2;
  e.psi = 1.0, e.theta = 1.0;
  s.Omega3 = (1.0 + b.par.c() * 1.0) / T;
  const auto bvp = beanie_bvp(b, T, N, s, e, Closure::Paper);
  const auto guess = beanie_guess(bvp, s, e);
  const auto g = reconstruct_group(b, guess.trajectory, guess.g0);
  std::vector<int> starts;
  for (int i = 0; i <= S; ++i) starts.push_back(2 + static_cast<int>(std::lround(double(N - 3) * i / S)));
  std::vector<BoundaryState<BeanieControl>> refs;
  for (int i = 0; i < S; ++i) refs.push_back({guess.trajectory.state(starts[i]), g[starts[i] - 2]});
  detail::ShootingSystem<BeanieControl> sys(bvp, refs, starts, NewtonOptions{}, 0);
  SparseJacobian J;
  ASSERT_TRUE(sys.jacobian(Eigen::VectorXd::Zero(sys.size()), J));
  const RankDiagnosis sparse = diagnose_rank(J, sys.row_names(), 1e-10);
  const RankDiagnosis dense = diagnose_rank(Eigen::MatrixXd(J), sys.row_names(), 1e-10);
  for (const auto& dep : sparse.dependent_conditions) std::printf("structured: %s\n", dep.c_str());
  for (const auto& dep : dense.dependent_conditions) std::printf("dense:      %s\n", dep.c_str());
  EXPECT_EQ(sparse.rank, sys.size() - 2);
  EXPECT_EQ(dense.rank, sys.size() - 2);
  EXPECT_FALSE(std::isfinite(sparse.condition) && sparse.condition < 1e12) << sparse.condition;
  const std::set<std::string> expected = {"terminal x (natural)", "terminal y (natural)", "terminal Omega1 (natural)",
                                          "terminal Omega2 (natural)"};
  EXPECT_EQ(named_rows(sparse), expected);
  EXPECT_EQ(named_rows(dense), expected);
}

TEST(Scale, ElectronAtOneHundredThousandStepsMeetsTheExactOptimum) {
  // Galerkin, cubic (order 4), segments "auto" (1000 of 100 steps: 12000 unknowns). Truncation is
  // ~1e-17 at this h; what remains is the rounding of 10^5 step solves, measured at 2.2e-8 (the
  // same at tolerance 1e-12; ~1e-10 at N = 10^4, GalerkinShooting.NoRoundoffFloorOnFineGrids):
  // bound 1e-7. A solve that stopped short, or a wrong boundary row, errs by far more.
  const Electron e{};
  const ElectronBoundary a{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
  const ElectronBoundary z{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};
  const double T = 2.0;
  const int N = 100000;
  const auto exact = electron_exact_optimum(e, T, a.position, a.velocity, z.position, z.velocity);
  const auto bvp = electron_galerkin_bvp<3>(model_of(e), T, N, a, z);
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;  // segments: auto
  const auto r = solve_bvp(bvp, electron_galerkin_guess<3>(bvp, a, z), opt);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.unknowns % auto_segments(N), 0);
  double err = 0;
  for (int n = 0; n <= N; ++n) err = std::max(err, (r.trajectory.x(n) - exact.position(n * bvp.h())).lpNorm<Eigen::Infinity>());
  std::printf("N = %d: %d unknowns, %d iterations, %.1f s, position error %.2e, cost error %.2e\n", N, r.unknowns,
              r.iterations, r.wall_time_s, err, std::abs(r.cost - exact.cost));
  EXPECT_LT(err, 1e-7);
  EXPECT_LT(std::abs(r.cost - exact.cost), 1e-12);
}
